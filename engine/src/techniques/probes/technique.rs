//! The light-probe technique: each moving group (those with keyframes, whatever their place in
//! the scene; a scene without any moves its first group: see [`ProbeGroups`]) takes its
//! irradiance from the probes, E(n) = nᵀMn (Ramamoorthi & Hanrahan 2001) with M from the SH
//! interpolated at that group's centre by its own walker, which starts where its last frame's
//! lookup ended (one lookup per moving group per frame, on the host; with trilinear
//! interpolation, from the grid cell instead; by default without the probes that centre cannot
//! see, [`super::ProbeVisibility`]), written to its own `ProbeLight` uniform buffer
//! and bound for its draws; negative irradiance is clamped; times albedo / π. The static groups
//! keep their own lighting in the same frame and depth buffer: the unshadowed technique's
//! (environment SH, no shadows) or Sloan's PRT (self-shadowed among the static groups: walls
//! shade each other). The probes are captured once, when the technique is built, with the
//! environment unrotated: turning the environment afterwards turns the static groups' light,
//! not the probes'.
use super::set::{bounds, ProbeGroups, ProbeSet, ProbeSettings, StaticLighting};
use super::{LookupCounts, Walker};
use crate::backend::{
    Binding, Buffer, BufferDesc, BufferUsage, Context, Depth, GraphicsPipeline, MemoryLocation,
};
use crate::error::{Error, Result};
use crate::frame::scene_pass::{bind_lit, draw_lit_meshes, lighting_pipeline};
use crate::frame::GpuScene;
use crate::frame::{FrameInputs, FrameState};

use crate::layouts::{bytes_of, spirv, ProbeLight};
use crate::pass::Pass;
use crate::progress::Progress;
use crate::prt::TransferSet;
use crate::scene::Scene;
use crate::techniques::sloan;

use crate::techniques::tamura::technique::PrtTechnique;
use crate::techniques::unshadowed::Unshadowed;
use crate::techniques::{Technique, TechniqueStats};
use glam::Vec3;
use std::sync::Arc;

/// The static groups' lighting.
enum Statics {
    Unshadowed(Unshadowed),
    /// Sloan's PRT (a PRT technique without regions), drawing the static groups only.
    Sloan(Box<PrtTechnique>),
}

/// A moving group and its own probe lookup.
struct Lit {
    group: usize,
    /// The group's centre in its object space (its bounding box's), where it looks up its light;
    /// `None` when it has no vertices (nothing to light).
    centre: Option<Vec3>,
    walker: Walker,
    /// Its `ProbeLight`.
    light: Buffer,
}

pub struct ProbeTechnique {
    statics: Statics,
    pipeline: GraphicsPipeline,
    set: ProbeSet,
    groups: ProbeGroups,
    /// One per moving group, in the scene's order.
    lit: Vec<Lit>,
    /// Every lookup since the technique was built, by what its visibility test did.
    lookups: LookupCounts,
}

impl ProbeTechnique {
    /// Captures the probes (see [`ProbeSet::capture`], which `progress` hears). `transfer`: the
    /// PRT transfer, which static groups lit by Sloan's PRT need.
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        gpu: &GpuScene,
        settings: &ProbeSettings,
        transfer: Option<&TransferSet>,
        progress: &mut Progress,
    ) -> Result<ProbeTechnique> {
        let groups = ProbeGroups::of(scene);
        let statics = match (settings.statics, transfer) {
            (StaticLighting::Unshadowed, _) => Statics::Unshadowed(Unshadowed::new(ctx)?),
            (StaticLighting::Sloan, Some(transfer)) => {
                let drawn = (0..scene.groups.len()).map(|g| groups.is_static(g)).collect();
                let prt = sloan::new(ctx, scene, gpu, transfer)?.for_groups(drawn);
                Statics::Sloan(Box::new(prt))
            }
            (StaticLighting::Sloan, None) => {
                return Err(Error::InvalidArgument(
                    "static groups lit by Sloan's PRT need the PRT transfer: precompute it first".into(),
                ))
            }
        };
        let set = ProbeSet::capture(ctx, scene, gpu, settings, progress)?;
        if groups.fallback() {
            eprintln!(
                "kage: note: no group of scene \"{}\" has keyframes: its first group, {}, is the moving one the probes light",
                scene.name,
                groups.describe(scene)
            );
        }
        let lit = groups
            .moving()
            .iter()
            .map(|&group| {
                let meshes = &scene.groups[group].meshes;
                let points = meshes.iter().flat_map(|m| m.positions.iter().map(|p| Vec3::from(*p)));
                let light = Buffer::new(
                    ctx,
                    &BufferDesc {
                        name: &format!("{}.probe_light", scene.groups[group].name),
                        size: size_of::<ProbeLight>() as u64,
                        usage: BufferUsage::UNIFORM,
                        location: MemoryLocation::CpuToGpu,
                    },
                )?;
                let centre = bounds(points).map(|(lo, hi)| (lo + hi) * 0.5);
                Ok(Lit { group, centre, walker: Walker::default(), light })
            })
            .collect::<Result<_>>()?;
        Ok(ProbeTechnique {
            statics,
            pipeline: lighting_pipeline(ctx, "scene_probes", spirv::PROBE_SCENE_FRAG)?,
            set,
            groups,
            lit,
            lookups: LookupCounts::default(),
        })
    }
}

impl Technique for ProbeTechnique {
    fn update(&mut self, state: &FrameState) -> Result<()> {
        if let Statics::Sloan(prt) = &mut self.statics {
            prt.update(state)?;
        }
        for lit in &mut self.lit {
            let (Some(centre), Some(transform)) = (lit.centre, state.transforms.get(lit.group)) else {
                continue;
            };
            let lookup = self.set.lookup(&mut lit.walker, transform.transform_point3(centre).as_dvec3())?;
            self.lookups.count(lookup.seen);
            let sh = self.set.blend(&lookup.weights);
            let [red, green, blue] = sh.irradiance_matrix().map(|m| m.to_cols_array_2d());
            lit.light.write(0, bytes_of(&ProbeLight { red, green, blue }))?;
        }
        Ok(())
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let (ctx, uniforms, env_sh, scene, targets) =
            (inputs.ctx, inputs.uniforms, inputs.env_sh, inputs.scene, inputs.targets);
        let mut passes = match &self.statics {
            Statics::Unshadowed(_) => Vec::new(),
            Statics::Sloan(prt) => prt.prepasses(ctx, scene),
        };
        passes.push(Pass::new("scene", move |cmd| {
            ctx.begin_rendering(
                cmd,
                Some((&targets.color).into()),
                None,
                Some(Depth::Clear((&targets.depth).into())),
            );
            let groups = &self.groups;
            match &self.statics {
                Statics::Unshadowed(unshadowed) => unshadowed.draw(ctx, cmd, uniforms, env_sh, scene, |m| {
                    groups.is_static(m.group).then_some(m.albedo)
                }),
                Statics::Sloan(prt) => prt.record_draws(ctx, cmd, uniforms, scene),
            }
            // Each moving group with its own light.
            for lit in self.lit.iter().filter(|lit| lit.centre.is_some()) {
                bind_lit(
                    cmd,
                    &self.pipeline,
                    scene,
                    &[Binding::Uniform(uniforms), Binding::Uniform(&lit.light)],
                );
                draw_lit_meshes(ctx, cmd, &self.pipeline, scene, |m| {
                    (m.group == lit.group).then_some(m.albedo)
                });
            }
            ctx.end_rendering(cmd);
        }));
        passes
    }

    fn stats(&self) -> TechniqueStats {
        TechniqueStats {
            probes: Some(self.set.counts()),
            probe_capture: self.set.capture_cost,
            probe_lookups: Some(self.lookups),
            ..Default::default()
        }
    }
}
