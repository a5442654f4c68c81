//! Buffers, with staging upload and readback for device-local ones.
use super::BufferUsage;
use super::Cmd;
use super::Context;
use crate::error::{Error, Result};
use crate::host_memory;
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

pub struct BufferDesc<'a> {
    pub name: &'a str,
    pub size: u64,
    pub usage: BufferUsage,
    /// `GpuOnly` for device-local data, `CpuToGpu` for per-frame uploads, `GpuToCpu` for
    /// readback.
    pub location: MemoryLocation,
}

pub struct Buffer {
    ctx: Arc<Context>,
    pub(crate) raw: vk::Buffer,
    allocation: Option<Allocation>,
    size: u64,
    name: Arc<str>,
}

impl Buffer {
    pub fn new(ctx: &Arc<Context>, desc: &BufferDesc) -> Result<Buffer> {
        if desc.size == 0 {
            return Err(Error::InvalidArgument(format!("buffer {} has size 0", desc.name)));
        }
        let info = vk::BufferCreateInfo::default()
            .size(desc.size)
            .usage(desc.usage.0)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_buffer(&info, None) }.map_err(Error::vk("vkCreateBuffer"))?;
        // SAFETY: raw was just created on this device.
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(raw) };
        let allocation = ctx.allocator().allocate(&AllocationCreateDesc {
            name: desc.name,
            requirements,
            location: desc.location,
            linear: true,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        });
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: the buffer is unbound and unused.
                unsafe { ctx.device.destroy_buffer(raw, None) };
                return Err(allocation_error(desc.name, requirements.size, e));
            }
        };
        // SAFETY: the allocation satisfies the buffer's requirements and is not bound elsewhere.
        let bound = unsafe { ctx.device.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) };
        let buffer = Buffer {
            ctx: ctx.clone(),
            raw,
            allocation: Some(allocation),
            size: desc.size,
            name: desc.name.into(),
        };
        bound.map_err(Error::vk("vkBindBufferMemory"))?;
        ctx.set_name(raw, desc.name);
        Ok(buffer)
    }

    /// A device-local buffer filled with `data` through a staging buffer.
    pub fn with_data(ctx: &Arc<Context>, name: &str, usage: BufferUsage, data: &[u8]) -> Result<Buffer> {
        let buffer = Buffer::new(
            ctx,
            &BufferDesc {
                name,
                size: data.len() as u64,
                usage: usage | BufferUsage::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        buffer.upload(data)?;
        Ok(buffer)
    }

    pub fn size(&self) -> u64 {
        self.size
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// Logs that the commands recorded into `cmd` use this buffer: read it, or (`writes`) may
    /// write it.
    pub(super) fn touched(&self, cmd: Cmd, writes: bool) {
        cmd.log.add(vk::Handle::as_raw(self.raw), &self.name, writes);
    }

    pub fn raw(&self) -> vk::Buffer {
        self.raw
    }

    pub(super) fn ctx(&self) -> &Arc<Context> {
        &self.ctx
    }

    fn mapped(&self) -> Option<&[u8]> {
        self.allocation.as_ref()?.mapped_slice().map(|s| &s[..self.size as usize])
    }

    /// The first `len` bytes of a host-visible buffer, to be written in place.
    pub(crate) fn mapped_mut(&mut self, len: u64) -> Result<&mut [u8]> {
        let (name, size) = (&self.name, self.size);
        if len > size {
            return Err(Error::Internal(format!("{len} bytes of buffer {name} ({size} bytes)")));
        }
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or_else(|| Error::Internal(format!("buffer {name} is not host-visible")))?;
        Ok(&mut slice[..len as usize])
    }

    /// Writes into a host-visible buffer at `offset`.
    pub fn write(&mut self, offset: u64, data: &[u8]) -> Result<()> {
        let end = offset.checked_add(data.len() as u64).filter(|&e| e <= self.size).ok_or_else(|| {
            Error::Internal(format!(
                "write of {} bytes at {offset} past the end of buffer {} ({} bytes)",
                data.len(),
                self.name,
                self.size
            ))
        })?;
        self.mapped_mut(end)?[offset as usize..].copy_from_slice(data);
        Ok(())
    }

    /// Copies `data` into this buffer: directly when mapped, else through a staging buffer.
    pub fn upload(&self, data: &[u8]) -> Result<()> {
        if data.len() as u64 > self.size {
            return Err(Error::Internal(format!(
                "upload of {} bytes into buffer {} of {} bytes",
                data.len(),
                self.name,
                self.size
            )));
        }
        let mut staging = Buffer::new(
            &self.ctx,
            &BufferDesc {
                name: &format!("{}.staging", self.name),
                size: data.len().max(1) as u64,
                usage: BufferUsage::TRANSFER_SRC,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        staging.write(0, data)?;
        let region = vk::BufferCopy::default().size(data.len() as u64);
        self.ctx.one_shot(&format!("{}.upload", self.name), |cmd| {
            // SAFETY: both buffers are alive until the one-shot submission has completed.
            unsafe { self.ctx.device.cmd_copy_buffer(cmd.raw, staging.raw, self.raw, &[region]) }
        })
    }

    /// Records writing `data` (at most 65536 bytes, a multiple of 4; it needs `TRANSFER_DST`
    /// usage) at `offset`, the bytes carried in the command buffer: a list that changes between
    /// the commands of one submission.
    pub fn record_update(&self, cmd: Cmd, offset: u64, data: &[u8]) {
        self.touched(cmd, true);
        // SAFETY: recording command buffer of this device, outside a rendering scope; the buffer
        // outlives the submission.
        unsafe { self.ctx.device.cmd_update_buffer(cmd.raw, self.raw, offset, data) }
    }

    /// Records filling the whole buffer with zeros (it needs `TRANSFER_DST` usage).
    pub fn record_zero(&self, cmd: Cmd) {
        self.touched(cmd, true);
        // SAFETY: recording command buffer of this device; the buffer outlives the submission.
        unsafe { self.ctx.device.cmd_fill_buffer(cmd.raw, self.raw, 0, vk::WHOLE_SIZE, 0) };
    }

    /// Reads the whole buffer back to the host (waits for the GPU), into memory reserved
    /// fallibly: a caller sized many of Kage's buffers (a frame's readback among them).
    pub fn read(&self) -> Result<Vec<u8>> {
        let copy = |bytes: &[u8]| host_memory::collect(bytes.iter().copied(), &self.name);
        if let Some(mapped) = self.mapped() {
            return Ok(copy(mapped)?);
        }
        let staging = Buffer::new(
            &self.ctx,
            &BufferDesc {
                name: &format!("{}.readback", self.name),
                size: self.size,
                usage: BufferUsage::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            },
        )?;
        let region = vk::BufferCopy::default().size(self.size);
        self.ctx.one_shot(&format!("{}.readback", self.name), |cmd| {
            // SAFETY: both buffers are alive until the submission has completed.
            unsafe { self.ctx.device.cmd_copy_buffer(cmd.raw, self.raw, staging.raw, &[region]) }
        })?;
        let mapped = staging
            .mapped()
            .ok_or_else(|| Error::Internal(format!("{} readback memory is not mapped", self.name)))?;
        Ok(copy(mapped)?)
    }
}

/// A failed allocation of `bytes` for the resource `name`: running out of memory names the
/// resource and its size, so that a host knows which setting to turn down.
pub(crate) fn allocation_error(name: &str, bytes: u64, e: gpu_allocator::AllocationError) -> Error {
    match e {
        gpu_allocator::AllocationError::OutOfMemory => Error::OutOfDeviceMemoryFor {
            name: name.to_owned(),
            bytes,
            reason: "no device memory block can hold it".into(),
        },
        e => Error::Allocation { name: name.to_owned(), message: e.to_string() },
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: Kage waits for every submission that uses a buffer before dropping it
        // (frames wait on their fence; one-shots wait inline).
        unsafe { self.ctx.device.destroy_buffer(self.raw, None) };
        if let Some(allocation) = self.allocation.take() {
            let _ = self.ctx.allocator().free(allocation);
        }
    }
}
