//! Kage (影): a real-time lighting engine on raw Vulkan.
//!
//! Layers, bottom to top (each a folder; a module imports only from layers below it):
//! - [`backend`]: a thin layer over ash: device, memory, buffers, images, pipelines,
//!   descriptors, timestamps, validation.
//! - [`pass`]: named passes with inputs, outputs and a record function, each wrapped in a debug
//!   label and a GPU timestamp pair.
//! - [`frame`]: what several techniques share: the GPU scene, targets, environment, background,
//!   scene draws, shadow depth, group bounds.
//! - [`raycast`], then [`reference`](mod@reference) and [`prt`] over it: the BVH, the ground
//!   truth, the PRT precomputation.
//! - [`techniques`]: one per file or folder, named and built by [`techniques::description`].
//! - [`renderer`]: the frame loop; then [`capi`] (and the command line, outside this crate).
//!
//! Beside the layers, imported by any of them: [`scene`] (what a scene holds and its file
//! format), [`sh`], [`layouts`] (the GPU/host structs), [`error`], [`imageio`], [`files`]
//! (opening what a user names), [`image_size`] (image headers checked before decoding) and
//! [`host_memory`] (allocations a caller sized, made fallibly).
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
