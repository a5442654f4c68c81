//! Read-only buffers of RGBA32UI texels, bound as uniform texel buffers (`usamplerBuffer`).
//!
//! Why not storage buffers: llvmpipe (Mesa 22.3) reads a storage buffer at a per-lane address
//! one lane and one word at a time, each behind a branch on the lane's mask and the buffer's
//! bound, while a texel fetch gathers all lanes' 16-byte texels without branching
//! (vendor-notes.md). The BVH's traversal reads most of its time away, so its data lives here.
use super::{Buffer, BufferUsage, Context};
use crate::error::{Error, Result};
use ash::vk;
use std::sync::Arc;

/// Bytes per texel: one `uvec4` of `texelFetch`.
const TEXEL_BYTES: usize = 16;

pub struct TexelBuffer {
    buffer: Buffer,
    pub(super) view: vk::BufferView,
}

impl TexelBuffer {
    /// A device-local texel buffer holding `data`, whose length must be a whole number of
    /// texels and at most the device's `maxTexelBufferElements` of them.
    pub fn with_data(ctx: &Arc<Context>, name: &str, data: &[u8]) -> Result<TexelBuffer> {
        if data.is_empty() || data.len() % TEXEL_BYTES != 0 {
            return Err(Error::Internal(format!(
                "texel buffer {name}: {} bytes is not a whole, nonzero number of {TEXEL_BYTES}-byte texels",
                data.len()
            )));
        }
        let texels = (data.len() / TEXEL_BYTES) as u64;
        let max = ctx.info().max_texel_buffer_elements as u64;
        if texels > max {
            return Err(Error::OutOfDeviceMemoryFor {
                name: name.into(),
                bytes: data.len() as u64,
                reason: format!("{texels} texels, more than the device's maxTexelBufferElements ({max})"),
            });
        }
        let buffer =
            Buffer::with_data(ctx, name, BufferUsage::UNIFORM_TEXEL | BufferUsage::TRANSFER_SRC, data)?;
        let info = vk::BufferViewCreateInfo::default()
            .buffer(buffer.raw)
            .format(vk::Format::R32G32B32A32_UINT)
            .offset(0)
            .range(vk::WHOLE_SIZE);
        // SAFETY: valid device; the buffer has uniform texel usage and outlives the view (both
        // are dropped together, the view first).
        let view =
            unsafe { ctx.device.create_buffer_view(&info, None) }.map_err(Error::vk("vkCreateBufferView"))?;
        ctx.set_name(view, &format!("{name}.view"));
        Ok(TexelBuffer { buffer, view })
    }

    /// The buffer under the view: its size, name and contents.
    pub fn buffer(&self) -> &Buffer {
        &self.buffer
    }
}

impl Drop for TexelBuffer {
    fn drop(&mut self) {
        // SAFETY: as for the buffer (Buffer's drop): no submission that uses it is pending.
        unsafe { self.buffer.ctx().device.destroy_buffer_view(self.view, None) };
    }
}
