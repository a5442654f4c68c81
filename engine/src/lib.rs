//! Kage (影): a real-time lighting engine on raw Vulkan.
//!
//! Layers, bottom to top: [`backend`] (the thin Vulkan layer), [`pass`], [`frame`] (what
//! several techniques share), [`raycast`], [`reference`](mod@reference) and [`prt`],
//! [`techniques`], [`renderer`], [`capi`]; beneath them the modules every layer uses ([`scene`],
//! [`sh`], [`error`], [`layouts`], [`imageio`], [`files`], ...). README's "Architecture" places
//! every module and is checked against the imports (`tests/tests/layers.rs`).
//!
//! Conventions: right-handed, +Y up; equirectangular maps map direction (x, y, z) to
//! u = atan2(x, -z) / 2π wrapped into \[0, 1), v = acos(y) / π, row 0 at the top (+Y).
//!
//! The API in one page, a program that renders the default scene with soft shadows
//! (`engine/examples/soft_shadows.rs`; `cargo run --release -p kage --example soft_shadows`):
//! make a [`backend::Context`], load a [`scene::Scene`], precompute its transfer with
//! [`prt::transfer::precompute`], build a [`renderer::Renderer`] with a
//! [`techniques::description::TechniqueDesc`], then move groups, [`renderer::Renderer::render`]
//! (each pass's GPU time) and read [`renderer::Renderer::image`].
#![warn(unsafe_op_in_unsafe_fn)]

pub mod backend;
pub mod capi;
pub mod equirect;
pub mod error;
pub mod files;
pub mod frame;
pub mod host_memory;
pub mod image_size;
pub mod imageio;
pub mod layouts;
pub mod pass;
pub mod progress;
pub mod prt;
pub mod raycast;
pub mod reference;
pub mod renderer;
pub mod scene;
pub mod sh;
pub mod techniques;

pub use error::{Error, Result};
