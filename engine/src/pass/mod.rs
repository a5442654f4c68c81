//! The pass layer: a frame is a list of named passes, each with the resources it reads and
//! writes and a function that records it. Every pass is wrapped in a debug label and a pair of
//! GPU timestamps; after the frame's fence the timings are read back per pass.
//!
//! # Synchronization policy
//! Kept conservative on purpose, until a measurement says a pass boundary is worth refining:
//! - Every image lives in `GENERAL` layout from creation on (see `backend::Image`), so no pass
//!   tracks or changes layouts.
//! - Between two consecutive passes the executor records one full memory barrier
//!   (all commands → all commands, memory writes → memory reads and writes), and one more
//!   after each pass's start timestamp, so that lavapipe writes it before the pass's work.
//!   Within a pass, the pass itself is responsible for any hazard between its own commands.
//! - A frame is one command buffer, ending with a barrier that makes every write visible to host
//!   reads, submitted and waited for on its fence before `run` returns, so the host may read or
//!   rewrite any resource afterwards (readbacks, the ASM analysis' counts).
//!
//! A pass's reads and writes are the resources its commands use: the backend logs every buffer
//! and image a recording method touches (bound, drawn from, rendered into, copied) and whether
//! it may write it (`backend/access.rs`). Before submitting, the executor checks the frame's
//! order by them: no pass only reads a resource that a later pass of the same frame writes and
//! no earlier one did, which catches passes recorded in the wrong order. A resource no pass of
//! the frame writes is persistent (uploaded by the host, or written by an earlier frame).
mod timings;

pub use timings::{frame_ms, median, scaled_to_submissions, TimingRow, TimingTable};

use crate::backend::{AccessLog, Cmd, Context, TimestampPool, Touch};
use crate::error::{Error, Result};
use ash::vk;
use std::collections::HashMap;
use std::sync::Arc;

/// One pass of a frame: its name and the function that records it.
pub struct Pass<'a> {
    pub name: &'static str,
    record: Box<dyn FnOnce(Cmd<'_>) + 'a>,
}

impl<'a> Pass<'a> {
    pub fn new(name: &'static str, record: impl FnOnce(Cmd<'_>) + 'a) -> Pass<'a> {
        Pass { name, record: Box::new(record) }
    }
}

/// The GPU time of one pass in one frame; `None` where the device has no timestamps.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTiming {
    pub name: &'static str,
    pub gpu_ms: Option<f64>,
    /// When the pass started on the device, ms after the frame's first pass started (for a
    /// timeline; `None` without timestamps).
    pub start_ms: Option<f64>,
    /// The device's timestamp of the pass's start, in ticks (for [`crate::backend::Calibration`]).
    pub start_ticks: Option<u64>,
}

/// Records, submits and times frames; owns the command buffer and timestamp pool it reuses.
pub struct FrameExecutor {
    ctx: Arc<Context>,
    name: String,
    /// The command buffer, or the failed submission that left it pending for good.
    recorder: std::result::Result<crate::backend::CommandRecorder, Failed>,
    timestamps: Option<TimestampPool>,
}

/// The failed submission that left an executor unusable, kept to answer every later frame.
struct Failed {
    device_lost: bool,
    message: String,
}

impl Failed {
    fn new(error: &Error) -> Failed {
        Failed { device_lost: matches!(error, Error::DeviceLost { .. }), message: error.to_string() }
    }

    /// A lost device stays a lost device for every later frame, so that a host's handling of
    /// it (rebuild everything) is triggered however many frames it renders before it looks;
    /// any other failure is named.
    fn error(&self) -> Error {
        match self.device_lost {
            true => Error::DeviceLost { call: "a frame after the device was lost" },
            false => Error::Internal(format!(
                "the frame executor cannot run after an earlier failure: {}",
                self.message
            )),
        }
    }
}

impl FrameExecutor {
    pub fn new(ctx: &Arc<Context>, name: &str) -> Result<FrameExecutor> {
        let recorder = ctx.create_recorder(&format!("{name}.commands"))?;
        Ok(FrameExecutor {
            ctx: ctx.clone(),
            name: name.to_owned(),
            recorder: Ok(recorder),
            timestamps: None,
        })
    }

    /// Runs `passes` in order as one submission and returns each pass's GPU time.
    pub fn run(&mut self, passes: Vec<Pass<'_>>) -> Result<Vec<PassTiming>> {
        let count = 2 * passes.len() as u32;
        let period_ns = self.ctx.info().timestamp_period_ns;
        if period_ns.is_some() && self.timestamps.as_ref().is_none_or(|t| t.capacity() < count) {
            self.timestamps =
                Some(TimestampPool::new(&self.ctx, &format!("{}.timestamps", self.name), count.max(16))?);
        }
        let recorder = match &self.recorder {
            Ok(recorder) => recorder,
            Err(failed) => return Err(failed.error()),
        };
        let timestamps = self.timestamps.as_ref().filter(|_| period_ns.is_some());
        // What the executor's own commands touch (none of them a resource) goes here; each
        // pass's touches go to a log of its own.
        let frame_log = AccessLog::default();
        let cmd = recorder.cmd(&frame_log);
        self.ctx.begin(recorder)?;
        if let Some(t) = timestamps {
            t.reset(cmd, count);
        }
        let names: Vec<&'static str> = passes.iter().map(|p| p.name).collect();
        let mut touches = Vec::with_capacity(passes.len());
        for (i, pass) in passes.into_iter().enumerate() {
            if i > 0 {
                self.ctx.full_barrier(cmd);
            }
            self.ctx.begin_label(cmd, pass.name);
            if let Some(t) = timestamps {
                t.write(cmd, vk::PipelineStageFlags::TOP_OF_PIPE, 2 * i as u32);
                // lavapipe writes a timestamp when it next rasterizes its binned work: without a
                // flush here the start waits until the pass's first scope is binned, a time no
                // pass counted (vendor-notes.md). Nothing is in flight after the barrier above,
                // so on a GPU this one waits for nothing.
                self.ctx.full_barrier(cmd);
            }
            let log = AccessLog::default();
            (pass.record)(recorder.cmd(&log));
            touches.push(log.take());
            if let Some(t) = timestamps {
                t.write(cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, 2 * i as u32 + 1);
            }
            self.ctx.end_label(cmd);
        }
        self.ctx.host_read_barrier(cmd);
        if let Err(e) = check_order(&names, &touches) {
            // Recorded but never submitted: the buffer is ended, ready to begin again.
            self.ctx.end(recorder)?;
            return Err(e);
        }
        if let Err(e) = self.ctx.submit_and_wait(recorder) {
            // The command buffer may still be pending after a timeout or device loss: never
            // reuse it.
            self.recorder = Err(Failed::new(&e));
            return Err(e);
        }
        let ticks = match timestamps {
            Some(t) => Some(t.read(count)?),
            None => None,
        };
        Ok(names
            .into_iter()
            .enumerate()
            .map(|(i, name)| {
                let ms = |from: usize, to: usize| {
                    ticks
                        .as_ref()
                        .zip(period_ns)
                        .map(|(t, period)| t[to].saturating_sub(t[from]) as f64 * period * 1e-6)
                };
                PassTiming {
                    name,
                    gpu_ms: ms(2 * i, 2 * i + 1),
                    start_ms: ms(0, 2 * i),
                    start_ticks: ticks.as_ref().map(|t| t[2 * i]),
                }
            })
            .collect())
    }
}

impl Drop for FrameExecutor {
    fn drop(&mut self) {
        if let Ok(recorder) = &self.recorder {
            self.ctx.destroy_recorder(recorder);
        }
    }
}

/// No pass only reads a resource that a later pass writes and no earlier pass (nor itself)
/// did: such a pass would see the previous frame's content, a pass recorded out of order.
fn check_order(names: &[&'static str], touches: &[Vec<Touch>]) -> Result<()> {
    let mut first_writer: HashMap<u64, usize> = HashMap::new();
    for (i, pass) in touches.iter().enumerate() {
        for touch in pass.iter().filter(|t| t.writes) {
            first_writer.entry(touch.id).or_insert(i);
        }
    }
    for (i, pass) in touches.iter().enumerate() {
        for touch in pass.iter().filter(|t| !t.writes) {
            if let Some(&writer) = first_writer.get(&touch.id).filter(|&&w| w > i) {
                return Err(Error::Internal(format!(
                    "pass {} reads {} before pass {} writes it: the passes are recorded out of order",
                    names[i], touch.name, names[writer]
                )));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn touch(id: u64, name: &str, writes: bool) -> Touch {
        Touch { id, name: name.into(), writes }
    }

    #[test]
    fn a_pass_reading_what_a_later_pass_writes_is_an_internal_error() {
        let produce = vec![touch(1, "uniforms", false), touch(2, "masks", true)];
        let consume = vec![touch(2, "masks", false), touch(3, "color", true)];
        let names = ["produce", "consume"];
        assert!(check_order(&names, &[produce.clone(), consume.clone()]).is_ok());
        // Read and written by the same pass, or by no pass of the frame: in order.
        let persistent = vec![touch(1, "uniforms", false), touch(2, "masks", false), touch(2, "masks", true)];
        assert!(check_order(&["a", "b"], &[persistent, consume.clone()]).is_ok());
        let error = check_order(&["consume", "produce"], &[consume, produce]).unwrap_err();
        // Kage's own bug, not the caller's: the C ABI gives it KAGE_RESULT_INTERNAL.
        assert_eq!(error.fault(), crate::error::Fault::Internal);
        assert!(
            error.to_string().contains("pass consume reads masks before pass produce writes it"),
            "{error}"
        );
    }

    /// Lavapipe cannot lose its device on demand, so the answer to the frames after a failure
    /// is tested on its own.
    #[test]
    fn frames_after_a_device_loss_report_the_loss() {
        let lost = Failed::new(&Error::DeviceLost { call: "vkQueueSubmit" });
        assert!(matches!(lost.error(), Error::DeviceLost { .. }));
        let timeout = Failed::new(&Error::Timeout("vkWaitForFences"));
        let message = timeout.error().to_string();
        assert!(message.contains("earlier failure") && message.contains("vkWaitForFences"), "{message}");
    }
}
