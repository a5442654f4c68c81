//! The first technique: diffuse surfaces lit by the environment's SH irradiance, no shadows,
//! over a background that shows the environment. Later techniques reuse its background pass.
use super::environment::GpuEnvironment;
use crate::backend::{
    vk, Binding, BindingKind, Buffer, Context, GraphicsDesc, GraphicsPipeline, VertexAttribute,
    VertexBuffer,
};
use crate::error::Result;
use crate::layouts::{bytes_of, spirv, DrawPush};
use crate::pass::Pass;
use crate::renderer::{GpuScene, Targets, COLOR_FORMAT, DEPTH_FORMAT};
use std::sync::Arc;

pub struct Unshadowed {
    ctx: Arc<Context>,
    background: GraphicsPipeline,
    scene: GraphicsPipeline,
}

/// Vertex layout of `GpuScene` meshes: position then normal, 3 floats each.
pub const VERTEX_STRIDE: u32 = 24;
pub const MESH_ATTRIBUTES: [VertexAttribute; 2] = [
    VertexAttribute {
        location: 0,
        format: vk::Format::R32G32B32_SFLOAT,
        offset: 0,
    },
    VertexAttribute {
        location: 1,
        format: vk::Format::R32G32B32_SFLOAT,
        offset: 12,
    },
];

impl Unshadowed {
    pub fn new(ctx: &Arc<Context>) -> Result<Unshadowed> {
        let background = GraphicsPipeline::new(
            ctx,
            &GraphicsDesc {
                name: "background",
                vertex_spirv: spirv::BACKGROUND_VERT,
                fragment_spirv: spirv::BACKGROUND_FRAG,
                bindings: &[BindingKind::UniformBuffer, BindingKind::SampledImage],
                push_size: 0,
                vertex_buffers: &[],
                topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                color_formats: &[COLOR_FORMAT],
                depth_format: None,
                depth_test: false,
                additive: false,
            },
        )?;
        let scene = GraphicsPipeline::new(
            ctx,
            &GraphicsDesc {
                name: "scene_unshadowed",
                vertex_spirv: spirv::SCENE_VERT,
                fragment_spirv: spirv::SCENE_FRAG,
                bindings: &[BindingKind::UniformBuffer, BindingKind::StorageBuffer],
                push_size: size_of::<DrawPush>() as u32,
                vertex_buffers: &[VertexBuffer {
                    stride: VERTEX_STRIDE,
                    attributes: &MESH_ATTRIBUTES,
                }],
                topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                color_formats: &[COLOR_FORMAT],
                depth_format: Some(DEPTH_FORMAT),
                depth_test: true,
                additive: false,
            },
        )?;
        Ok(Unshadowed {
            ctx: ctx.clone(),
            background,
            scene,
        })
    }

    /// "background" clears the colour target and draws the environment behind everything;
    /// "scene" draws every mesh over it with depth testing.
    pub fn passes<'a>(
        &'a self,
        frame_uniforms: &'a Buffer,
        env: &'a GpuEnvironment,
        env_sh: &'a Buffer,
        scene: &'a GpuScene,
        targets: &'a Targets,
    ) -> [Pass<'a>; 2] {
        let ctx = &self.ctx;
        [
            Pass::new(
                "background",
                &["frame_uniforms", "environment"],
                &["color"],
                move |cmd| {
                    ctx.begin_rendering(cmd, Some((&targets.color).into()), Some([0.0; 4]), None);
                    self.background.bind(
                        cmd,
                        &[
                            Binding::Uniform(frame_uniforms),
                            Binding::Sampled(&env.image, &env.sampler),
                        ],
                    );
                    ctx.draw(cmd, 3);
                    ctx.end_rendering(cmd);
                },
            ),
            Pass::new(
                "scene",
                &["frame_uniforms", "env_sh", "color"],
                &["color", "depth"],
                move |cmd| {
                    ctx.begin_rendering(
                        cmd,
                        Some((&targets.color).into()),
                        None,
                        Some((&targets.depth).into()),
                    );
                    self.scene.bind(
                        cmd,
                        &[Binding::Uniform(frame_uniforms), Binding::Storage(env_sh)],
                    );
                    for mesh in &scene.meshes {
                        let push = DrawPush {
                            model: scene.transforms[mesh.group].to_cols_array_2d(),
                            albedo: [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], 0.0],
                        };
                        self.scene.push(cmd, bytes_of(&push));
                        ctx.draw_indexed(cmd, &[&mesh.vertices], &mesh.indices, mesh.index_count);
                    }
                    ctx.end_rendering(cmd);
                },
            ),
        ]
    }
}
