//! The pass most techniques end with: every mesh drawn once into the colour and depth targets
//! by a pipeline that reads the mesh vertices (position, normal), with per-draw push constants.
//! Shared by the unshadowed, parallel-lights and shadowmap techniques.
use super::unshadowed::MESH_VERTICES;
use super::FrameInputs;
use crate::backend::{vk, Binding, BindingKind, Context, GraphicsDesc, GraphicsPipeline, VertexBuffer};
use crate::error::Result;
use crate::layouts::{bytes_of, Pod};
use crate::pass::Pass;
use crate::renderer::{GpuMesh, COLOR_FORMAT, DEPTH_FORMAT};
use glam::Mat4;
use std::sync::Arc;

/// What a shadow-map technique's scene pass reads.
pub const SCENE_READS: [&str; 3] = ["frame_uniforms", "shadow_maps", "color"];

/// A scene pipeline named `name` from its two shaders, resources and push-constant size, drawing
/// the meshes' positions and normals.
pub fn scene_pipeline(
    ctx: &Arc<Context>,
    name: &str,
    shaders: (&[u8], &[u8]),
    bindings: &[BindingKind],
    push_size: usize,
) -> Result<GraphicsPipeline> {
    scene_pipeline_with(ctx, name, shaders, bindings, push_size, &[MESH_VERTICES])
}

/// [`scene_pipeline`] with other vertex buffers (per-vertex data beside the positions).
pub fn scene_pipeline_with(
    ctx: &Arc<Context>,
    name: &str,
    shaders: (&[u8], &[u8]),
    bindings: &[BindingKind],
    push_size: usize,
    vertex_buffers: &[VertexBuffer],
) -> Result<GraphicsPipeline> {
    GraphicsPipeline::new(
        ctx,
        &GraphicsDesc {
            name,
            vertex_spirv: shaders.0,
            fragment_spirv: shaders.1,
            bindings,
            push_size: push_size as u32,
            vertex_buffers,
            topology: vk::PrimitiveTopology::TRIANGLE_LIST,
            color_formats: &[COLOR_FORMAT],
            depth_format: Some(DEPTH_FORMAT),
            depth_test: true,
            additive: false,
            constants: &[],
        },
    )
}

/// The `scene` pass: binds `bindings`, then draws each mesh with the push constants
/// `push(mesh, its model matrix)` gives.
pub fn scene_pass<'a, P: Pod>(
    frame: &FrameInputs<'a>,
    reads: &'a [&'static str],
    pipeline: &'a GraphicsPipeline,
    bindings: Vec<Binding<'a>>,
    push: impl Fn(&GpuMesh, &Mat4) -> P + 'a,
) -> Pass<'a> {
    let (ctx, scene, targets) = (frame.ctx, frame.scene, frame.targets);
    Pass::new("scene", reads, &["color", "depth"], move |cmd| {
        ctx.begin_rendering(cmd, Some((&targets.color).into()), None, Some((&targets.depth).into()));
        pipeline.bind(cmd, &bindings);
        for mesh in &scene.meshes {
            let p = push(mesh, &scene.transforms[mesh.group]);
            pipeline.push(cmd, bytes_of(&p));
            ctx.draw_indexed(cmd, &[&mesh.vertices], &mesh.indices, mesh.index_count);
        }
        ctx.end_rendering(cmd);
    })
}
