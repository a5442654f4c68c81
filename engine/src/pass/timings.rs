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
}
