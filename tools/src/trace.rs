//! `kage render --trace FILE.json`: the frames as a timeline in the Chrome trace event format,
//! which Perfetto (ui.perfetto.dev) and chrome://tracing open. Track 1 holds each frame as the
//! CPU saw it (from the call that records it to its image being ready); track 2 each pass as
//! the device's timestamps measured it. Where the device reads its clock and the host's
//! together (VK_EXT_calibrated_timestamps), both tracks are on the host's monotonic clock and
//! `otherData.gpu_clock` says "calibrated"; elsewhere each frame's passes start where its CPU
//! event starts, offset by their GPU start within the frame (durations and order exact, the gap
//! before the first pass not), and it says "uncalibrated".
use anyhow::{Context as _, Result};
use kage::pass::PassTiming;
use serde_json::{json, Value};
use std::path::Path;

#[derive(Default)]
pub struct Trace {
    events: Vec<Value>,
    /// The largest deviation between the two clocks' readings, ns, when calibrated.
    deviation_ns: Option<u64>,
}

impl Trace {
    /// Frame `frame`, recorded from `cpu_start_us` (µs on the trace's clock) for `cpu_us`, with
    /// its passes, each at `place(pass)` µs; a pass without timestamps is left out.
    pub fn add_frame(
        &mut self,
        frame: u32,
        cpu_start_us: f64,
        cpu_us: f64,
        passes: &[PassTiming],
        place: impl Fn(&PassTiming) -> Option<f64>,
    ) {
        self.events.push(json!({
            "name": "frame", "cat": "cpu", "ph": "X", "pid": 1, "tid": 1,
            "ts": cpu_start_us, "dur": cpu_us, "args": {"frame": frame},
        }));
        for pass in passes {
            if let (Some(ms), Some(ts)) = (pass.gpu_ms, place(pass)) {
                self.events.push(json!({
                    "name": pass.name, "cat": "gpu", "ph": "X", "pid": 1, "tid": 2,
                    "ts": ts, "dur": 1e3 * ms, "args": {"frame": frame},
                }));
            }
        }
    }

    /// Notes a calibration's deviation (the trace is then on one clock).
    pub fn calibrated(&mut self, deviation_ns: u64) {
        self.deviation_ns = Some(self.deviation_ns.unwrap_or(0).max(deviation_ns));
    }

    /// Writes the trace, its two tracks named (the second after `device`).
    pub fn write(mut self, path: &Path, device: &str) -> Result<()> {
        let name = |tid: u32, name: &str| json!({"name": "thread_name", "ph": "M", "pid": 1, "tid": tid, "args": {"name": name}});
        self.events.splice(0..0, [name(1, "CPU: frames"), name(2, &format!("GPU: passes ({device})"))]);
        let clock = match self.deviation_ns {
            Some(ns) => json!({"gpu_clock": "calibrated", "max_deviation_ns": ns}),
            None => json!({"gpu_clock": "uncalibrated"}),
        };
        let file = json!({"traceEvents": self.events, "displayTimeUnit": "ms", "otherData": clock});
        std::fs::write(path, serde_json::to_string(&file)?)
            .with_context(|| format!("writing {}", path.display()))
    }
}
