//! Command buffers and submission. Kage records a frame into one primary command buffer and
//! waits for its fence; `one_shot` is the same for set-up work (uploads, layout changes).
use super::{AccessLog, Context};
use crate::error::{Error, Result};
use ash::vk;

/// How long a submission may run before Kage calls it hung. Long compute jobs (reference
/// rendering, precomputation) are split into submissions well below this on lavapipe.
const FENCE_TIMEOUT_NS: u64 = 600_000_000_000;

/// A command buffer with its fence, reused frame after frame. Each has its own command pool:
/// a pool is externally synchronized, so recorders of one context (renderers driven from
/// different threads) may then record at the same time.
pub struct CommandRecorder {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

impl CommandRecorder {
    /// The command buffer to record into, between [`Context::begin`] and
    /// [`Context::submit_and_wait`], logging what its commands touch into `log`.
    pub(crate) fn cmd<'a>(&self, log: &'a AccessLog) -> Cmd<'a> {
        Cmd { raw: self.cmd, log }
    }
}

/// A command buffer being recorded: what passes record into, through the backend's methods
/// that take it, which log the resources they touch. Only the backend reaches the Vulkan
/// handle inside.
#[derive(Clone, Copy)]
pub struct Cmd<'a> {
    pub(super) raw: vk::CommandBuffer,
    pub(super) log: &'a AccessLog,
}

impl Context {
    pub(crate) fn create_recorder(&self, name: &str) -> Result<CommandRecorder> {
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(self.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and create info.
        let pool = unsafe { self.device.create_command_pool(&pool_info, None) }
            .map_err(Error::vk("vkCreateCommandPool"))?;
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool is this recorder's own.
        let made = unsafe { self.device.allocate_command_buffers(&info) }
            .map_err(Error::vk("vkAllocateCommandBuffers"))
            .and_then(|cmds| {
                // SAFETY: valid device, default create info.
                let fence = unsafe { self.device.create_fence(&vk::FenceCreateInfo::default(), None) }
                    .map_err(Error::vk("vkCreateFence"))?;
                Ok((cmds[0], fence))
            });
        let (cmd, fence) = match made {
            Ok(made) => made,
            Err(e) => {
                // SAFETY: nothing from the pool was submitted; destroying it frees its buffers.
                unsafe { self.device.destroy_command_pool(pool, None) };
                return Err(e);
            }
        };
        self.set_name(pool, &format!("{name}.pool"));
        self.set_name(cmd, name);
        self.set_name(fence, &format!("{name}.fence"));
        Ok(CommandRecorder { pool, cmd, fence })
    }

    pub(crate) fn destroy_recorder(&self, recorder: &CommandRecorder) {
        // SAFETY: the buffer is not pending (callers wait first); destroying the pool frees it.
        unsafe { self.device.destroy_command_pool(recorder.pool, None) };
        // SAFETY: the fence is not in use once the last submission was waited for.
        unsafe { self.device.destroy_fence(recorder.fence, None) };
    }

    pub(crate) fn begin(&self, recorder: &CommandRecorder) -> Result<()> {
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: the buffer is not pending: every submit is waited for before the next begin.
        unsafe { self.device.begin_command_buffer(recorder.cmd, &begin) }
            .map_err(Error::vk("vkBeginCommandBuffer"))
    }

    /// Ends the recording that [`Context::begin`] began, leaving the buffer ready to submit or
    /// to begin again.
    pub(crate) fn end(&self, recorder: &CommandRecorder) -> Result<()> {
        // SAFETY: recording was begun by `begin`.
        unsafe { self.device.end_command_buffer(recorder.cmd) }.map_err(Error::vk("vkEndCommandBuffer"))
    }

    /// Ends, submits and waits for the recorder's command buffer.
    pub(crate) fn submit_and_wait(&self, recorder: &CommandRecorder) -> Result<()> {
        self.end(recorder)?;
        let cmds = [recorder.cmd];
        let submit = vk::SubmitInfo::default().command_buffers(&cmds);
        {
            let queue = self.queue();
            // SAFETY: the queue is locked; the fence is unsignalled (reset after each wait).
            unsafe { self.device.queue_submit(*queue, &[submit], recorder.fence) }
                .map_err(Error::vk("vkQueueSubmit"))?;
        }
        // SAFETY: the fence was just submitted.
        unsafe { self.device.wait_for_fences(&[recorder.fence], true, FENCE_TIMEOUT_NS) }
            .map_err(Error::vk("vkWaitForFences"))?;
        // SAFETY: the fence is signalled and no longer in use.
        unsafe { self.device.reset_fences(&[recorder.fence]) }.map_err(Error::vk("vkResetFences"))
    }

    /// Records `record` into a fresh command buffer, submits it and waits; its writes are then
    /// visible to the host.
    pub fn one_shot(&self, name: &str, record: impl FnOnce(Cmd)) -> Result<()> {
        let recorder = self.create_recorder(name)?;
        // Set-up work is one submission of its own: nothing to order it against.
        let log = AccessLog::default();
        let result = self.begin(&recorder).and_then(|()| {
            record(recorder.cmd(&log));
            self.host_read_barrier(recorder.cmd(&log));
            self.submit_and_wait(&recorder)
        });
        // After a failed submission the buffer may still be pending: free it only once idle.
        if result.is_ok() || self.wait_idle().is_ok() {
            self.destroy_recorder(&recorder);
        }
        result
    }

    /// A full memory barrier: everything before finishes and is visible to everything after.
    pub fn full_barrier(&self, cmd: Cmd) {
        self.barrier_to(
            cmd,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE,
        );
    }

    /// Everything before finishes and its writes become visible to host reads once the
    /// submission's fence is waited for (a fence alone does not make device writes visible to
    /// the host: mapped memory needs this HOST-stage dependency, coherent or not).
    pub fn host_read_barrier(&self, cmd: Cmd) {
        self.barrier_to(cmd, vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ);
    }

    fn barrier_to(&self, cmd: Cmd, stage: vk::PipelineStageFlags, access: vk::AccessFlags) {
        let barrier = vk::MemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
            .dst_access_mask(access);
        // SAFETY: recording command buffer of this device.
        unsafe {
            self.device.cmd_pipeline_barrier(
                cmd.raw,
                vk::PipelineStageFlags::ALL_COMMANDS,
                stage,
                vk::DependencyFlags::empty(),
                &[barrier],
                &[],
                &[],
            )
        };
    }

    /// Opens a debug label (a named region debuggers show) when debug utils are on.
    pub fn begin_label(&self, cmd: Cmd, name: &str) {
        let Some(debug) = &self.debug else { return };
        let Ok(name) = std::ffi::CString::new(name) else { return };
        let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
        // SAFETY: recording command buffer; the label string outlives the call.
        unsafe { debug.cmd_begin_debug_utils_label(cmd.raw, &label) };
    }

    /// Closes the label `begin_label` opened.
    pub fn end_label(&self, cmd: Cmd) {
        if let Some(debug) = &self.debug {
            // SAFETY: matches a begin_label before it in the same command buffer.
            unsafe { debug.cmd_end_debug_utils_label(cmd.raw) };
        }
    }
}
