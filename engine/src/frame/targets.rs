//! The frame's render targets: the colour and depth images every technique draws into, and the
//! buffer the picture is read back through.
use crate::backend::{
    Buffer, BufferDesc, BufferUsage, Cmd, Context, Format, Image, ImageDesc, ImageUsage, MemoryLocation,
};
use crate::error::{Error, Result};
use crate::host_memory;
use crate::imageio::RgbaF32Image;
use std::sync::Arc;

/// Linear radiance, 32-bit float per channel: the picture is compared against the ray-traced
/// reference pixel by pixel, so no precision is given away before the output file.
pub const COLOR_FORMAT: Format = Format::RGBA32_FLOAT;
pub const DEPTH_FORMAT: Format = Format::DEPTH32_FLOAT;

/// The largest image side Kage renders (lavapipe and current GPUs allow 16384; 8192 keeps the
/// colour target and its readback within 2 GiB).
pub const MAX_SIZE: u32 = 8192;
// Any render Kage writes, `kage compare` and `imageio::read_exr` read back.
const _: () = assert!(MAX_SIZE as u64 * MAX_SIZE as u64 <= crate::image_size::MAX_IMAGE_PIXELS);

pub struct Targets {
    pub color: Image,
    pub depth: Image,
    readback: Buffer,
}

impl Targets {
    pub fn new(ctx: &Arc<Context>, width: u32, height: u32) -> Result<Targets> {
        if !(1..=MAX_SIZE).contains(&width) || !(1..=MAX_SIZE).contains(&height) {
            return Err(Error::InvalidArgument(format!(
                "image size {width}x{height}: each side must be 1 to {MAX_SIZE} pixels"
            )));
        }
        let color = Image::new(
            ctx,
            &ImageDesc {
                name: "color",
                width,
                height,
                layers: 1,
                levels: 1,
                array: false,
                format: COLOR_FORMAT,
                usage: ImageUsage::COLOR_ATTACHMENT | ImageUsage::TRANSFER_SRC,
            },
        )?;
        let depth = Image::new(
            ctx,
            &ImageDesc {
                name: "depth",
                width,
                height,
                layers: 1,
                levels: 1,
                array: false,
                format: DEPTH_FORMAT,
                // Sampled: the ASM refinement analysis reads the visible surfaces back.
                usage: ImageUsage::DEPTH_ATTACHMENT | ImageUsage::SAMPLED,
            },
        )?;
        let readback = Buffer::new(
            ctx,
            &BufferDesc {
                name: "color.readback",
                size: color.byte_size(),
                usage: BufferUsage::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            },
        )?;
        Ok(Targets { color, depth, readback })
    }

    /// Records the copy of the colour target into the readback buffer.
    pub fn record_readback(&self, cmd: Cmd) {
        self.color.record_copy_to(cmd, &self.readback)
    }

    /// The last frame read back: linear radiance, row 0 at the top.
    pub fn read(&self) -> Result<RgbaF32Image> {
        let bytes = self.readback.read()?;
        let texel = |t: &[u8]| {
            std::array::from_fn(|k| f32::from_ne_bytes([t[4 * k], t[4 * k + 1], t[4 * k + 2], t[4 * k + 3]]))
        };
        let pixels = host_memory::collect(bytes.chunks_exact(16).map(texel), "the frame's pixels")?;
        Ok(RgbaF32Image { width: self.color.width, height: self.color.height, pixels })
    }
}
