//! What both reference shaders bind first: the scene's BVH, the environment map and its
//! sampling distribution (bindings 0 .. BVH_BINDINGS + 3, in the order reference.glsl declares).
use super::env_sampling::EnvDistribution;
use crate::backend::{vk, Binding, BindingKind, Buffer, Context};
use crate::error::Result;
use crate::raycast::{GpuBvh, SceneBvh};
use crate::scene::Scene;
use crate::techniques::environment::GpuEnvironment;
use std::sync::Arc;

/// Resources the passes import: written before the first batch, read by every batch.
pub const IMPORTS: [&str; 3] = ["bvh", "environment", "env_distribution"];

pub struct ReferenceLighting {
    bvh: GpuBvh,
    env: GpuEnvironment,
    marginal: Buffer,
    conditional: Buffer,
    /// Σ luminance × solid angle of the map; 0 turns environment sampling off (black map).
    pub env_total: f32,
}

impl ReferenceLighting {
    pub fn new(ctx: &Arc<Context>, scene: &Scene) -> Result<ReferenceLighting> {
        let bvh = GpuBvh::new(ctx, &SceneBvh::build(scene)?)?;
        let distribution = EnvDistribution::new(&scene.environment);
        let upload = |name: &str, values: &[f32]| {
            let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_ne_bytes()).collect();
            Buffer::with_data(ctx, name, vk::BufferUsageFlags::STORAGE_BUFFER, &bytes)
        };
        Ok(ReferenceLighting {
            bvh,
            env: GpuEnvironment::new(ctx, &scene.environment)?,
            marginal: upload("env_marginal_cdf", distribution.marginal_cdf())?,
            conditional: upload("env_conditional_cdf", distribution.conditional_cdf())?,
            env_total: distribution.total(),
        })
    }

    /// The binding kinds of a reference shader: these, then the shader's own `extra`.
    pub fn binding_kinds(extra: &[BindingKind]) -> Vec<BindingKind> {
        let mut kinds = GpuBvh::BINDING_KINDS.to_vec();
        kinds.extend([BindingKind::SampledImage, BindingKind::StorageBuffer, BindingKind::StorageBuffer]);
        kinds.extend_from_slice(extra);
        kinds
    }

    /// The bindings matching [`ReferenceLighting::binding_kinds`], then `extra`.
    pub fn bindings<'a>(&'a self, extra: &[&'a Buffer]) -> Vec<Binding<'a>> {
        let mut bindings: Vec<Binding> = self.bvh.bindings().into_iter().collect();
        bindings.extend([
            Binding::Sampled(&self.env.image, &self.env.sampler),
            Binding::Storage(&self.marginal),
            Binding::Storage(&self.conditional),
        ]);
        bindings.extend(extra.iter().map(|b| Binding::Storage(b)));
        bindings
    }
}
