//! Lighting techniques, one file or folder each, built from passes over the frame layer
//! (`crate::frame`); `description` names them with their parameters.
pub mod asm;
pub mod description;
pub mod parallel_lights;
pub mod probes;
pub mod shadow_map;
pub mod tamura;
pub mod unshadowed;

use crate::error::Result;
use crate::frame::{FrameInputs, FrameState};
use crate::pass::{Pass, PassTiming};

/// A lighting technique: host-side updates, then the passes that draw the scene over the
/// background (the colour target is cleared and holds the environment when they start).
pub trait Technique {
    fn update(&mut self, state: &FrameState) -> Result<()>;
    /// Resources the technique keeps from frame to frame, which its passes may read without a
    /// pass of the same frame writing them.
    fn persistent(&self) -> &'static [&'static str] {
        &[]
    }
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
    /// The GPU times of the frame's own passes, after it completed (the adaptive shadow map
    /// scales its tile cost model by them).
    fn timed(&mut self, _timings: &[PassTiming]) {}
    /// Occlusion layers the last frame wanted but had no room for (their light was left
    /// unshadowed): 0 for techniques without a layer budget.
    fn dropped_layers(&self) -> usize {
        0
    }
    /// Bytes of the shadow storage of the scene's local lights (maps, tile pools), what the
    /// memory comparisons of shadow-map techniques count; `None` for techniques without one.
    fn shadow_memory_bytes(&self) -> Option<u64> {
        None
    }
    /// The adaptive shadow map's hierarchy after the last update; `None` for other techniques.
    fn asm_stats(&self) -> Option<asm::AsmStats> {
        None
    }
    /// The light probes placed and kept; `None` for techniques without probes.
    fn probe_counts(&self) -> Option<probes::ProbeCounts> {
        None
    }
}
