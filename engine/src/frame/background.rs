//! The environment seen directly, behind everything: one full-screen triangle that clears the
//! colour target and looks up the map along each pixel's view ray.
use super::environment::GpuEnvironment;
use super::FrameInputs;
use crate::backend::{
    Binding, BindingKind, Buffer, Cmd, Context, DepthTest, GraphicsDesc, GraphicsPipeline, Topology,
};
use crate::error::Result;
use crate::frame::COLOR_FORMAT;
use crate::layouts::spirv;
use crate::pass::Pass;
use std::sync::Arc;

pub struct Background {
    pipeline: GraphicsPipeline,
}

impl Background {
    pub fn new(ctx: &Arc<Context>) -> Result<Background> {
        let pipeline = GraphicsPipeline::new(
            ctx,
            &GraphicsDesc {
                name: "background",
                vertex_spirv: spirv::BACKGROUND_VERT,
                fragment_spirv: spirv::BACKGROUND_FRAG,
                bindings: &[BindingKind::UniformBuffer, BindingKind::SampledImage],
                push_size: 0,
                vertex_buffers: &[],
                topology: Topology::Triangles,
                color_formats: &[COLOR_FORMAT],
                depth_format: None,
                depth: DepthTest::Off,
                write_color: true,
                constants: &[],
            },
        )?;
        Ok(Background { pipeline })
    }

    pub fn pass<'a>(&'a self, inputs: &FrameInputs<'a>) -> Pass<'a> {
        let (ctx, uniforms, env, color) =
            (inputs.ctx, inputs.uniforms, inputs.environment, &inputs.targets.color);
        Pass::new("background", move |cmd| {
            ctx.begin_rendering(cmd, Some(color.into()), Some([0.0; 4]), None);
            self.draw(ctx, cmd, uniforms, env);
            ctx.end_rendering(cmd);
        })
    }

    /// Draws the environment as seen with `uniforms` (`FrameUniforms`) into the current
    /// viewport, inside a rendering scope with a colour target only.
    pub fn draw(&self, ctx: &Context, cmd: Cmd, uniforms: &Buffer, env: &GpuEnvironment) {
        self.pipeline.bind(cmd, &[Binding::Uniform(uniforms), Binding::Sampled(&env.image, &env.sampler)]);
        ctx.draw(cmd, &[], 3);
    }
}
