//! Per-pass GPU timings gathered over many frames: median, minimum and maximum per pass.
use super::PassTiming;

#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TimingRow {
    pub name: String,
    pub median_ms: f64,
    pub min_ms: f64,
    pub max_ms: f64,
    /// Frames in which the pass ran (a pass such as the SH projection runs only when its input
    /// changes).
    pub frames: usize,
}

#[derive(Default, Debug)]
pub struct TimingTable {
    passes: Vec<(String, Vec<f64>)>,
    frames: Vec<f64>,
}

/// The median of `values` (the mean of the middle two for an even count); NaN when empty.
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The seconds of `units` units of work (samples, rounds of rays) submitted at most
/// `per_submission` to a submission, from the seconds of a submission of one unit (`one`) and
/// of `timed` (> 1) units (`many`): a line through the two, a submission's own cost (recording,
/// submitting, the wait) its intercept, counted once per submission; neither part below 0, as
/// noise can tilt the line. Scaling `many` alone would count that cost once per `timed` units.
pub fn scaled_to_submissions(one: f64, many: f64, timed: u32, units: u32, per_submission: u32) -> f64 {
    let per_unit = ((many - one) / f64::from(timed.max(2) - 1)).max(0.0);
    let per_call = (one - per_unit).max(0.0);
    per_unit * f64::from(units) + per_call * f64::from(units.div_ceil(per_submission.max(1)))
}

/// A frame's device time: from its first pass's start to its last pass's end, the time between
/// passes included (lavapipe writes a compute pass's timestamps when it next flushes, so part
/// of a pass's work can fall between passes; vendor-notes.md). The sum of the passes' times
/// where they have no start; `None` without timestamps.
pub fn frame_ms(frame: &[PassTiming]) -> Option<f64> {
    let ends = frame.iter().map(|t| Some(t.start_ms? + t.gpu_ms?)).collect::<Option<Vec<f64>>>();
    match ends {
        Some(ends) if !ends.is_empty() => Some(ends.into_iter().fold(0.0, f64::max)),
        _ => frame.iter().any(|t| t.gpu_ms.is_some()).then(|| frame.iter().filter_map(|t| t.gpu_ms).sum()),
    }
}

impl TimingTable {
    /// Adds one frame's timings ([`frame_ms`]); passes without a GPU time (no timestamps) are
    /// left out.
    pub fn add_frame(&mut self, frame: &[PassTiming]) {
        for timing in frame {
            let Some(ms) = timing.gpu_ms else { continue };
            match self.passes.iter_mut().find(|(name, _)| name == timing.name) {
                Some((_, samples)) => samples.push(ms),
                None => self.passes.push((timing.name.to_owned(), vec![ms])),
            }
        }
        if let Some(total) = frame_ms(frame) {
            self.frames.push(total);
        }
    }

    /// One row per pass, in the order the passes first ran.
    pub fn rows(&self) -> Vec<TimingRow> {
        self.passes
            .iter()
            .map(|(name, samples)| TimingRow {
                name: name.clone(),
                median_ms: median(samples),
                min_ms: samples.iter().copied().fold(f64::INFINITY, f64::min),
                max_ms: samples.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                frames: samples.len(),
            })
            .collect()
    }

    /// Median over frames of [`frame_ms`].
    pub fn frame_median_ms(&self) -> f64 {
        median(&self.frames)
    }

    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_min_max_per_pass() {
        let mut table = TimingTable::default();
        for ms in [3.0, 1.0, 2.0, 10.0] {
            table.add_frame(&[
                PassTiming { name: "a", gpu_ms: Some(ms), start_ms: Some(0.0), start_ticks: None },
                PassTiming { name: "b", gpu_ms: Some(1.0), start_ms: Some(ms), start_ticks: None },
            ]);
        }
        let rows = table.rows();
        assert_eq!(rows[0].name, "a");
        assert_eq!((rows[0].median_ms, rows[0].min_ms, rows[0].max_ms), (2.5, 1.0, 10.0));
        assert_eq!(rows[1].frames, 4);
        // Each frame from a's start to b's end: 4, 2, 3 and 11 ms.
        assert_eq!(table.frame_median_ms(), 3.5);
    }

    /// Time between passes counts (a pass's work lavapipe times late); without starts, the sum.
    #[test]
    fn a_frame_spans_its_first_start_to_its_last_end() {
        let pass = |name, gpu_ms, start_ms| PassTiming { name, gpu_ms, start_ms, start_ticks: None };
        let gap = [pass("a", Some(2.0), Some(0.0)), pass("b", Some(1.0), Some(9.0))];
        assert_eq!(frame_ms(&gap), Some(10.0));
        let unplaced = [pass("a", Some(2.0), None), pass("b", Some(1.0), None)];
        assert_eq!(frame_ms(&unplaced), Some(3.0));
        assert_eq!(frame_ms(&[pass("a", None, None)]), None);
    }

    /// A submission's own cost counts once per submission, a unit's once per unit: 2 ms a
    /// submission and 1.5 ms a unit, timed on 1 and 16 units, give 256 units in submissions of
    /// 64 as 4 · 2 + 256 · 1.5 ms (scaling the 16-unit time alone gave 16 · 2 + 256 · 1.5).
    #[test]
    fn a_submission_counts_once_per_submission() {
        let time = |units: u32| 2e-3 + 1.5e-3 * f64::from(units);
        let total = scaled_to_submissions(time(1), time(16), 16, 256, 64);
        assert!((total - (4.0 * 2e-3 + 256.0 * 1.5e-3)).abs() < 1e-12, "{total}");
        // Noise that times 16 units below 1: no negative cost per unit.
        assert_eq!(scaled_to_submissions(3e-3, 2e-3, 16, 256, 64), 4.0 * 3e-3);
    }
}
