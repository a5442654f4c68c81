//! A timestamp query pool: two queries per pass, read after the frame's fence.
use super::Cmd;
use super::Context;
use crate::error::{Error, Result};
use ash::vk;
use std::sync::Arc;

pub struct TimestampPool {
    ctx: Arc<Context>,
    raw: vk::QueryPool,
    capacity: u32,
}

impl TimestampPool {
    pub fn new(ctx: &Arc<Context>, name: &str, capacity: u32) -> Result<TimestampPool> {
        let info =
            vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(capacity);
        // SAFETY: valid device and create info.
        let raw =
            unsafe { ctx.device.create_query_pool(&info, None) }.map_err(Error::vk("vkCreateQueryPool"))?;
        ctx.set_name(raw, name);
        Ok(TimestampPool { ctx: ctx.clone(), raw, capacity })
    }

    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    pub fn reset(&self, cmd: Cmd, count: u32) {
        // SAFETY: recording command buffer; count <= capacity (checked by the caller).
        unsafe { self.ctx.device.cmd_reset_query_pool(cmd.raw, self.raw, 0, count) };
    }

    pub fn write(&self, cmd: Cmd, stage: vk::PipelineStageFlags, index: u32) {
        // SAFETY: recording command buffer; the query was reset earlier in the same buffer.
        unsafe { self.ctx.device.cmd_write_timestamp(cmd.raw, stage, self.raw, index) };
    }

    /// Reads `count` timestamps (ticks) once the submission that wrote them has completed.
    pub fn read(&self, count: u32) -> Result<Vec<u64>> {
        let mut ticks = vec![0u64; count as usize];
        // SAFETY: the writing submission has been waited for; WAIT makes availability certain.
        unsafe {
            self.ctx.device.get_query_pool_results(
                self.raw,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .map_err(Error::vk("vkGetQueryPoolResults"))?;
        Ok(ticks)
    }
}

impl Drop for TimestampPool {
    fn drop(&mut self) {
        // SAFETY: no pending submission writes the pool.
        unsafe { self.ctx.device.destroy_query_pool(self.raw, None) };
    }
}
