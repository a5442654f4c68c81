//! The paper's Fig. 3 baseline: the environment's q regions (the same decomposition as the
//! Tamura technique) treated as q directional lights, each with a binary shadow map in which
//! every group, the receiver included, is an occluder. Per pixel
//! L = albedo / π · Σ_i B_i · max(n·ω_i, 0) · V_i(p), with V_i one depth comparison in region
//! i's map: no filtering, so the banding of q hard shadows shows, which is what the paper's
//! figure compares against.
//!
//! Passes: `shadow_maps` renders every mesh into layer i of a D32 array image (one depth-only
//! rendering scope per region, orthographic along ω_i over the scene's bounding sphere, with
//! the [`ShadowMaps`] pass shared with the shadowmap technique), then
//! `scene` loops over the regions in one fragment shader, reading the lights from a uniform
//! buffer (much cheaper per fragment than a storage buffer on CPU drivers) and the maps with
//! `texelFetch` and a manual comparison.
//!
//! Shadow acne is avoided with a normal offset in the scene shader rather than the pipeline's
//! depth bias: a slope-scaled depth bias grows as tan θ of the light's angle to the surface, and
//! with q up to 128 many regions sit near the horizon, where it would detach the teapot's
//! contact shadow from its base; a normal offset grows as sin θ (at most a texel and a half) and
//! moves the lookup off the surface by a distance tied to the map's texel size. It also keeps
//! `GraphicsDesc` free of a setting only this baseline would use. A small constant depth bias
//! covers curved surfaces, where the texel's depth varies inside the texel.
use super::Technique;
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, Context, DepthTest, GraphicsPipeline,
    MemoryLocation,
};
use crate::error::{Error, Result};
use crate::frame::bounds::env_rotation;
use crate::frame::bounds::{group_bounds, scene_sphere, GroupBounds};
use crate::frame::regions::Regions;
use crate::frame::scene_pass::{depth_prepass, depth_prepass_pipeline, scene_pass, scene_pipeline};
use crate::frame::shadow_depth::ShadowMaps;
use crate::frame::{FrameInputs, FrameState, GpuMesh};
use crate::layouts::{bytes_of_slice, constants, spirv, ParallelDrawPush, ParallelLight};
use crate::pass::Pass;
use crate::scene::Scene;
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// Default side of a shadow map, texels.
pub const DEFAULT_SHADOW_MAP_SIZE: u32 = 512;
/// Shadow-map sides accepted: 128 maps of 2048² D32 texels are 2 GiB already.
pub const SHADOW_MAP_SIZES: std::ops::RangeInclusive<u32> = 16..=2048;

/// Normal offset at grazing light, in shadow-map texels (scaled by sin θ).
const SLOPE_OFFSET_TEXELS: f32 = 1.5;
/// Normal offset at any angle, in texels.
const CONSTANT_OFFSET_TEXELS: f32 = 0.25;
/// Depth bias, in texels of world size along ω_i.
const DEPTH_BIAS_TEXELS: f32 = 0.5;

pub struct ParallelLights {
    regions: Regions,
    bounds: Vec<GroupBounds>,
    size: u32,
    /// One map per region.
    shadow_maps: ShadowMaps,
    scene_pipeline: GraphicsPipeline,
    prepass_pipeline: GraphicsPipeline,
    /// `ParallelLight` per region, `MAX_PARALLEL_LIGHTS` records (the shader's array size).
    lights: Buffer,
    /// World size of a shadow-map texel and of the light depth range this frame.
    texel: f32,
    depth_range: f32,
}

/// The settings' limits: `q` regions, 1 to the shader's `MAX_PARALLEL_LIGHTS`, and maps of
/// [`SHADOW_MAP_SIZES`].
pub fn check(q: usize, shadow_map_size: u32) -> Result<()> {
    let max = constants::MAX_PARALLEL_LIGHTS as usize;
    if !(1..=max).contains(&q) {
        return Err(Error::InvalidArgument(format!("parallel lights: q = {q} regions, must be 1 to {max}")));
    }
    super::shadow_map::check_map_size(shadow_map_size, SHADOW_MAP_SIZES)
}

impl ParallelLights {
    /// `q` regions of the scene's environment (1 to `MAX_PARALLEL_LIGHTS`), shadow maps of
    /// `shadow_map_size`² texels.
    pub fn new(ctx: &Arc<Context>, scene: &Scene, q: usize, shadow_map_size: u32) -> Result<ParallelLights> {
        check(q, shadow_map_size)?;
        let regions = Regions::new(&scene.environment, q)?;
        let scene_pipeline = scene_pipeline(
            ctx,
            "scene_parallel_lights",
            (spirv::PARALLEL_LIGHTS_VERT, spirv::PARALLEL_LIGHTS_FRAG),
            &[BindingKind::UniformBuffer, BindingKind::UniformBuffer, BindingKind::SampledImage],
            size_of::<ParallelDrawPush>(),
            DepthTest::Equal,
        )?;
        let lights = Buffer::new(
            ctx,
            &BufferDesc {
                name: "parallel_lights.lights",
                size: (constants::MAX_PARALLEL_LIGHTS as usize * size_of::<ParallelLight>()) as u64,
                usage: BufferUsage::UNIFORM,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        Ok(ParallelLights {
            regions,
            bounds: group_bounds(scene),
            size: shadow_map_size,
            shadow_maps: ShadowMaps::new(ctx, "parallel_lights", shadow_map_size, q as u32)?,
            scene_pipeline,
            prepass_pipeline: depth_prepass_pipeline(
                ctx,
                "parallel_lights.depth_prepass",
                size_of::<ParallelDrawPush>(),
            )?,
            lights,
            texel: 0.0,
            depth_range: 1.0,
        })
    }

    /// The regions used as lights, in the map's frame.
    pub fn regions(&self) -> &Regions {
        &self.regions
    }
}

impl Technique for ParallelLights {
    fn update(&mut self, state: &FrameState) -> Result<()> {
        let (centre, radius) = scene_sphere(&self.bounds, state.transforms);
        // The maps' depth range reaches a little past the sphere so nothing on it is clipped.
        let margin = 0.01 * radius;
        let projection =
            Mat4::orthographic_rh(-radius, radius, -radius, radius, -margin, 2.0 * radius + margin);
        let env = env_rotation(state.env_rotation);
        let mut lights = Vec::with_capacity(self.regions.regions.len());
        self.shadow_maps.view_projs.clear();
        for region in &self.regions.regions {
            let w = (env * region.direction.as_vec3()).normalize();
            let up = if w.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
            let view_proj = projection * Mat4::look_at_rh(centre + radius * w, centre, up);
            self.shadow_maps.view_projs.push(view_proj);
            lights.push(ParallelLight {
                view_proj: view_proj.to_cols_array_2d(),
                direction: w.extend(0.0).to_array(),
                energy: [region.energy[0] as f32, region.energy[1] as f32, region.energy[2] as f32, 0.0],
            });
        }
        self.texel = 2.0 * radius / self.size as f32;
        self.depth_range = 2.0 * (radius + margin);
        self.lights.write(0, bytes_of_slice(&lights))
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let shadow_maps = self.shadow_maps.pass(inputs.ctx, inputs.scene);
        let shadow = [
            SLOPE_OFFSET_TEXELS * self.texel,
            CONSTANT_OFFSET_TEXELS * self.texel,
            DEPTH_BIAS_TEXELS * self.texel / self.depth_range,
            0.0,
        ];
        let (count, size) = (self.shadow_maps.view_projs.len() as u32, self.size);
        let bindings = vec![
            Binding::Uniform(inputs.uniforms),
            Binding::Uniform(&self.lights),
            self.shadow_maps.binding(),
        ];
        let push = move |mesh: &GpuMesh, model: &Mat4| ParallelDrawPush {
            model: model.to_cols_array_2d(),
            albedo: [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], 0.0],
            params: [count, size, 0, 0],
            shadow,
        };
        // Its fragments test q shadow maps each: a depth prepass shades each pixel once.
        let prepass = depth_prepass(inputs, &self.prepass_pipeline, push);
        let scene_pass = scene_pass(inputs, &self.scene_pipeline, bindings, push);
        vec![shadow_maps, prepass, scene_pass]
    }
}
