//! Sloan, Kautz, Snyder 2002: precomputed radiance transfer. Each vertex's transfer vector (the
//! cosine-weighted visibility of its own group, or of the whole scene as it stood when
//! precomputed: `crate::prt`) dotted with the environment's SH turned into the group's frame:
//! self-shadowed diffuse light per vertex, evaluated on the GPU one texel per vertex
//! ([`self_shadow`], the Tamura paper's section 4.1).
//!
//! The Tamura technique is this plus occlusion between groups, and draws the scene with the
//! same pipeline; Sloan's technique is that pipeline with no regions.
pub mod self_shadow;

use super::tamura::technique::{OcclusionSettings, PrtTechnique};
use crate::backend::Context;
use crate::error::Result;
use crate::frame::GpuScene;
use crate::prt::TransferSet;
use crate::scene::Scene;
use std::sync::Arc;

/// Sloan's technique for `scene` with `transfer`, as published: the light interpolated from the
/// vertices.
pub fn new(
    ctx: &Arc<Context>,
    scene: &Scene,
    gpu: &GpuScene,
    transfer: &TransferSet,
) -> Result<PrtTechnique> {
    let settings = OcclusionSettings {
        regions: 0,
        dominant_lights: 0,
        pixel_cosine: false,
        ..OcclusionSettings::default()
    };
    PrtTechnique::new(ctx, scene, gpu, transfer, settings)
}
