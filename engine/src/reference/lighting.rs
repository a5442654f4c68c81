//! What both reference shaders bind first: the scene's BVH, the environment map and its
//! sampling distribution (bindings 0 .. BVH_BINDINGS + 2, in the order reference.glsl declares);
//! and what both need besides: the scene's point and spot lights.
use super::env_sampling::EnvDistribution;
use super::render::reference_light;
use crate::backend::{Binding, BindingKind, Buffer, BufferUsage, Context, TexelBuffer};
use crate::error::Result;
use crate::frame::environment::GpuEnvironment;

use crate::layouts::{bytes_of_slice, ReferenceLight};

use crate::raycast::{GpuBvh, SceneBvh};
use crate::scene::Scene;
use std::sync::Arc;

pub struct ReferenceLighting {
    bvh: GpuBvh,
    env: GpuEnvironment,
    /// The environment's alias table (reference.glsl), four words a texel.
    alias: TexelBuffer,
    /// Σ luminance × solid angle of the map; 0 turns environment sampling off (black map).
    pub env_total: f32,
    /// The scene's lights as `ReferenceLight`s (one unused entry when there are none: a
    /// storage buffer may not be empty).
    pub lights: Buffer,
    pub light_count: u32,
    /// Per BVH triangle, the scene vertex indices (groups, meshes, vertices in scene order) of its
    /// v0, v1, v2: where a hit finds the per-vertex radiance of the irradiance mode's bounce.
    pub triangle_vertices: Buffer,
}

impl ReferenceLighting {
    pub fn new(ctx: &Arc<Context>, scene: &Scene) -> Result<ReferenceLighting> {
        let scene_bvh = SceneBvh::build(scene)?;
        let bvh = GpuBvh::new(ctx, &scene_bvh)?;
        let distribution = EnvDistribution::new(&scene.environment);
        let storage = BufferUsage::STORAGE;
        let alias: Vec<u8> = distribution.alias_words().iter().flat_map(|v| v.to_ne_bytes()).collect();
        let mut lights: Vec<ReferenceLight> = scene.lights.iter().map(reference_light).collect();
        if lights.is_empty() {
            lights.push(ReferenceLight::default());
        }
        Ok(ReferenceLighting {
            bvh,
            env: GpuEnvironment::new(ctx, &scene.environment)?,
            alias: TexelBuffer::with_data(ctx, "env_alias_table", &alias)?,
            env_total: distribution.total(),
            lights: Buffer::with_data(ctx, "reference_lights", storage, bytes_of_slice(&lights))?,
            light_count: scene.lights.len() as u32,
            triangle_vertices: Buffer::with_data(
                ctx,
                "reference_triangle_vertices",
                storage,
                &triangle_vertices(scene, &scene_bvh)
                    .iter()
                    .flatten()
                    .flat_map(|v| v.to_ne_bytes())
                    .collect::<Vec<u8>>(),
            )?,
        })
    }

    /// The binding kinds of a reference shader: these, then the shader's own `extra`.
    pub fn binding_kinds(extra: &[BindingKind]) -> Vec<BindingKind> {
        let mut kinds = GpuBvh::BINDING_KINDS.to_vec();
        kinds.extend([BindingKind::SampledImage, BindingKind::TexelBuffer]);
        kinds.extend_from_slice(extra);
        kinds
    }

    /// The bindings matching [`ReferenceLighting::binding_kinds`], then `extra`.
    pub fn bindings<'a>(&'a self, extra: &[&'a Buffer]) -> Vec<Binding<'a>> {
        let mut bindings: Vec<Binding> = self.bvh.bindings().into_iter().collect();
        bindings.extend([Binding::Sampled(&self.env.image, &self.env.sampler), Binding::Texel(&self.alias)]);
        bindings.extend(extra.iter().map(|b| Binding::Storage(b)));
        bindings
    }
}

/// See [`ReferenceLighting::triangle_vertices`]; the fourth index is unused.
fn triangle_vertices(scene: &Scene, bvh: &SceneBvh) -> Vec<[u32; 4]> {
    let mut first = Vec::new();
    let mut next = 0u32;
    for group in &scene.groups {
        first.push(
            group
                .meshes
                .iter()
                .map(|mesh| {
                    let base = next;
                    next += mesh.positions.len() as u32;
                    base
                })
                .collect::<Vec<_>>(),
        );
    }
    (0..bvh.triangle_count() as u32)
        .filter_map(|t| bvh.triangle_origin(t))
        .map(|o| {
            let mesh = &scene.groups[o.group as usize].meshes[o.mesh as usize];
            let base = first[o.group as usize][o.mesh as usize];
            let corner = |k: usize| base + mesh.indices[3 * o.triangle as usize + k];
            [corner(0), corner(1), corner(2), 0]
        })
        .collect()
}
