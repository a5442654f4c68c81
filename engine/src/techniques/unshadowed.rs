//! Diffuse surfaces lit by the environment's SH irradiance, no shadows: L = albedo / π · E(n).
use super::scene_pass::{scene_pass, scene_pipeline};
use super::{FrameInputs, FrameState, Technique};
use crate::backend::{vk, Binding, BindingKind, Context, GraphicsPipeline, VertexAttribute, VertexBuffer};
use crate::error::Result;
use crate::layouts::{spirv, DrawPush};
use crate::pass::Pass;
use std::sync::Arc;

/// Vertex layout of `GpuScene` meshes: position then normal, 3 floats each.
pub const VERTEX_STRIDE: u32 = 24;
pub const MESH_ATTRIBUTES: [VertexAttribute; 2] = [
    VertexAttribute { location: 0, format: vk::Format::R32G32B32_SFLOAT, offset: 0 },
    VertexAttribute { location: 1, format: vk::Format::R32G32B32_SFLOAT, offset: 12 },
];
pub const MESH_VERTICES: VertexBuffer<'static> =
    VertexBuffer { stride: VERTEX_STRIDE, attributes: &MESH_ATTRIBUTES };
/// The same buffers read by shaders that need positions only.
pub const MESH_POSITIONS: VertexBuffer<'static> =
    VertexBuffer { stride: VERTEX_STRIDE, attributes: MESH_ATTRIBUTES.split_at(1).0 };

pub struct Unshadowed {
    scene: GraphicsPipeline,
}

impl Unshadowed {
    pub fn new(ctx: &Arc<Context>) -> Result<Unshadowed> {
        let scene = scene_pipeline(
            ctx,
            "scene_unshadowed",
            (spirv::SCENE_VERT, spirv::SCENE_FRAG),
            &[BindingKind::UniformBuffer, BindingKind::UniformBuffer],
            size_of::<DrawPush>(),
        )?;
        Ok(Unshadowed { scene })
    }
}

impl Technique for Unshadowed {
    fn update(&mut self, _state: &FrameState) -> Result<()> {
        Ok(())
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let bindings = vec![Binding::Uniform(inputs.uniforms), Binding::Uniform(inputs.env_sh)];
        vec![scene_pass(
            inputs,
            &["frame_uniforms", "env_sh", "color"],
            &self.scene,
            bindings,
            |mesh, model| DrawPush {
                model: model.to_cols_array_2d(),
                albedo: [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], 0.0],
            },
        )]
    }
}
