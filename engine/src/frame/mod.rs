//! What several techniques share, under all of them: the scene's geometry on the GPU and the
//! frame's targets, the environment map and its SH projection, the background pass, the scene
//! and depth-prepass draws, shadow depth rendering, and the groups' bounds. A frame layer module
//! imports the backend, the pass layer and the scene; never a technique.
pub mod albedo_maps;
pub mod background;
pub mod bounds;
pub mod environment;
pub mod gpu_scene;
pub mod irradiance;
pub mod regions;
pub mod scene_pass;
pub mod sh_projection;
pub mod shadow_depth;
pub mod targets;

pub use gpu_scene::{GpuMesh, GpuScene};
pub use targets::{Targets, COLOR_FORMAT, DEPTH_FORMAT, MAX_SIZE};

use crate::backend::{Buffer, Context};
use crate::layouts::EyeRays;
use crate::scene::{Camera, Light};
use environment::GpuEnvironment;
use glam::Mat4;
use std::sync::Arc;

/// The eye rays of `camera` at `aspect` as the shaders take them (shaders-glsl/include/eye_ray.glsl).
pub fn eye_rays(camera: &Camera, aspect: f32) -> EyeRays {
    let [x, y, forward] = camera.eye_rays(aspect).map(|v| v.extend(0.0).to_array());
    EyeRays { x, y, forward }
}

/// What every technique may read while recording a frame.
pub struct FrameInputs<'a> {
    pub ctx: &'a Arc<Context>,
    /// `FrameUniforms` of this frame.
    pub uniforms: &'a Buffer,
    pub environment: &'a GpuEnvironment,
    /// The environment's 9 SH coefficients per channel (`ShCoeffs`), in the map's frame.
    pub env_sh: &'a Buffer,
    pub scene: &'a GpuScene,
    pub targets: &'a Targets,
}

/// The state of the frame about to be recorded.
pub struct FrameState<'a> {
    /// World to the camera's clip space.
    pub view_proj: Mat4,
    /// Object-to-world transform of every group.
    pub transforms: &'a [Mat4],
    /// The environment's rotation about +Y, in radians (counter-clockwise seen from above).
    pub env_rotation: f32,
    /// The scene's point and spot lights as they are this frame (`Renderer::set_light`).
    pub lights: &'a [Light],
}
