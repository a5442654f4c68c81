//! The pass layer: a frame is a list of named passes, each with the resources it reads and
//! writes and a function that records it. Every pass is wrapped in a debug label and a pair of
//! GPU timestamps; after the frame's fence the timings are read back per pass.
//!
//! # Synchronization policy
//! Kept conservative on purpose, until a measurement says a pass boundary is worth refining:
//! - Every image lives in `GENERAL` layout from creation on (see `backend::Image`), so no pass
//!   tracks or changes layouts.
//! - Between two consecutive passes the executor records one full memory barrier
//!   (all commands → all commands, memory writes → memory reads and writes). Within a pass,
//!   the pass itself is responsible for any hazard between its own commands.
//! - A frame is one command buffer, ending with a barrier that makes every write visible to host
//!   reads, submitted and waited for on its fence before `run` returns, so the host may read or
//!   rewrite any resource afterwards (readbacks, the ASM analysis' counts).
//!
//! The declared inputs and outputs are checked before recording: a pass may only read what an
//! earlier pass of the frame wrote or what the frame imports (persistent resources), which
//! catches passes recorded in the wrong order.
mod timings;

pub use timings::{frame_ms, median, TimingRow, TimingTable};

use crate::backend::{Cmd, Context, TimestampPool};
use crate::error::{Error, Result};
use ash::vk;
use std::sync::Arc;

/// A resource passes read and write (a GPU buffer or image), named once as a constant beside
/// what makes it (`frame::COLOR`, `techniques::tamura::occlusion::OCCLUSION`), so that a
/// misspelt resource is a compile error; the executor checks a frame's order by them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resource(pub &'static str);

/// One pass of a frame.
pub struct Pass<'a> {
    pub name: &'static str,
    pub inputs: &'a [Resource],
    pub outputs: &'a [Resource],
    record: Box<dyn FnOnce(Cmd) + 'a>,
}

impl<'a> Pass<'a> {
    pub fn new(
        name: &'static str,
        inputs: &'a [Resource],
        outputs: &'a [Resource],
        record: impl FnOnce(Cmd) + 'a,
    ) -> Pass<'a> {
        Pass { name, inputs, outputs, record: Box::new(record) }
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
    pub fn run(&mut self, imports: &[Resource], passes: Vec<Pass<'_>>) -> Result<Vec<PassTiming>> {
        check_data_flow(imports, &passes)?;
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
        let cmd = recorder.cmd();
        let timestamps = self.timestamps.as_ref().filter(|_| period_ns.is_some());
        self.ctx.begin(recorder)?;
        if let Some(t) = timestamps {
            t.reset(cmd, count);
        }
        let names: Vec<&'static str> = passes.iter().map(|p| p.name).collect();
        for (i, pass) in passes.into_iter().enumerate() {
            if i > 0 {
                self.ctx.full_barrier(cmd);
            }
            self.ctx.begin_label(cmd, pass.name);
            if let Some(t) = timestamps {
                t.write(cmd, vk::PipelineStageFlags::TOP_OF_PIPE, 2 * i as u32);
            }
            (pass.record)(cmd);
            if let Some(t) = timestamps {
                t.write(cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, 2 * i as u32 + 1);
            }
            self.ctx.end_label(cmd);
        }
        self.ctx.host_read_barrier(cmd);
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

fn check_data_flow(imports: &[Resource], passes: &[Pass<'_>]) -> Result<()> {
    let mut available: Vec<Resource> = imports.to_vec();
    for pass in passes {
        if let Some(missing) = pass.inputs.iter().find(|i| !available.contains(i)) {
            return Err(Error::Internal(format!(
                "pass {} reads {}, which no earlier pass writes and the frame does not import",
                pass.name, missing.0
            )));
        }
        available.extend_from_slice(pass.outputs);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pass_reading_what_nothing_wrote_is_an_internal_error() {
        const A: Resource = Resource("a");
        const B: Resource = Resource("b");
        let passes = [Pass::new("first", &[A], &[B], |_| {}), Pass::new("second", &[B], &[], |_| {})];
        assert!(check_data_flow(&[A], &passes).is_ok());
        let passes = [Pass::new("second", &[B], &[], |_| {})];
        let error = check_data_flow(&[A], &passes).unwrap_err();
        // Kage's own bug, not the caller's: the C ABI gives it KAGE_RESULT_INTERNAL.
        assert_eq!(error.fault(), crate::error::Fault::Internal);
        assert!(error.to_string().contains("pass second reads b, which no earlier pass writes"), "{error}");
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
