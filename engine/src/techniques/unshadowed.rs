//! Diffuse surfaces lit by the environment's SH irradiance, no shadows: L = albedo / π · E(n).
use super::Technique;
use crate::backend::{Binding, Buffer, Cmd, Context, Depth, GraphicsPipeline};
use crate::error::Result;
use crate::frame::scene_pass::{bind_lit, draw_lit_meshes, lighting_pipeline};
use crate::frame::{FrameInputs, FrameState};
use crate::frame::{GpuMesh, GpuScene};
use crate::layouts::spirv;
use crate::pass::Pass;
use std::sync::Arc;

pub struct Unshadowed {
    scene: GraphicsPipeline,
}

impl Unshadowed {
    pub fn new(ctx: &Arc<Context>) -> Result<Unshadowed> {
        Ok(Unshadowed { scene: lighting_pipeline(ctx, "scene_unshadowed", spirv::SCENE_FRAG)? })
    }
}

impl Technique for Unshadowed {
    fn update(&mut self, _state: &FrameState) -> Result<()> {
        Ok(())
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let (ctx, uniforms, env_sh, scene, targets) =
            (inputs.ctx, inputs.uniforms, inputs.env_sh, inputs.scene, inputs.targets);
        vec![Pass::new("scene", move |cmd| {
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
        cmd: Cmd,
        uniforms: &Buffer,
        sh: &Buffer,
        scene: &GpuScene,
        albedo: impl Fn(&GpuMesh) -> Option<[f32; 3]>,
    ) {
        bind_lit(cmd, &self.scene, scene, &[Binding::Uniform(uniforms), Binding::Uniform(sh)]);
        draw_lit_meshes(ctx, cmd, &self.scene, scene, albedo);
    }
}
