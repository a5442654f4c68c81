//! The ground truth every technique is measured against: Monte Carlo direct lighting with full
//! visibility, cast through the BVH on the GPU.
//!
//! - [`render`]: the reference image, progressive (batches of samples per pixel), environment
//!   light with multiple importance sampling or local lights with hard shadows;
//! - [`irradiance`]: E(p, n) at listed points, for light probes;
//! - [`env_sampling`]: the environment map's 2D sampling distribution;
//! - [`statistics`]: the mean and standard error per pixel or point;
//! - [`metrics`]: error metrics between images, the fraction of pixels shadowed differently,
//!   and a false-colour difference picture.
//!
//! Estimator (shaders-glsl/include/reference.glsl): per sample, one direction drawn from the
//! environment distribution and one cosine-weighted, each with one shadow ray, combined by the
//! power heuristic. The map is treated as constant per texel in the lighting (the function its
//! SH projection integrates); a black map falls back to cosine sampling alone.
pub mod env_sampling;
pub mod irradiance;
mod lighting;
pub mod metrics;
pub mod render;
pub mod statistics;

pub use irradiance::{
    surface_radiance, IrradianceFile, IrradianceReference, PointsFile, SurfaceRadiance, MAX_BOUNCES,
};
pub use metrics::{
    compare, diff_image, frames_to_converge, shadow_flips, shadow_mismatch, shadow_mismatch_image, EdgeTies,
    ImageMetrics, ShadowFlips, ShadowMismatch, SHADOW_THRESHOLD,
};
pub use render::{LightMode, ReferenceOptions, ReferenceRenderer, OUTPUT_VERSION};
pub use statistics::Statistics;

use crate::layouts::constants;
use crate::pass::Pass;

/// Splits a batch of `spp` samples, the first numbered `first`, into passes of at most
/// `KAGE_SAMPLES_PER_DISPATCH` samples each (see constants.glsl: llvmpipe cuts long loops),
/// made by `pass(first sample, count)`.
fn sample_passes<'a>(spp: u32, first: u32, mut pass: impl FnMut(u32, u32) -> Pass<'a>) -> Vec<Pass<'a>> {
    (0..spp)
        .step_by(constants::SAMPLES_PER_DISPATCH as usize)
        .map(|done| pass(first + done, (spp - done).min(constants::SAMPLES_PER_DISPATCH)))
        .collect()
}
