//! The light-probe technique: the moving group ([`MOVING_GROUP`]) takes its irradiance from
//! the probes, E(n) = nᵀMn (Ramamoorthi & Hanrahan 2001) with M from the SH interpolated at the
//! group's centre by a walker that starts where the last frame's lookup ended (one lookup per
//! object per frame, on the host; with trilinear interpolation, from the grid cell instead); negative irradiance is clamped; times albedo / π. The static
//! groups keep their own lighting: for now the unshadowed technique's (environment SH, no
//! shadows). The probes are captured once, when the technique is built, with the environment
//! unrotated: turning the environment afterwards turns the static groups' light, not the
//! probes'.
use super::set::{bounds, is_static, ProbeSet, ProbeSettings, MOVING_GROUP};
use super::Walker;
use crate::backend::{vk, Binding, Buffer, BufferDesc, Context, GraphicsPipeline, MemoryLocation};
use crate::error::Result;
use crate::layouts::{bytes_of, spirv, ProbeLight};
use crate::pass::Pass;
use crate::renderer::GpuScene;
use crate::scene::Scene;
use crate::techniques::unshadowed::{draw_meshes, scene_pipeline, Unshadowed};
use crate::techniques::{FrameInputs, FrameState, Technique};
use glam::Vec3;
use std::sync::Arc;

pub struct ProbeTechnique {
    statics: Unshadowed,
    pipeline: GraphicsPipeline,
    set: ProbeSet,
    /// The moving group's centre in its object space (its bounding box's), where it looks up
    /// its light; `None` when the scene has no such group.
    centre: Option<Vec3>,
    walker: Walker,
    /// `ProbeLight` of the moving group.
    light: Buffer,
}

impl ProbeTechnique {
    /// Captures the probes (see [`ProbeSet::capture`]).
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        gpu: &GpuScene,
        settings: &ProbeSettings,
    ) -> Result<ProbeTechnique> {
        let centre = scene.groups.get(MOVING_GROUP).and_then(|group| {
            let points = group.meshes.iter().flat_map(|m| m.positions.iter().map(|p| Vec3::from(*p)));
            bounds(points).map(|(lo, hi)| (lo + hi) * 0.5)
        });
        Ok(ProbeTechnique {
            statics: Unshadowed::new(ctx)?,
            pipeline: scene_pipeline(ctx, "scene_probes", spirv::PROBE_SCENE_FRAG)?,
            set: ProbeSet::capture(ctx, scene, gpu, settings)?,
            centre,
            walker: Walker::default(),
            light: Buffer::new(
                ctx,
                &BufferDesc {
                    name: "probe_light",
                    size: size_of::<ProbeLight>() as u64,
                    usage: vk::BufferUsageFlags::UNIFORM_BUFFER,
                    location: MemoryLocation::CpuToGpu,
                },
            )?,
        })
    }
}

impl Technique for ProbeTechnique {
    fn update(&mut self, state: &FrameState) -> Result<()> {
        let (Some(centre), Some(transform)) = (self.centre, state.transforms.get(MOVING_GROUP)) else {
            return Ok(());
        };
        let sh = self.set.interpolate(&mut self.walker, transform.transform_point3(centre))?;
        let [red, green, blue] = sh.irradiance_matrix().map(|m| m.to_cols_array_2d());
        self.light.write(0, bytes_of(&ProbeLight { red, green, blue }))
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let (ctx, uniforms, env_sh, scene, targets) =
            (inputs.ctx, inputs.uniforms, inputs.env_sh, inputs.scene, inputs.targets);
        vec![Pass::new("scene", &["frame_uniforms", "env_sh", "color"], &["color", "depth"], move |cmd| {
            ctx.begin_rendering(cmd, Some((&targets.color).into()), None, Some((&targets.depth).into()));
            self.statics.draw(ctx, cmd, uniforms, env_sh, scene, |m| is_static(m.group).then_some(m.albedo));
            self.pipeline.bind(cmd, &[Binding::Uniform(uniforms), Binding::Uniform(&self.light)]);
            draw_meshes(ctx, cmd, &self.pipeline, scene, |m| (!is_static(m.group)).then_some(m.albedo));
            ctx.end_rendering(cmd);
        })]
    }

    fn probe_counts(&self) -> Option<super::ProbeCounts> {
        Some(self.set.counts())
    }
}
