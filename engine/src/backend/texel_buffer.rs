//! Buffers of RGBA32UI texels, read as uniform texel buffers (`usamplerBuffer`) and, where a
//! shader writes them (ASM's page packing), bound as storage texel buffers (`uimageBuffer`):
//! their size limit is `maxTexelBufferElements` texels, not `maxStorageBufferRange` bytes
//! (128 MiB on lavapipe, less than a 256 MiB ASM budget's pages).
//!
//! Why not storage buffers: llvmpipe (Mesa 22.3) reads a storage buffer at a per-lane address
//! one lane and one word at a time, each behind a branch on the lane's mask and the buffer's
//! bound, while a texel fetch gathers all lanes' 16-byte texels without branching
//! (vendor-notes.md). What hot loops read at such addresses lives here: the BVH's traversal
//! data, ASM's page table, Tamura's per-region SH basis.
use super::{Buffer, BufferDesc, BufferUsage, Context};
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// Bytes per texel: one `uvec4` of `texelFetch`.
const TEXEL_BYTES: u64 = 16;

pub struct TexelBuffer {
    buffer: Buffer,
    pub(super) view: vk::BufferView,
}

impl TexelBuffer {
    /// A texel buffer of `bytes` (a whole, nonzero number of texels, at most the device's
    /// `maxTexelBufferElements` of them) in `location`: `GpuOnly` for data uploaded once,
    /// `CpuToGpu` for data the host rewrites ([`TexelBuffer::write`]).
    pub fn new(ctx: &Arc<Context>, name: &str, bytes: u64, location: MemoryLocation) -> Result<TexelBuffer> {
        if bytes == 0 || bytes % TEXEL_BYTES != 0 {
            return Err(Error::Internal(format!(
                "texel buffer {name}: {bytes} bytes is not a whole, nonzero number of {TEXEL_BYTES}-byte texels"
            )));
        }
        let texels = bytes / TEXEL_BYTES;
        let max = u64::from(ctx.info().max_texel_buffer_elements);
        if texels > max {
            return Err(Error::OutOfDeviceMemoryFor {
                name: name.into(),
                bytes,
                reason: format!("{texels} texels, more than the device's maxTexelBufferElements ({max})"),
            });
        }
        // RGBA32UI supports storage texel buffers on every device (a format feature Vulkan
        // requires).
        let usage = BufferUsage::UNIFORM_TEXEL
            | BufferUsage::STORAGE_TEXEL
            | BufferUsage::TRANSFER_SRC
            | BufferUsage::TRANSFER_DST;
        let buffer = Buffer::new(ctx, &BufferDesc { name, size: bytes, usage, location })?;
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

    /// A device-local texel buffer holding `data`.
    pub fn with_data(ctx: &Arc<Context>, name: &str, data: &[u8]) -> Result<TexelBuffer> {
        let texels = TexelBuffer::new(ctx, name, data.len() as u64, MemoryLocation::GpuOnly)?;
        texels.buffer.upload(data)?;
        Ok(texels)
    }

    /// Writes into a host-visible texel buffer at `offset` (bytes).
    pub fn write(&mut self, offset: u64, data: &[u8]) -> Result<()> {
        self.buffer.write(offset, data)
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
