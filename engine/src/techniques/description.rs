//! A technique named with its parameters: the one description the command line and the C ABI
//! both convert into, checked in one place ([`TechniqueDesc::validated`]) before any GPU work,
//! and built into the running technique by [`TechniqueDesc::build`].
//!
//! Adding a technique: its folder or file under `techniques/`, a [`TechniqueKind`] value, a
//! [`TechniqueDesc`] variant (the compiler then asks for its arms here, in
//! [`TechniqueDesc::from_params`] among them); a new kind of parameter is a [`TechniqueParams`]
//! method, which the command line (`tools/src/render.rs`) and the C ABI (`capi/technique.rs`)
//! then implement.
use super::asm::technique::Asm;
use super::asm::AsmSettings;
use super::parallel_lights::{ParallelLights, DEFAULT_SHADOW_MAP_SIZE};
use super::probes::technique::ProbeTechnique;
use super::probes::{ProbeSettings, StaticLighting};
use super::shadow_map::ShadowMap;
use super::tamura::technique::{OcclusionSettings, PrtTechnique};
use super::unshadowed::Unshadowed;
use super::{sloan, Technique};
use crate::backend::Context;
use crate::error::{Error, Result};
use crate::frame::GpuScene;
use crate::progress::Progress;
use crate::prt::{PrtParams, TransferSet, Visibility};
use crate::scene::Scene;
use std::sync::Arc;

/// The lighting techniques by name. The values are the C ABI's `kage_technique` and never
/// change; the command line spells them in kebab case.
#[repr(u32)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, strum::FromRepr)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum TechniqueKind {
    /// SH irradiance, no shadows.
    #[default]
    Unshadowed = 0,
    /// Sloan et al. 2002: per-vertex PRT, self-shadowing within each group only. Needs the PRT
    /// precomputation.
    SloanSelf = 1,
    /// Sloan et al. 2002 as the Tamura paper compares against: per-vertex PRT whose visibility
    /// is the whole scene as it stood when precomputed (shadows between groups baked into the
    /// vertices; they stay where they were when groups move). Needs the PRT precomputation.
    SloanScene = 7,
    /// Tamura, Johan, Nishita: PRT plus soft shadows between moving groups from q environment
    /// regions, the map's few brightest small lights (a sun, lamps) taken out and lit per pixel
    /// with soft shadows. Needs the PRT precomputation.
    Tamura = 2,
    /// Tamura, Johan, Nishita as the paper has it: q regions, the fixed penumbra from each
    /// region's solid angle, no dominant lights. Needs the PRT precomputation.
    TamuraPaper = 8,
    /// The paper's Fig. 3 baseline: the q regions as directional lights with binary shadow maps.
    ParallelLights = 3,
    /// The scene's point and spot lights (1 to 8), one conventional shadow map each (hard
    /// shadows).
    #[cfg_attr(feature = "clap", value(name = "shadowmap"))]
    ShadowMap = 5,
    /// Morishige 2014: light probes captured as SH when the renderer is made light the scene's
    /// moving groups (those with keyframes, each at its own place; a scene without any moves its
    /// first group, with a note); the other groups are captured by the probes and lit as the
    /// probe statics say.
    Probes = 4,
    /// Adaptive shadow maps (Fernando et al. 2001) for the scene's one point or spot light: a
    /// quadtree of tiles in a page pool of a memory budget, refined where the eye sees shadow
    /// edges coarser than its pixels.
    Asm = 6,
}

/// Which of a scene's lights a technique renders: each models its paper's light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RenderedLight {
    /// The environment alone (with the dominant lights taken out of its map, for Tamura); the
    /// scene's point and spot lights are left out.
    Environment,
    /// The scene's point and spot lights alone; the environment is left out.
    Local,
    /// The environment on the static groups; on the moving groups whatever the probes
    /// captured: the environment and the point and spot lights.
    Probes,
}

impl TechniqueKind {
    /// The lights this technique renders.
    pub fn rendered_light(self) -> RenderedLight {
        match self {
            TechniqueKind::Unshadowed
            | TechniqueKind::SloanSelf
            | TechniqueKind::SloanScene
            | TechniqueKind::Tamura
            | TechniqueKind::TamuraPaper
            | TechniqueKind::ParallelLights => RenderedLight::Environment,
            TechniqueKind::ShadowMap | TechniqueKind::Asm => RenderedLight::Local,
            TechniqueKind::Probes => RenderedLight::Probes,
        }
    }
}

/// A technique and its parameters.
#[derive(Clone, Debug)]
pub enum TechniqueDesc {
    Unshadowed,
    SloanSelf {
        prt: PrtParams,
    },
    SloanScene {
        prt: PrtParams,
    },
    Tamura {
        prt: PrtParams,
        occlusion: OcclusionSettings,
    },
    /// q = `regions` regions on masks of `mask_size`² texels; everything else as published.
    TamuraPaper {
        prt: PrtParams,
        regions: usize,
        mask_size: u32,
    },
    /// `regions` (1 to 128) directional lights with shadow maps of `shadow_map_size`² texels.
    ParallelLights {
        regions: usize,
        shadow_map_size: u32,
    },
    /// One shadow map of `size`² texels per local light.
    ShadowMap {
        size: u32,
    },
    /// `prt` is read when the static groups are lit by Sloan's PRT.
    Probes {
        probes: ProbeSettings,
        prt: PrtParams,
    },
    Asm(AsmSettings),
}

impl Default for TechniqueDesc {
    fn default() -> Self {
        TechniqueDesc::new(TechniqueKind::default())
    }
}

/// Where a front end keeps the techniques' parameters: the command line's flags, the C ABI's
/// `kage_technique_desc`, or the defaults ([`Defaults`]). [`TechniqueDesc::from_params`] is the
/// one conversion into a technique's description, and asks only for what that technique reads,
/// so a front end never checks a field the technique ignores.
pub trait TechniqueParams {
    type Error;
    fn prt(&self) -> Result<PrtParams, Self::Error>;
    /// Environment regions q: Tamura's (both variants) and parallel lights'.
    fn regions(&self) -> usize;
    /// Side of a Tamura occlusion mask layer (both variants).
    fn mask_size(&self) -> u32;
    /// The rest of Tamura's settings, with `regions` and `mask_size`.
    fn occlusion(&self) -> Result<OcclusionSettings, Self::Error>;
    /// Parallel lights' and the shadowmap technique's map side.
    fn shadow_map_size(&self) -> u32;
    fn probes(&self) -> Result<ProbeSettings, Self::Error>;
    fn asm(&self) -> Result<AsmSettings, Self::Error>;
}

/// Every parameter at its default.
pub struct Defaults;

impl TechniqueParams for Defaults {
    type Error = std::convert::Infallible;
    fn prt(&self) -> Result<PrtParams, Self::Error> {
        Ok(PrtParams::DEFAULT)
    }
    fn regions(&self) -> usize {
        OcclusionSettings::default().regions
    }
    fn mask_size(&self) -> u32 {
        OcclusionSettings::default().mask_size
    }
    fn occlusion(&self) -> Result<OcclusionSettings, Self::Error> {
        Ok(OcclusionSettings::default())
    }
    fn shadow_map_size(&self) -> u32 {
        DEFAULT_SHADOW_MAP_SIZE
    }
    fn probes(&self) -> Result<ProbeSettings, Self::Error> {
        Ok(ProbeSettings::default())
    }
    fn asm(&self) -> Result<AsmSettings, Self::Error> {
        Ok(AsmSettings::default())
    }
}

impl TechniqueDesc {
    /// `kind` with every parameter at its default.
    pub fn new(kind: TechniqueKind) -> TechniqueDesc {
        let Ok(desc) = TechniqueDesc::from_params(kind, &Defaults);
        desc
    }

    /// `kind` with the parameters it reads from `params` (not yet checked: see
    /// [`TechniqueDesc::validated`]).
    pub fn from_params<P: TechniqueParams>(
        kind: TechniqueKind,
        params: &P,
    ) -> Result<TechniqueDesc, P::Error> {
        Ok(match kind {
            TechniqueKind::Unshadowed => TechniqueDesc::Unshadowed,
            TechniqueKind::SloanSelf => TechniqueDesc::SloanSelf { prt: params.prt()? },
            TechniqueKind::SloanScene => TechniqueDesc::SloanScene { prt: params.prt()? },
            TechniqueKind::Tamura => {
                TechniqueDesc::Tamura { prt: params.prt()?, occlusion: params.occlusion()? }
            }
            TechniqueKind::TamuraPaper => TechniqueDesc::TamuraPaper {
                prt: params.prt()?,
                regions: params.regions(),
                mask_size: params.mask_size(),
            },
            TechniqueKind::ParallelLights => TechniqueDesc::ParallelLights {
                regions: params.regions(),
                shadow_map_size: params.shadow_map_size(),
            },
            TechniqueKind::ShadowMap => TechniqueDesc::ShadowMap { size: params.shadow_map_size() },
            TechniqueKind::Probes => TechniqueDesc::Probes { probes: params.probes()?, prt: params.prt()? },
            TechniqueKind::Asm => TechniqueDesc::Asm(params.asm()?),
        })
    }

    pub fn kind(&self) -> TechniqueKind {
        match self {
            TechniqueDesc::Unshadowed => TechniqueKind::Unshadowed,
            TechniqueDesc::SloanSelf { .. } => TechniqueKind::SloanSelf,
            TechniqueDesc::SloanScene { .. } => TechniqueKind::SloanScene,
            TechniqueDesc::Tamura { .. } => TechniqueKind::Tamura,
            TechniqueDesc::TamuraPaper { .. } => TechniqueKind::TamuraPaper,
            TechniqueDesc::ParallelLights { .. } => TechniqueKind::ParallelLights,
            TechniqueDesc::ShadowMap { .. } => TechniqueKind::ShadowMap,
            TechniqueDesc::Probes { .. } => TechniqueKind::Probes,
            TechniqueDesc::Asm(_) => TechniqueKind::Asm,
        }
    }

    /// The same technique with `prt` as its transfer's bands and rays, where it has a
    /// transfer (the visibility stays the technique's own, see [`TechniqueDesc::precomputation`]).
    pub fn with_prt(mut self, params: PrtParams) -> TechniqueDesc {
        match &mut self {
            TechniqueDesc::SloanSelf { prt }
            | TechniqueDesc::SloanScene { prt }
            | TechniqueDesc::Tamura { prt, .. }
            | TechniqueDesc::TamuraPaper { prt, .. }
            | TechniqueDesc::Probes { prt, .. } => *prt = params,
            TechniqueDesc::Unshadowed
            | TechniqueDesc::ParallelLights { .. }
            | TechniqueDesc::ShadowMap { .. }
            | TechniqueDesc::Asm(_) => {}
        }
        self
    }

    /// The PRT precomputation the technique needs before its first frame, if any.
    pub fn precomputation(&self) -> Option<PrtParams> {
        let group = |prt: &PrtParams| Some(PrtParams { visibility: Visibility::Group, ..*prt });
        match self {
            TechniqueDesc::SloanSelf { prt }
            | TechniqueDesc::Tamura { prt, .. }
            | TechniqueDesc::TamuraPaper { prt, .. } => group(prt),
            TechniqueDesc::SloanScene { prt } => Some(PrtParams { visibility: Visibility::Scene, ..*prt }),
            TechniqueDesc::Probes { probes, prt } if probes.statics == StaticLighting::Sloan => group(prt),
            _ => None,
        }
    }

    /// Checks every parameter that can be checked before GPU work, so that a bad one fails
    /// before a long precomputation.
    pub fn validated(mut self) -> Result<TechniqueDesc> {
        if let Some(prt) = self.precomputation() {
            prt.validated()?;
        }
        // Zero regions would quietly be Sloan's technique.
        let at_least_one_region = |regions: usize| match regions {
            0 => Err(Error::InvalidArgument("regions must be at least 1 for the Tamura technique".into())),
            _ => Ok(()),
        };
        match &mut self {
            TechniqueDesc::Tamura { occlusion, .. } => {
                at_least_one_region(occlusion.regions)?;
                *occlusion = occlusion.validated()?;
            }
            TechniqueDesc::TamuraPaper { regions, mask_size, .. } => {
                at_least_one_region(*regions)?;
                OcclusionSettings::paper(*regions, *mask_size).validated()?;
            }
            TechniqueDesc::Probes { probes, .. } => *probes = probes.clone().validated()?,
            TechniqueDesc::Asm(asm) => *asm = asm.validated()?,
            TechniqueDesc::ParallelLights { regions, shadow_map_size } => {
                super::parallel_lights::check(*regions, *shadow_map_size)?
            }
            TechniqueDesc::ShadowMap { size } => {
                super::shadow_map::check_map_size(*size, super::shadow_map::SHADOW_MAP_SIZES)?
            }
            TechniqueDesc::Unshadowed
            | TechniqueDesc::SloanSelf { .. }
            | TechniqueDesc::SloanScene { .. } => {}
        }
        Ok(self)
    }

    /// `transfer` if it is what [`Self::precomputation`] asks for; `None` when the technique
    /// needs none.
    fn transfer<'t>(&self, transfer: Option<&'t Arc<TransferSet>>) -> Result<Option<&'t TransferSet>> {
        let Some(wanted) = self.precomputation() else { return Ok(None) };
        let kind = self.kind();
        match transfer {
            None => Err(Error::InvalidArgument(format!(
                "the {kind:?} technique needs the PRT transfer: precompute it first"
            ))),
            Some(t) if t.params.bands != wanted.bands => Err(Error::InvalidArgument(format!(
                "the transfer was precomputed with {} SH bands, the technique asks for {}",
                t.params.bands, wanted.bands
            ))),
            Some(t) if t.params.visibility != wanted.visibility => Err(Error::InvalidArgument(format!(
                "the transfer was precomputed with {:?} visibility, the {kind:?} technique needs {:?}",
                t.params.visibility, wanted.visibility
            ))),
            Some(t) => Ok(Some(t.as_ref())),
        }
    }

    /// Builds the technique for `scene` (on the GPU as `gpu`) and images of `size`, after
    /// [`Self::validated`]; `transfer` is the result of [`Self::precomputation`]. `progress`
    /// hears the long work of building (the light probes' capture).
    pub fn build(
        &self,
        ctx: &Arc<Context>,
        scene: &Scene,
        gpu: &GpuScene,
        transfer: Option<&Arc<TransferSet>>,
        size: (u32, u32),
        progress: &mut Progress,
    ) -> Result<Box<dyn Technique>> {
        let desc = self.clone().validated()?;
        let transfer = desc.transfer(transfer)?;
        let prt = || transfer.ok_or_else(|| Error::Internal("a PRT technique without its transfer".into()));
        Ok(match &desc {
            TechniqueDesc::Unshadowed => Box::new(Unshadowed::new(ctx)?),
            TechniqueDesc::SloanSelf { .. } | TechniqueDesc::SloanScene { .. } => {
                Box::new(sloan::new(ctx, scene, gpu, prt()?)?)
            }
            TechniqueDesc::Tamura { occlusion, .. } => {
                Box::new(PrtTechnique::new(ctx, scene, gpu, prt()?, *occlusion)?)
            }
            TechniqueDesc::TamuraPaper { regions, mask_size, .. } => Box::new(PrtTechnique::new(
                ctx,
                scene,
                gpu,
                prt()?,
                OcclusionSettings::paper(*regions, *mask_size),
            )?),
            TechniqueDesc::ParallelLights { regions, shadow_map_size } => {
                Box::new(ParallelLights::new(ctx, scene, *regions, *shadow_map_size)?)
            }
            TechniqueDesc::ShadowMap { size } => Box::new(ShadowMap::new(ctx, scene, *size)?),
            TechniqueDesc::Probes { probes, .. } => {
                Box::new(ProbeTechnique::new(ctx, scene, gpu, probes, transfer, progress)?)
            }
            TechniqueDesc::Asm(settings) => Box::new(Asm::new(ctx, scene, gpu, *settings, size)?),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::asm::AsmTimeBudget;
    use crate::techniques::probes::ProbePlacement;

    fn transfer(bands: u32, visibility: Visibility) -> Option<Arc<TransferSet>> {
        let params = PrtParams { bands, rays: 1, visibility };
        Some(Arc::new(TransferSet { params, seconds: 0.0, traversal_seconds: 0.0, meshes: vec![] }))
    }

    fn invalid(desc: TechniqueDesc) -> String {
        desc.validated().unwrap_err().to_string()
    }

    /// Every kind's defaults name that kind, and its value is the one kage.h gives it.
    #[test]
    fn each_kind_has_its_desc_and_its_value() {
        for value in 0..=8 {
            let kind = TechniqueKind::from_repr(value).unwrap();
            assert_eq!(kind as u32, value);
            let desc = TechniqueDesc::new(kind);
            assert_eq!(desc.kind(), kind);
            desc.validated().unwrap();
        }
        assert_eq!(TechniqueKind::from_repr(9), None);
    }

    #[test]
    fn the_precomputation_follows_the_technique() {
        let group = Some(PrtParams::DEFAULT);
        let scene = Some(PrtParams { visibility: Visibility::Scene, ..PrtParams::DEFAULT });
        for (kind, wanted) in [
            (TechniqueKind::Unshadowed, None),
            (TechniqueKind::SloanSelf, group),
            (TechniqueKind::SloanScene, scene),
            (TechniqueKind::Tamura, group),
            (TechniqueKind::TamuraPaper, group),
            (TechniqueKind::ParallelLights, None),
            (TechniqueKind::ShadowMap, None),
            (TechniqueKind::Probes, None),
            (TechniqueKind::Asm, None),
        ] {
            assert_eq!(TechniqueDesc::new(kind).precomputation(), wanted, "{kind:?}");
        }
        // Static groups lit by Sloan's PRT: the probes technique needs the transfer too.
        let probes = ProbeSettings { statics: StaticLighting::Sloan, ..Default::default() };
        let sloan_statics = TechniqueDesc::Probes { probes, prt: PrtParams::DEFAULT };
        assert_eq!(sloan_statics.precomputation(), group);
        assert!(sloan_statics.transfer(None).unwrap_err().to_string().contains("precompute it first"));
    }

    #[test]
    fn a_missing_or_mismatched_transfer_is_an_error() {
        let tamura = TechniqueDesc::new(TechniqueKind::Tamura);
        let error = |t: Option<Arc<TransferSet>>| tamura.transfer(t.as_ref()).unwrap_err().to_string();
        assert!(error(None).contains("precompute it first"));
        assert!(error(transfer(4, Visibility::Group)).contains("4 SH bands"));
        assert!(error(transfer(3, Visibility::Scene)).contains("Scene visibility"));
        assert!(tamura.transfer(transfer(3, Visibility::Group).as_ref()).unwrap().is_some());
        let scene = TechniqueDesc::new(TechniqueKind::SloanScene);
        let group = transfer(3, Visibility::Group);
        assert!(scene.transfer(group.as_ref()).unwrap_err().to_string().contains("Group visibility"));
        assert!(TechniqueDesc::Unshadowed.transfer(None).unwrap().is_none());
    }

    #[test]
    fn bad_parameters_are_errors_naming_them() {
        let tamura = |change: fn(&mut OcclusionSettings)| {
            let mut occlusion = OcclusionSettings::default();
            change(&mut occlusion);
            TechniqueDesc::Tamura { prt: PrtParams::DEFAULT, occlusion }
        };
        assert!(invalid(tamura(|o| o.regions = 0)).contains("at least 1"));
        assert!(invalid(tamura(|o| o.dominant_lights = 9)).contains("dominant lights: 9"));
        assert!(invalid(tamura(|o| o.light_map_size = 8)).contains("light map size 8"));
        assert!(invalid(tamura(|o| o.mask_size = 4)).contains("mask size 4"));
        let paper = TechniqueDesc::TamuraPaper { prt: PrtParams::DEFAULT, regions: 0, mask_size: 128 };
        assert!(invalid(paper).contains("at least 1"));
        let bands = TechniqueDesc::SloanSelf { prt: PrtParams { bands: 9, ..PrtParams::DEFAULT } };
        assert!(invalid(bands).contains("9 SH bands"));
        let mut probes = ProbeSettings { placement: ProbePlacement::Grid([2, 1, 2]), ..Default::default() };
        let desc = |probes| TechniqueDesc::Probes { probes, prt: PrtParams::DEFAULT };
        assert!(invalid(desc(probes.clone())).contains("probe grid [2, 1, 2]"));
        probes = ProbeSettings::default();
        probes.capture.cube_size = 512;
        assert!(invalid(desc(probes)).contains("cube map size 512"));
        let asm = |budget_mb, time_ms| {
            let time = AsmTimeBudget { time_ms, ..Default::default() };
            TechniqueDesc::Asm(AsmSettings { budget_mb, time, ..Default::default() })
        };
        assert!(invalid(asm(0.01, 8.0)).contains("holds no tile"));
        assert!(invalid(asm(f64::INFINITY, 8.0)).contains("finite number of MB"));
        assert!(invalid(asm(16.0, 0.0)).contains("time budget"));
        for time_share in [0.0, 101.0, f64::NAN] {
            let time = AsmTimeBudget { time_share, ..Default::default() };
            let share = TechniqueDesc::Asm(AsmSettings { time, ..Default::default() });
            assert!(invalid(share).contains("ASM time share"));
        }
        let levels = TechniqueDesc::Asm(AsmSettings { extra_levels: 9, ..Default::default() });
        assert!(invalid(levels).contains("9 extra ASM levels: at most 8"));
        // Parallel lights and shadow maps are checked here too, before anything is built.
        let parallel = |regions, shadow_map_size| TechniqueDesc::ParallelLights { regions, shadow_map_size };
        assert!(invalid(parallel(129, 512)).contains("q = 129 regions, must be 1 to 128"));
        assert!(invalid(parallel(32, 4096)).contains("shadow map size 4096 must be 16 to 2048"));
        assert!(invalid(TechniqueDesc::ShadowMap { size: 8 }).contains("shadow map size 8 must be 16 to"));
    }
}
