//! The conventional shadow map for the scene's point and spot lights (the baseline of Adaptive
//! Shadow Maps): one perspective depth map per light, hard shadows, lit exactly as `kage reference --light local` (shaders-glsl/include/local_light.glsl)
//! so that the two compare pixel by pixel.
//!
//! Each light's map is a perspective view from the light:
//! - a spot light's map looks along its axis with the cone's full angle as field of view: the
//!   cone is inscribed in the square map, so every point the spot lights has a texel;
//! - a point light has no axis: like the paper's point light (a 122° field of view on the
//!   ceiling), its map looks down −Y with [`POINT_LIGHT_FOV_DEG`]. Points outside that view are
//!   lit without a shadow test (a single perspective map cannot cover a whole sphere; a cube
//!   map would be the next step if a scene needed it).
//!
//! Near and far planes hug the scene's bounding sphere, so the D32 depth keeps its precision
//! where the geometry is. The lookup compares view depths (the stored depth linearized) with a
//! slope-scaled bias in texels of the receiver's depth: a surface at angle θ to the light spans
//! a depth of tan θ per unit of width inside a texel, so the bias grows with tan θ (capped:
//! grazing surfaces would otherwise detach their shadows entirely).
use super::{Technique, TechniqueStats};
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, Context, DepthTest, GraphicsPipeline,
    MemoryLocation,
};
use crate::error::{Error, Result};
use crate::frame::bounds::scene_sphere;
use crate::frame::bounds::{group_bounds, GroupBounds};
use crate::frame::scene_pass::{depth_prepass, depth_prepass_pipeline, scene_pass, scene_pipeline};
use crate::frame::shadow_depth::ShadowMaps;
use crate::frame::{FrameInputs, FrameState};
use crate::frame::{GpuMesh, MAX_SIZE};
use crate::layouts::{bytes_of_slice, constants, spirv, LocalDrawPush, ShadowLight};
use crate::pass::Pass;
use crate::reference::render::reference_light;
use crate::scene::{Light, Scene};
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// Shadow-map sides accepted, texels: up to the largest image Kage renders.
pub const SHADOW_MAP_SIZES: std::ops::RangeInclusive<u32> = 16..=MAX_SIZE;
/// The field of view of a point light's single map, looking down −Y (the paper's light).
pub const POINT_LIGHT_FOV_DEG: f32 = 122.0;

/// Depth bias at any slope, in texels of the receiver's depth: half a texel covers the
/// depth quantisation and rasterisation offsets on a surface facing the light.
const CONSTANT_BIAS_TEXELS: f32 = 0.5;
/// Depth bias per unit of tan θ, in texels: the depth a tilted surface spans across the
/// distance from the lookup point to the centres of the four texels the lookup blends: those
/// farther than 1 texel weigh under 0.14 together, short of the ½ that decides
/// (`shadow_footprint_texel` in shaders-glsl/include/shadow_test.glsl).
const SLOPE_BIAS_TEXELS: f32 = 1.0;
/// tan θ beyond which the bias stops growing (θ ≈ 84°).
const MAX_SLOPE: f32 = 10.0;
/// `LocalDrawPush.bias`: the slope-scaled depth bias of every local-light shadow map (this
/// technique's and adaptive shadow maps' tiles).
pub(crate) const DEPTH_BIAS: [f32; 4] = [CONSTANT_BIAS_TEXELS, SLOPE_BIAS_TEXELS, MAX_SLOPE, 0.0];

pub struct ShadowMap {
    bounds: Vec<GroupBounds>,
    size: u32,
    /// One map per light.
    shadow_maps: ShadowMaps,
    prepass_pipeline: GraphicsPipeline,
    scene_pipeline: GraphicsPipeline,
    /// `ShadowLight` per light, `MAX_LOCAL_LIGHTS` records (the shader's array size).
    records: Buffer,
}

/// A shadow map's side checked against `sizes` (the shadowmap technique's
/// [`SHADOW_MAP_SIZES`], parallel lights' own): what `TechniqueDesc::validated` and the
/// techniques' constructors ask.
pub fn check_map_size(size: u32, sizes: std::ops::RangeInclusive<u32>) -> Result<()> {
    if sizes.contains(&size) {
        return Ok(());
    }
    Err(Error::InvalidArgument(format!(
        "shadow map size {size} must be {} to {} texels",
        sizes.start(),
        sizes.end()
    )))
}

impl ShadowMap {
    /// Maps of `size`² texels for each of the scene's local lights (1 to `MAX_LOCAL_LIGHTS`).
    pub fn new(ctx: &Arc<Context>, scene: &Scene, size: u32) -> Result<ShadowMap> {
        let max = constants::MAX_LOCAL_LIGHTS as usize;
        if !(1..=max).contains(&scene.lights.len()) {
            return Err(Error::InvalidArgument(format!(
                "the shadowmap technique shadows 1 to {max} point or spot lights; scene {} has {} (the \
                 built-in scene asm has one)",
                scene.name,
                scene.lights.len()
            )));
        }
        check_map_size(size, SHADOW_MAP_SIZES)?;
        let scene_pipeline = scene_pipeline(
            ctx,
            "scene_local_lights",
            (spirv::LOCAL_LIGHTS_VERT, spirv::LOCAL_LIGHTS_FRAG),
            &[BindingKind::UniformBuffer, BindingKind::UniformBuffer, BindingKind::SampledImage],
            size_of::<LocalDrawPush>(),
            DepthTest::Equal,
        )?;
        let records = Buffer::new(
            ctx,
            &BufferDesc {
                name: "shadow_map.lights",
                size: (max * size_of::<ShadowLight>()) as u64,
                usage: BufferUsage::UNIFORM,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        Ok(ShadowMap {
            bounds: group_bounds(scene),
            size,
            shadow_maps: ShadowMaps::new(ctx, "shadow_map", size, scene.lights.len() as u32)?,
            prepass_pipeline: depth_prepass_pipeline(
                ctx,
                "shadow_map.depth_prepass",
                size_of::<LocalDrawPush>(),
            )?,
            scene_pipeline,
            records,
        })
    }
}

/// A light's map: its position, axis and full field of view in degrees.
fn map_view(light: &Light) -> (Vec3, Vec3, f32) {
    match *light {
        Light::Point { position, .. } => (position, Vec3::NEG_Y, POINT_LIGHT_FOV_DEG),
        Light::Spot { position, direction, fov_deg, .. } => (position, direction.normalize(), fov_deg),
    }
}

/// The record of one light for this frame's scene sphere (`centre`, `radius`): the map's
/// view-projection with near and far planes around the sphere, for a map of `size`² texels
/// (adaptive shadow maps: the root tile's).
pub(crate) fn shadow_light(light: &Light, centre: Vec3, radius: f32, size: u32) -> ShadowLight {
    let (position, axis, fov_deg) = map_view(light);
    let distance = position.distance(centre);
    // A light inside the sphere still gets a near plane in front of it: 1/1000 of the scene
    // keeps the D32 depth's view-depth error well below a texel's bias at every distance.
    let near = (distance - radius).max(1e-3 * radius);
    let far = distance + radius;
    let up = if axis.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    let fov = fov_deg.to_radians();
    let view_proj =
        Mat4::perspective_rh(fov, 1.0, near, far) * Mat4::look_at_rh(position, position + axis, up);
    ShadowLight {
        view_proj: view_proj.to_cols_array_2d(),
        light: reference_light(light),
        map: [near, far, 2.0 * (0.5 * fov).tan() / size as f32, 0.0],
    }
}

impl Technique for ShadowMap {
    fn update(&mut self, state: &FrameState) -> Result<()> {
        let (centre, radius) = scene_sphere(&self.bounds, state.transforms);
        // The records (and so the maps) are redone from the lights every frame: a moved light
        // needs nothing else.
        let records: Vec<ShadowLight> =
            state.lights.iter().map(|l| shadow_light(l, centre, radius, self.size)).collect();
        self.shadow_maps.view_projs =
            records.iter().map(|r| Mat4::from_cols_array_2d(&r.view_proj)).collect();
        self.records.write(0, bytes_of_slice(&records))
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let shadow_maps = self.shadow_maps.pass(inputs.ctx, inputs.scene);
        let count = self.shadow_maps.view_projs.len() as u32;
        let bindings = vec![
            Binding::Uniform(inputs.uniforms),
            Binding::Uniform(&self.records),
            self.shadow_maps.binding(),
        ];
        let push = move |mesh: &GpuMesh, model: &Mat4| LocalDrawPush {
            model: model.to_cols_array_2d(),
            albedo: [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], 0.0],
            params: [count, 0, 0, 0],
            bias: DEPTH_BIAS,
        };
        let prepass = depth_prepass(inputs, &self.prepass_pipeline, push);
        let scene_pass = scene_pass(inputs, &self.scene_pipeline, bindings, push);
        vec![shadow_maps, prepass, scene_pass]
    }

    fn stats(&self) -> TechniqueStats {
        // D32 has a texel size, so this never fails.
        TechniqueStats { shadow_memory_bytes: Some(self.shadow_maps.byte_size()), ..Default::default() }
    }
}
