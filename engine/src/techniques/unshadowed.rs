//! Diffuse surfaces lit by the environment's SH irradiance, no shadows: L = albedo / π · E(n).
use super::scene_pass;
use super::{FrameInputs, FrameState, Technique};
use crate::backend::{
    vk, Binding, BindingKind, Buffer, Context, Depth, DepthTest, GraphicsPipeline, VertexAttribute,
    VertexBuffer,
};
use crate::error::Result;
use crate::layouts::{bytes_of, spirv, DrawPush};
use crate::pass::Pass;
use crate::renderer::{GpuMesh, GpuScene};
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
        Ok(Unshadowed { scene: scene_pipeline(ctx, "scene_unshadowed", spirv::SCENE_FRAG)? })
    }
}

/// A pipeline drawing `GpuScene` meshes with scene.vert and `fragment_spirv`, which reads
/// `FrameUniforms` (binding 0), one uniform buffer of lighting (binding 1) and a `DrawPush`.
pub fn scene_pipeline(ctx: &Arc<Context>, name: &str, fragment_spirv: &[u8]) -> Result<GraphicsPipeline> {
    let bindings = [BindingKind::UniformBuffer, BindingKind::UniformBuffer];
    scene_pass::scene_pipeline(
        ctx,
        name,
        (spirv::SCENE_VERT, fragment_spirv),
        &bindings,
        size_of::<DrawPush>(),
        DepthTest::Less,
    )
}

/// Draws, with `pipeline` bound, the meshes of `scene` for which `albedo` gives an albedo
/// (`None` leaves a mesh out), each with its group's transform.
pub fn draw_meshes(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    pipeline: &GraphicsPipeline,
    scene: &GpuScene,
    albedo: impl Fn(&GpuMesh) -> Option<[f32; 3]>,
) {
    for (mesh, albedo) in scene.meshes.iter().filter_map(|m| Some((m, albedo(m)?))) {
        let push = DrawPush {
            model: scene.transforms[mesh.group].to_cols_array_2d(),
            albedo: [albedo[0], albedo[1], albedo[2], 0.0],
        };
        pipeline.push(cmd, bytes_of(&push));
        ctx.draw_indexed(cmd, &[&mesh.vertices], &mesh.indices, mesh.index_count);
    }
}

impl Technique for Unshadowed {
    fn update(&mut self, _state: &FrameState) -> Result<()> {
        Ok(())
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let (ctx, uniforms, env_sh, scene, targets) =
            (inputs.ctx, inputs.uniforms, inputs.env_sh, inputs.scene, inputs.targets);
        vec![Pass::new("scene", &["frame_uniforms", "env_sh", "color"], &["color", "depth"], move |cmd| {
            ctx.begin_rendering(
                cmd,
                Some((&targets.color).into()),
                None,
                Some(Depth::Clear((&targets.depth).into())),
            );
            self.draw(ctx, cmd, uniforms, env_sh, scene, |mesh| Some(mesh.albedo));
            ctx.end_rendering(cmd);
        })]
    }
}

impl Unshadowed {
    /// Draws the meshes of `scene` lit by `sh` (`ShCoeffs` in the map's frame) as seen with
    /// `uniforms` (`FrameUniforms`), inside a rendering scope with colour and depth. `albedo`
    /// gives each mesh's albedo, or `None` to leave the mesh out (black draws an occluder that
    /// reflects nothing).
    pub fn draw(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        uniforms: &Buffer,
        sh: &Buffer,
        scene: &GpuScene,
        albedo: impl Fn(&GpuMesh) -> Option<[f32; 3]>,
    ) {
        self.scene.bind(cmd, &[Binding::Uniform(uniforms), Binding::Uniform(sh)]);
        draw_meshes(ctx, cmd, &self.scene, scene, albedo);
    }
}
