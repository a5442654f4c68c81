//! The pass most techniques end with: every mesh drawn once into the colour and depth targets
//! by a pipeline that reads the mesh vertices (position, normal, texture coordinate), with
//! per-draw push constants and the mesh's albedo map as the pipeline's last binding (a lit
//! pipeline, [`lit_bindings`]). Shared by the unshadowed, parallel-lights, shadowmap and
//! adaptive shadow map techniques.
//!
//! The techniques with costly fragments (parallel lights, shadowmap, adaptive shadow maps, and
//! Tamura's PRT technique) lay the depth down first in a depth-only prepass computing the scene
//! pass's own positions, then shade only what it left visible: their lighting looks up shadow
//! maps or occlusion layers per fragment, and with the scene drawn in any order a fragment
//! hidden later would pay for it too (the `asm` scene's overdraw made its ASM lighting pass 2x
//! as long on lavapipe; BENCHMARKS.md).
use super::gpu_scene::MESH_VERTICES;
use super::shadow_depth::depth_only_pipeline;

use super::FrameInputs;
use crate::backend::{
    Binding, BindingKind, Cmd, Context, Depth, DepthTest, GraphicsDesc, GraphicsPipeline, Topology,
    VertexBuffer,
};
use crate::error::Result;
use crate::frame::{GpuMesh, GpuScene, COLOR_FORMAT, DEPTH_FORMAT};
use crate::layouts::{bytes_of, spirv, DrawPush, Pod};
use crate::pass::Pass;
use glam::Mat4;
use std::sync::Arc;

/// A lit pipeline's bindings: `bindings`, then the mesh's albedo map, which its fragment shader
/// declares through `albedo_map.glsl` at binding `bindings.len()` and which
/// [`GpuScene::bind_albedo_map`] pushes per draw.
pub fn lit_bindings(bindings: &[BindingKind]) -> Vec<BindingKind> {
    [bindings, &[BindingKind::SampledImage]].concat()
}

/// A lit scene pipeline named `name` from its two shaders, resources (before the albedo map,
/// [`lit_bindings`]) and push-constant size, drawing the meshes with the depth test `depth`
/// (`Equal` after [`depth_prepass`]).
pub fn scene_pipeline(
    ctx: &Arc<Context>,
    name: &str,
    shaders: (&[u8], &[u8]),
    bindings: &[BindingKind],
    push_size: usize,
    depth: DepthTest,
) -> Result<GraphicsPipeline> {
    scene_pipeline_with(ctx, name, shaders, bindings, push_size, &[MESH_VERTICES], depth)
}

/// The depth prepass' pipeline for scene pipelines whose push constants (`push_size` bytes)
/// begin with the model matrix: depth_prepass.vert, which computes the same
/// `gl_Position` (so the scene pass' EQUAL test meets the same depths), no colour.
pub fn depth_prepass_pipeline(ctx: &Arc<Context>, name: &str, push_size: usize) -> Result<GraphicsPipeline> {
    depth_only_pipeline(ctx, name, spirv::DEPTH_PREPASS_VERT, &[BindingKind::UniformBuffer], push_size)
}

/// The `depth_prepass` pass: every mesh's depth into the depth target, with the push constants
/// the scene pass gives it (`push`; the vertex shader reads the model matrix).
pub fn depth_prepass<'a, P: Pod>(
    frame: &FrameInputs<'a>,
    pipeline: &'a GraphicsPipeline,
    push: impl Fn(&GpuMesh, &Mat4) -> P + 'a,
) -> Pass<'a> {
    let (ctx, scene, targets, uniforms) = (frame.ctx, frame.scene, frame.targets, frame.uniforms);
    Pass::new("depth_prepass", move |cmd| {
        ctx.begin_rendering(cmd, None, None, Some(Depth::Clear((&targets.depth).into())));
        pipeline.bind(cmd, &[Binding::Uniform(uniforms)]);
        draw_meshes(ctx, cmd, scene, pipeline, false, &|m, t| Some(push(m, t)));
        ctx.end_rendering(cmd);
    })
}

/// [`scene_pipeline`] with other vertex buffers (per-vertex data beside the positions).
pub fn scene_pipeline_with(
    ctx: &Arc<Context>,
    name: &str,
    shaders: (&[u8], &[u8]),
    bindings: &[BindingKind],
    push_size: usize,
    vertex_buffers: &[VertexBuffer],
    depth: DepthTest,
) -> Result<GraphicsPipeline> {
    GraphicsPipeline::new(
        ctx,
        &GraphicsDesc {
            name,
            vertex_spirv: shaders.0,
            fragment_spirv: shaders.1,
            bindings: &lit_bindings(bindings),
            push_size: push_size as u32,
            vertex_buffers,
            topology: Topology::Triangles,
            color_formats: &[COLOR_FORMAT],
            depth_format: Some(DEPTH_FORMAT),
            depth,
            write_color: true,
            constants: &[],
        },
    )
}

/// The `scene` pass: binds `bindings`, then draws each mesh with the push constants
/// `push(mesh, its model matrix)` gives; over the depth prepass' depth when the pipeline tests
/// `Equal`, else into a cleared depth target.
pub fn scene_pass<'a, P: Pod>(
    frame: &FrameInputs<'a>,
    pipeline: &'a GraphicsPipeline,
    bindings: Vec<Binding<'a>>,
    push: impl Fn(&GpuMesh, &Mat4) -> P + 'a,
) -> Pass<'a> {
    let (ctx, scene, targets) = (frame.ctx, frame.scene, frame.targets);
    Pass::new("scene", move |cmd| {
        let depth = (&targets.depth).into();
        let depth =
            if pipeline.depth() == DepthTest::Equal { Depth::Keep(depth) } else { Depth::Clear(depth) };
        ctx.begin_rendering(cmd, Some((&targets.color).into()), None, Some(depth));
        bind_lit(cmd, pipeline, scene, &bindings);
        draw_meshes(ctx, cmd, scene, pipeline, true, &|m, t| Some(push(m, t)));
        ctx.end_rendering(cmd);
    })
}

/// Binds a lit pipeline with `bindings` and the first mesh's albedo map, which
/// [`draw_meshes`] replaces per draw.
pub fn bind_lit(cmd: Cmd, pipeline: &GraphicsPipeline, scene: &GpuScene, bindings: &[Binding]) {
    let first = scene.albedo_maps.binding(scene.meshes.first().map_or(0, |m| m.albedo_map));
    let all: Vec<Binding> = bindings.iter().cloned().chain([first]).collect();
    pipeline.bind(cmd, &all);
}

/// Draws the meshes of `scene` with the push constants `push(mesh, its model matrix)` gives
/// (`None` leaves a mesh out); `lit`: with each mesh's albedo map (a lit pipeline bound with
/// [`bind_lit`]).
pub fn draw_meshes<P: Pod>(
    ctx: &Context,
    cmd: Cmd,
    scene: &GpuScene,
    pipeline: &GraphicsPipeline,
    lit: bool,
    push: &impl Fn(&GpuMesh, &Mat4) -> Option<P>,
) {
    for mesh in &scene.meshes {
        if let Some(p) = push(mesh, &scene.transforms[mesh.group]) {
            if lit {
                scene.bind_albedo_map(cmd, pipeline, mesh);
            }
            pipeline.push(cmd, bytes_of(&p));
            ctx.draw_indexed(cmd, &[&mesh.vertices], &mesh.indices, mesh.index_count);
        }
    }
}

/// A lit pipeline drawing `GpuScene` meshes with scene.vert and `fragment_spirv`, which reads
/// `FrameUniforms` (binding 0), one uniform buffer of lighting (binding 1), the albedo map
/// (binding 2) and a `DrawPush`.
pub fn lighting_pipeline(ctx: &Arc<Context>, name: &str, fragment_spirv: &[u8]) -> Result<GraphicsPipeline> {
    let bindings = [BindingKind::UniformBuffer, BindingKind::UniformBuffer];
    scene_pipeline(
        ctx,
        name,
        (spirv::SCENE_VERT, fragment_spirv),
        &bindings,
        size_of::<DrawPush>(),
        DepthTest::Less,
    )
}

/// Draws, with a [`lighting_pipeline`] bound by [`bind_lit`], the meshes of `scene` for which
/// `albedo` gives an albedo (`None` leaves a mesh out), each with its group's transform and
/// albedo map.
pub fn draw_lit_meshes(
    ctx: &Context,
    cmd: Cmd,
    pipeline: &GraphicsPipeline,
    scene: &GpuScene,
    albedo: impl Fn(&GpuMesh) -> Option<[f32; 3]>,
) {
    draw_meshes(ctx, cmd, scene, pipeline, true, &|mesh, model| {
        let albedo = albedo(mesh)?;
        Some(DrawPush { model: model.to_cols_array_2d(), albedo: [albedo[0], albedo[1], albedo[2], 0.0] })
    });
}
