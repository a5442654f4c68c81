//! Lighting techniques, one file or folder each, built from passes over the frame layer
//! (`crate::frame`); `description` names them with their parameters.
pub mod asm;
pub mod description;
pub mod parallel_lights;
pub mod probes;
pub mod shadow_map;
pub mod sloan;
pub mod tamura;
pub mod unshadowed;

use crate::error::Result;
use crate::frame::{FrameInputs, FrameState};
use crate::pass::{Pass, PassTiming};

/// A lighting technique: host-side updates, then the passes that draw the scene over the
/// background (the colour target is cleared and holds the environment when they start).
pub trait Technique {
    fn update(&mut self, state: &FrameState) -> Result<()>;
    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>>;
    /// Passes submitted and waited for before the frame's own, whose results the host reads in
    /// [`Technique::analysed`] before [`Technique::passes`] records the frame: the adaptive
    /// shadow map's analysis of the eye view, which decides the tiles the same frame renders
    /// and looks up (the paper's order). None for the other techniques.
    fn analysis_passes<'a>(&'a self, _inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        Vec::new()
    }
    /// Reads what [`Technique::analysis_passes`] wrote, after their submission has completed.
    fn analysed(&mut self) -> Result<()> {
        Ok(())
    }
    /// The GPU times of the frame's passes (its analysis passes included), after it completed:
    /// the adaptive shadow map scales its tile cost model and budget by them.
    fn timed(&mut self, _timings: &[PassTiming]) {}
    /// What the technique reports of its last frame besides the pass timings.
    fn stats(&self) -> TechniqueStats {
        TechniqueStats::default()
    }
}

/// What a technique reports of its last frame besides the pass timings; what it does not have
/// stays at the default (0, `None`). The renderer, the command line and the C ABI pass it on.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TechniqueStats {
    /// Tamura: occlusion layers the last frame wanted but had no room for (their light was
    /// left unshadowed: see `OcclusionSettings::max_layers`).
    pub dropped_layers: usize,
    /// Bytes of the shadow storage of the scene's local lights (maps, tile pools), what the
    /// memory comparisons of shadow-map techniques count.
    pub shadow_memory_bytes: Option<u64>,
    /// The adaptive shadow map's hierarchy after the last update.
    pub asm: Option<asm::AsmStats>,
    /// The light probes placed and kept.
    pub probes: Option<probes::ProbeCounts>,
    /// What capturing the light probes took.
    pub probe_capture: Option<probes::CaptureCost>,
    /// The probe lookups since the technique was built, by what their visibility test did.
    pub probe_lookups: Option<probes::LookupCounts>,
}
