//! `kage render --trace FILE.json`: the frames as a timeline in the Chrome trace event format,
//! which Perfetto (ui.perfetto.dev) and chrome://tracing open. Track 1 holds each frame as the
//! CPU saw it (from the call that records it to its image being ready); track 2 each pass as
//! the device's timestamps measured it. The device's clock is not calibrated against the CPU's:
//! each frame's passes start where its CPU event starts, offset by their GPU start within the
//! frame, so durations and order are exact and the gap before the first pass is not.
use anyhow::{Context as _, Result};
use kage::pass::PassTiming;
use serde_json::{json, Value};
use std::path::Path;

#[derive(Default)]
pub struct Trace {
    events: Vec<Value>,
}

impl Trace {
    /// Frame `frame`, recorded from `cpu_start_us` (µs since the run began) for `cpu_us`, with
    /// its passes; a pass without timestamps is left out.
    pub fn add_frame(&mut self, frame: u32, cpu_start_us: f64, cpu_us: f64, passes: &[PassTiming]) {
        self.events.push(json!({
            "name": "frame", "cat": "cpu", "ph": "X", "pid": 1, "tid": 1,
            "ts": cpu_start_us, "dur": cpu_us, "args": {"frame": frame},
        }));
        for pass in passes {
            if let (Some(ms), Some(start)) = (pass.gpu_ms, pass.start_ms) {
                self.events.push(json!({
                    "name": pass.name, "cat": "gpu", "ph": "X", "pid": 1, "tid": 2,
                    "ts": cpu_start_us + 1e3 * start, "dur": 1e3 * ms, "args": {"frame": frame},
                }));
            }
        }
    }

    /// Writes the trace, its two tracks named (the second after `device`).
    pub fn write(mut self, path: &Path, device: &str) -> Result<()> {
        let name = |tid: u32, name: &str| json!({"name": "thread_name", "ph": "M", "pid": 1, "tid": tid, "args": {"name": name}});
        self.events.splice(0..0, [name(1, "CPU: frames"), name(2, &format!("GPU: passes ({device})"))]);
        let file = json!({"traceEvents": self.events, "displayTimeUnit": "ms"});
        std::fs::write(path, serde_json::to_string(&file)?)
            .with_context(|| format!("writing {}", path.display()))
    }
}
