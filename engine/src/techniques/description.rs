//! A technique named with all its parameters: what the command line's options and the C ABI's
//! `kage_technique_desc` both turn into, checked in one place, and turned into the renderer's
//! [`TechniqueChoice`] once the precomputation it needs is done.
use super::asm::AsmSettings;
use super::parallel_lights::DEFAULT_SHADOW_MAP_SIZE;
use super::probes::{ProbeSettings, StaticLighting};
use super::tamura::occlusion::RegionSize;
use super::tamura::technique::{OcclusionSettings, Penumbra};
use crate::error::{Error, Result};
use crate::prt::{PrtParams, TransferSet, Visibility};
use crate::renderer::TechniqueChoice;
use std::sync::Arc;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TechniqueKind {
    /// SH irradiance, no shadows.
    #[default]
    Unshadowed,
    /// Sloan et al. 2002: per-vertex PRT, self-shadowing within each group only.
    SloanSelf,
    /// Sloan et al. 2002 as the Tamura paper compares against: per-vertex PRT whose visibility
    /// is the whole scene at its rest pose (shadows between groups baked into the vertices).
    SloanScene,
    /// Tamura, Johan, Nishita, with dominant lights lit per pixel (Kage's default): PRT plus
    /// per-pixel shadows between groups, q regions.
    Tamura,
    /// Tamura, Johan, Nishita as the paper has it: q regions, the fixed penumbra of eq. (13)
    /// from each region's solid angle, no dominant lights.
    TamuraPaper,
    /// The paper's Fig. 3 baseline: q regions as directional lights with binary shadow maps.
    ParallelLights,
    /// Morishige 2014: light probes captured as SH light the moving group (group 0).
    Probes,
    /// The scene's point and spot lights with hard shadows from one conventional shadow map
    /// per light.
    ShadowMap,
    /// Adaptive shadow maps (Fernando et al. 2001) for the scene's one point or spot light.
    Asm,
}

/// Every parameter of every technique; each technique reads the ones it uses.
#[derive(Clone, Debug)]
pub struct TechniqueSettings {
    pub kind: TechniqueKind,
    /// The PRT precomputation of Sloan and Tamura (SH bands, rays per vertex).
    pub prt: PrtParams,
    /// q: environment regions of Tamura (1 to 64) and parallel-lights (1 to 128).
    pub regions: usize,
    /// Side of a Tamura occlusion mask layer, texels.
    pub mask_size: u32,
    pub penumbra: Penumbra,
    /// Most dominant lights Tamura lights per pixel (0 to 8; they count among the q regions).
    pub dominant_lights: usize,
    /// Side of a group's depth map along a dominant light, texels.
    pub light_map_size: u32,
    /// Side of a shadow map (parallel-lights, shadowmap), texels.
    pub shadow_map_size: u32,
    /// Placement and capture of the light probes.
    pub probes: ProbeSettings,
    /// Adaptive shadow maps: memory and time budgets.
    pub asm: AsmSettings,
}

impl Default for TechniqueSettings {
    fn default() -> Self {
        let occlusion = OcclusionSettings::default();
        TechniqueSettings {
            kind: TechniqueKind::default(),
            prt: PrtParams::DEFAULT,
            regions: occlusion.regions,
            mask_size: occlusion.mask_size,
            penumbra: occlusion.penumbra,
            dominant_lights: occlusion.dominant_lights,
            light_map_size: occlusion.light_map_size,
            shadow_map_size: DEFAULT_SHADOW_MAP_SIZE,
            probes: ProbeSettings::default(),
            asm: AsmSettings::default(),
        }
    }
}

impl TechniqueSettings {
    /// The PRT precomputation the technique needs before its first frame, if any.
    pub fn precomputation(&self) -> Option<PrtParams> {
        let sloan_statics =
            self.kind == TechniqueKind::Probes && self.probes.statics == StaticLighting::Sloan;
        let own_group = matches!(
            self.kind,
            TechniqueKind::SloanSelf | TechniqueKind::Tamura | TechniqueKind::TamuraPaper
        );
        match self.kind {
            TechniqueKind::SloanScene => Some(PrtParams { visibility: Visibility::Scene, ..self.prt }),
            _ if own_group || sloan_statics => Some(PrtParams { visibility: Visibility::Group, ..self.prt }),
            _ => None,
        }
    }

    /// Checks what can be checked before any GPU work (the techniques check the rest when
    /// they are built), so that a bad parameter fails before a long precomputation.
    pub fn validated(mut self) -> Result<TechniqueSettings> {
        if self.precomputation().is_some() {
            self.prt.validated()?;
        }
        if self.kind == TechniqueKind::Probes {
            self.probes = self.probes.validated()?;
        }
        if self.kind == TechniqueKind::Asm {
            self.asm = self.asm.validated()?;
        }
        // Zero regions would quietly be Sloan's technique (see `TechniqueChoice::Prt`).
        let tamura = matches!(self.kind, TechniqueKind::Tamura | TechniqueKind::TamuraPaper);
        if tamura && self.regions == 0 {
            return Err(Error::InvalidArgument("regions must be at least 1 for the Tamura technique".into()));
        }
        if self.kind == TechniqueKind::Tamura {
            let max = crate::layouts::constants::MAX_DOMINANT_LIGHTS as usize;
            if self.dominant_lights > max {
                return Err(Error::InvalidArgument(format!(
                    "dominant lights: {} is more than the {max} Tamura lights per pixel",
                    self.dominant_lights
                )));
            }
            let sizes = super::tamura::dominant_maps::MAP_SIZES;
            if !sizes.contains(&self.light_map_size) {
                return Err(Error::InvalidArgument(format!(
                    "light map size {} must be {} to {} texels",
                    self.light_map_size,
                    sizes.start(),
                    sizes.end()
                )));
            }
        }
        Ok(self)
    }

    /// What the renderer runs. `transfer` is the result of [`Self::precomputation`] (ignored
    /// by techniques that need none); it must have been computed with `self.prt`'s bands.
    pub fn choice(&self, transfer: Option<Arc<TransferSet>>) -> Result<TechniqueChoice> {
        let settings = self.clone().validated()?;
        let transfer = || match &transfer {
            None => Err(Error::InvalidArgument(format!(
                "the {:?} technique needs the PRT transfer: precompute it first",
                settings.kind
            ))),
            Some(transfer) if transfer.params.bands != settings.prt.bands => {
                Err(Error::InvalidArgument(format!(
                    "the transfer was precomputed with {} SH bands, the technique asks for {}",
                    transfer.params.bands, settings.prt.bands
                )))
            }
            Some(transfer)
                if Some(transfer.params.visibility) != settings.precomputation().map(|p| p.visibility) =>
            {
                Err(Error::InvalidArgument(format!(
                    "the transfer was precomputed with {:?} visibility, the {:?} technique needs {:?}",
                    transfer.params.visibility,
                    settings.kind,
                    settings.precomputation().map(|p| p.visibility)
                )))
            }
            Some(transfer) => Ok(transfer.clone()),
        };
        let prt = |occlusion| Ok(TechniqueChoice::Prt { transfer: transfer()?, occlusion });
        let occlusion = OcclusionSettings {
            regions: settings.regions,
            mask_size: settings.mask_size,
            penumbra: settings.penumbra,
            size: RegionSize::Energy,
            dominant_lights: settings.dominant_lights,
            light_map_size: settings.light_map_size,
            ..OcclusionSettings::default()
        };
        let sloan = OcclusionSettings { regions: 0, dominant_lights: 0, pixel_cosine: false, ..occlusion };
        match settings.kind {
            TechniqueKind::Unshadowed => Ok(TechniqueChoice::Unshadowed),
            TechniqueKind::SloanSelf | TechniqueKind::SloanScene => prt(sloan),
            TechniqueKind::Tamura => prt(occlusion),
            TechniqueKind::TamuraPaper => prt(OcclusionSettings {
                penumbra: Penumbra::Fixed,
                size: RegionSize::Geometric,
                dominant_lights: 0,
                pixel_cosine: false,
                ..occlusion
            }),
            TechniqueKind::ParallelLights => Ok(TechniqueChoice::ParallelLights {
                regions: settings.regions,
                shadow_map_size: settings.shadow_map_size,
            }),
            TechniqueKind::Probes => Ok(TechniqueChoice::Probes {
                transfer: match settings.probes.statics {
                    StaticLighting::Unshadowed => None,
                    StaticLighting::Sloan => Some(transfer()?),
                },
                settings: settings.probes.clone(),
            }),
            TechniqueKind::ShadowMap => Ok(TechniqueChoice::ShadowMap { size: settings.shadow_map_size }),
            TechniqueKind::Asm => Ok(TechniqueChoice::Asm(settings.asm)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn transfer(bands: u32) -> Option<Arc<TransferSet>> {
        Some(Arc::new(TransferSet {
            params: PrtParams { bands, rays: 1, ..PrtParams::DEFAULT },
            seconds: 0.0,
            meshes: vec![],
        }))
    }

    fn error(settings: TechniqueSettings, transfer: Option<Arc<TransferSet>>) -> String {
        settings.choice(transfer).unwrap_err().to_string()
    }

    #[test]
    fn each_kind_becomes_its_choice() {
        let of = |kind| TechniqueSettings { kind, regions: 4, ..Default::default() };
        assert!(matches!(of(TechniqueKind::Unshadowed).choice(None), Ok(TechniqueChoice::Unshadowed)));
        let sloan = of(TechniqueKind::SloanSelf).choice(transfer(3)).unwrap();
        assert!(matches!(sloan, TechniqueChoice::Prt { occlusion, .. } if occlusion.regions == 0));
        let tamura = of(TechniqueKind::Tamura).choice(transfer(3)).unwrap();
        assert!(matches!(tamura, TechniqueChoice::Prt { occlusion, .. } if occlusion.regions == 4));
        let lights = of(TechniqueKind::ParallelLights).choice(None).unwrap();
        assert!(matches!(lights, TechniqueChoice::ParallelLights { regions: 4, .. }));
        let map = TechniqueSettings { shadow_map_size: 2048, ..of(TechniqueKind::ShadowMap) };
        assert!(matches!(map.choice(None), Ok(TechniqueChoice::ShadowMap { size: 2048 })));
        assert_eq!(of(TechniqueKind::ParallelLights).precomputation(), None);
        assert_eq!(of(TechniqueKind::Tamura).precomputation(), Some(PrtParams::DEFAULT));
        assert!(matches!(
            of(TechniqueKind::Probes).choice(None),
            Ok(TechniqueChoice::Probes { transfer: None, .. })
        ));
        let asm = TechniqueSettings {
            asm: AsmSettings { budget_mb: 4.0, time_ms: 2.0, ..AsmSettings::default() },
            ..of(TechniqueKind::Asm)
        };
        assert!(
            matches!(asm.choice(None), Ok(TechniqueChoice::Asm(s)) if s.budget_mb == 4.0 && s.time_ms == 2.0)
        );
        assert_eq!(of(TechniqueKind::Probes).precomputation(), None);
        // Static groups by Sloan's PRT: the probes technique needs the transfer too.
        let mut sloan_statics = of(TechniqueKind::Probes);
        sloan_statics.probes.statics = StaticLighting::Sloan;
        assert_eq!(sloan_statics.precomputation(), Some(PrtParams::DEFAULT));
        assert!(matches!(
            sloan_statics.choice(transfer(3)),
            Ok(TechniqueChoice::Probes { transfer: Some(_), .. })
        ));
        assert!(error(sloan_statics, None).contains("precompute it first"));
    }

    #[test]
    fn missing_or_mismatched_precomputation_and_bad_parameters_are_errors() {
        let tamura = TechniqueSettings { kind: TechniqueKind::Tamura, ..Default::default() };
        assert!(error(tamura.clone(), None).contains("precompute it first"));
        assert!(error(tamura.clone(), transfer(4)).contains("4 SH bands"));
        assert!(error(TechniqueSettings { regions: 0, ..tamura.clone() }, transfer(3)).contains("at least 1"));
        let dominant = TechniqueSettings { dominant_lights: 9, ..tamura.clone() };
        assert!(error(dominant, transfer(3)).contains("dominant lights: 9"));
        let light_map = TechniqueSettings { light_map_size: 8, ..tamura.clone() };
        assert!(error(light_map, transfer(3)).contains("light map size 8"));
        let paper = TechniqueSettings { kind: TechniqueKind::TamuraPaper, regions: 0, ..tamura.clone() };
        assert!(error(paper, transfer(3)).contains("at least 1"));
        // Sloan's whole-scene variant needs a transfer with the whole scene's visibility.
        let scene = TechniqueSettings { kind: TechniqueKind::SloanScene, ..tamura.clone() };
        assert!(error(scene, transfer(3)).contains("Group visibility"));
        let bands = PrtParams { bands: 9, ..PrtParams::DEFAULT };
        assert!(error(TechniqueSettings { prt: bands, ..tamura }, transfer(9)).contains("9 SH bands"));
        let mut probes = TechniqueSettings { kind: TechniqueKind::Probes, ..Default::default() };
        probes.probes.placement = crate::techniques::probes::ProbePlacement::Grid([2, 1, 2]);
        assert!(error(probes.clone(), None).contains("probe grid [2, 1, 2]"));
        probes.probes = ProbeSettings::default();
        probes.probes.capture.cube_size = 512;
        assert!(error(probes, None).contains("cube map size 512"));
        let mut asm = TechniqueSettings { kind: TechniqueKind::Asm, ..Default::default() };
        asm.asm.budget_mb = 0.01;
        assert!(error(asm.clone(), None).contains("holds no tile"));
        asm.asm = AsmSettings { time_ms: 0.0, ..AsmSettings::default() };
        assert!(error(asm, None).contains("time budget"));
    }
}
