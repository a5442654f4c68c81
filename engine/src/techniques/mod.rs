//! Lighting techniques, each built from passes. `environment` and `env_sh` are shared by all
//! of them: the environment map on the GPU and its SH projection.
pub mod env_sh;
pub mod environment;
pub mod prt;
pub mod unshadowed;
