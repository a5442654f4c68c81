//! Images and samplers. Layout policy: every image is moved to `GENERAL` when it is created and
//! stays there between commands (see `pass` for why), so passes never track layouts. Copies
//! alone step into the transfer layout drivers prefer and back, inside `record_copy_to`,
//! `upload` and `upload_rows`.
use super::buffer::allocation_error;
use super::Cmd;
use super::{Buffer, BufferDesc, Context};
use super::{BufferUsage, Format, ImageUsage};
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// The most bytes [`Image::upload_rows`] stages at once.
pub const STAGING_BAND_BYTES: u64 = 64 << 20;

pub struct ImageDesc<'a> {
    pub name: &'a str,
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    /// Mipmap levels, each half the one before (rounded down, at least 1): 1 for most images.
    pub levels: u32,
    /// Viewed as a 2D array even with one layer (shaders declare `*2DArray`).
    pub array: bool,
    pub format: Format,
    pub usage: ImageUsage,
}

impl<'a> ImageDesc<'a> {
    /// `layers` square layers of `size`² texels, viewed as a 2D array (shadow maps, masks).
    pub fn square_array(
        name: &'a str,
        size: u32,
        layers: u32,
        format: Format,
        usage: ImageUsage,
    ) -> ImageDesc<'a> {
        ImageDesc { name, width: size, height: size, layers, levels: 1, array: true, format, usage }
    }
}

pub struct Image {
    ctx: Arc<Context>,
    pub(crate) raw: vk::Image,
    pub(crate) view: vk::ImageView,
    /// One 2D view per layer of a layered attachment, to render into a single layer.
    layer_views: Vec<vk::ImageView>,
    allocation: Option<Allocation>,
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    pub levels: u32,
    pub format: Format,
    name: Arc<str>,
}

impl Image {
    pub fn new(ctx: &Arc<Context>, desc: &ImageDesc) -> Result<Image> {
        // The limits of this format and usage (finer than the device-wide ones): an image
        // beyond them is invalid to create, so it is refused before vkCreateImage.
        // SAFETY: plain property query.
        let limits = unsafe {
            ctx.instance.get_physical_device_image_format_properties(
                ctx.physical,
                desc.format.raw,
                vk::ImageType::TYPE_2D,
                vk::ImageTiling::OPTIMAL,
                desc.usage.0,
                vk::ImageCreateFlags::empty(),
            )
        }
        .map_err(|e| match e {
            vk::Result::ERROR_FORMAT_NOT_SUPPORTED => Error::Unsupported(format!(
                "{:?} images with usage {:?} (for {})",
                desc.format, desc.usage, desc.name
            )),
            e => Error::vk("vkGetPhysicalDeviceImageFormatProperties")(e),
        })?;
        let max = limits.max_extent;
        if desc.width == 0
            || desc.height == 0
            || desc.layers == 0
            || desc.levels == 0
            || desc.levels > limits.max_mip_levels
            || desc.width > max.width
            || desc.height > max.height
            || desc.layers > limits.max_array_layers
        {
            return Err(Error::InvalidArgument(format!(
                "image {} of {}x{}x{} with {} levels is outside the device limits (1..={}x{}, {} layers, {} levels)",
                desc.name,
                desc.width,
                desc.height,
                desc.layers,
                desc.levels,
                max.width,
                max.height,
                limits.max_array_layers,
                limits.max_mip_levels
            )));
        }
        let bytes = u64::from(desc.width)
            * u64::from(desc.height)
            * u64::from(desc.layers)
            * desc.format.texel_bytes();
        if bytes > limits.max_resource_size {
            return Err(Error::OutOfDeviceMemoryFor {
                name: desc.name.into(),
                bytes,
                reason: format!(
                    "the device's largest image of this format is {} bytes",
                    limits.max_resource_size
                ),
            });
        }
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format.raw)
            .extent(vk::Extent3D { width: desc.width, height: desc.height, depth: 1 })
            .mip_levels(desc.levels)
            .array_layers(desc.layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage.0)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_image(&info, None) }.map_err(Error::vk("vkCreateImage"))?;
        // SAFETY: raw was just created on this device.
        let requirements = unsafe { ctx.device.get_image_memory_requirements(raw) };
        let allocation = match ctx.allocator().allocate(&AllocationCreateDesc {
            name: desc.name,
            requirements,
            location: MemoryLocation::GpuOnly,
            linear: false,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        }) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: unbound, unused image.
                unsafe { ctx.device.destroy_image(raw, None) };
                return Err(allocation_error(desc.name, requirements.size, e));
            }
        };
        let mut image = Image {
            ctx: ctx.clone(),
            raw,
            view: vk::ImageView::null(),
            layer_views: Vec::new(),
            allocation: None,
            width: desc.width,
            height: desc.height,
            layers: desc.layers,
            levels: desc.levels,
            format: desc.format,
            name: desc.name.into(),
        };
        // SAFETY: the allocation satisfies the image's requirements.
        let bound = unsafe { ctx.device.bind_image_memory(raw, allocation.memory(), allocation.offset()) };
        image.allocation = Some(allocation);
        bound.map_err(Error::vk("vkBindImageMemory"))?;
        ctx.set_name(raw, desc.name);

        let view_type = if desc.array || desc.layers > 1 {
            vk::ImageViewType::TYPE_2D_ARRAY
        } else {
            vk::ImageViewType::TYPE_2D
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(view_type)
            .format(desc.format.raw)
            .subresource_range(image.range());
        // SAFETY: the image is bound to memory; the view covers its whole range.
        image.view = unsafe { ctx.device.create_image_view(&view_info, None) }
            .map_err(Error::vk("vkCreateImageView"))?;
        ctx.set_name(image.view, &format!("{}.view", desc.name));

        let attachment = ImageUsage::COLOR_ATTACHMENT | ImageUsage::DEPTH_ATTACHMENT;
        if desc.layers > 1 && desc.usage.0.intersects(attachment.0) {
            for layer in 0..desc.layers {
                let range =
                    vk::ImageSubresourceRange { base_array_layer: layer, layer_count: 1, ..image.range() };
                let info = vk::ImageViewCreateInfo::default()
                    .image(raw)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(desc.format.raw)
                    .subresource_range(range);
                // SAFETY: the image is bound; the view covers one existing layer.
                let view = unsafe { ctx.device.create_image_view(&info, None) }
                    .map_err(Error::vk("vkCreateImageView"))?;
                ctx.set_name(view, &format!("{}.layer{layer}", desc.name));
                image.layer_views.push(view);
            }
        }
        ctx.one_shot(&format!("{}.to_general", desc.name), |cmd| {
            image.transition(cmd, vk::ImageLayout::UNDEFINED, vk::ImageLayout::GENERAL)
        })?;
        Ok(image)
    }

    /// Records a layout change of the whole image, ordered after all earlier commands.
    fn transition(&self, cmd: Cmd, from: vk::ImageLayout, to: vk::ImageLayout) {
        record_layout_barriers(&self.ctx, cmd, &[self.layout_barrier(from, to)]);
    }

    /// A layout change of the whole image, ordered after all earlier commands on it and before
    /// all later ones.
    fn layout_barrier(&self, from: vk::ImageLayout, to: vk::ImageLayout) -> vk::ImageMemoryBarrier<'static> {
        vk::ImageMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
            .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE)
            .old_layout(from)
            .new_layout(to)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(self.raw)
            .subresource_range(self.range())
    }

    pub(crate) fn range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: self.format.aspect(),
            base_mip_level: 0,
            level_count: self.levels,
            base_array_layer: 0,
            layer_count: self.layers,
        }
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// Logs that the commands recorded into `cmd` use this image: read it, or (`writes`) may
    /// write it.
    pub(super) fn touched(&self, cmd: Cmd, writes: bool) {
        cmd.log.add(vk::Handle::as_raw(self.raw), &self.name, writes);
    }

    pub fn view(&self) -> vk::ImageView {
        self.view
    }

    /// The view to render into `layer` (the whole image when it has one layer).
    pub(crate) fn attachment_view(&self, layer: u32) -> vk::ImageView {
        self.layer_views.get(layer as usize).copied().unwrap_or(self.view)
    }

    /// Width and height of mipmap level `level`.
    pub fn level_extent(&self, level: u32) -> (u32, u32) {
        ((self.width >> level).max(1), (self.height >> level).max(1))
    }

    /// Bytes of the whole image in a tightly packed buffer: level after level, each layer after
    /// layer.
    pub fn byte_size(&self) -> u64 {
        let texel = self.format.texel_bytes();
        let level = |l| {
            let (w, h) = self.level_extent(l);
            texel * w as u64 * h as u64 * self.layers as u64
        };
        (0..self.levels).map(level).sum()
    }

    /// One copy per level between the image and a tightly packed buffer laid out as
    /// [`Image::byte_size`] says.
    pub(crate) fn copy_regions(&self) -> Vec<vk::BufferImageCopy> {
        let texel = self.format.texel_bytes();
        let mut offset = 0;
        (0..self.levels)
            .map(|level| {
                let (width, height) = self.level_extent(level);
                let region = vk::BufferImageCopy::default()
                    .buffer_offset(offset)
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: self.format.aspect(),
                        mip_level: level,
                        base_array_layer: 0,
                        layer_count: self.layers,
                    })
                    .image_extent(vk::Extent3D { width, height, depth: 1 });
                offset += texel * width as u64 * height as u64 * self.layers as u64;
                region
            })
            .collect()
    }

    /// Records a copy of the whole image into `buffer` (tightly packed, layer after layer).
    pub fn record_copy_to(&self, cmd: Cmd, buffer: &Buffer) {
        self.touched(cmd, false);
        buffer.touched(cmd, true);
        let src = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        self.transition(cmd, vk::ImageLayout::GENERAL, src);
        // SAFETY: recording command buffer; the image was just moved to `src`.
        unsafe {
            self.ctx.device.cmd_copy_image_to_buffer(cmd.raw, self.raw, src, buffer.raw, &self.copy_regions())
        }
        self.transition(cmd, src, vk::ImageLayout::GENERAL);
    }

    /// Records copies of `size`² squares into `dst`, each from its first texel here (x, y, layer)
    /// to a byte offset there (rows tightly packed), ordered after all earlier commands on the
    /// image and before all later ones (the copies step into the transfer layout and back).
    /// Destination ranges must not overlap.
    pub fn record_copy_squares_to(&self, cmd: Cmd, dst: &Buffer, squares: &[([u32; 3], u64)], size: u32) {
        self.touched(cmd, false);
        dst.touched(cmd, true);
        let regions: Vec<vk::BufferImageCopy> = squares
            .iter()
            .map(|&([x, y, layer], offset)| {
                let layer = vk::ImageSubresourceLayers {
                    aspect_mask: self.format.aspect(),
                    mip_level: 0,
                    base_array_layer: layer,
                    layer_count: 1,
                };
                vk::BufferImageCopy::default()
                    .buffer_offset(offset)
                    .image_subresource(layer)
                    .image_offset(vk::Offset3D { x: x as i32, y: y as i32, z: 0 })
                    .image_extent(vk::Extent3D { width: size, height: size, depth: 1 })
            })
            .collect();
        let (general, src) = (vk::ImageLayout::GENERAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
        record_layout_barriers(&self.ctx, cmd, &[self.layout_barrier(general, src)]);
        // SAFETY: recording command buffer; the image and buffer are alive until the submission
        // completes, and the image was just moved to `src`.
        unsafe { self.ctx.device.cmd_copy_image_to_buffer(cmd.raw, self.raw, src, dst.raw, &regions) }
        record_layout_barriers(&self.ctx, cmd, &[self.layout_barrier(src, general)]);
    }

    /// Fills the image (every level) from tightly packed texels through a staging buffer.
    pub fn upload(&self, data: &[u8]) -> Result<()> {
        let expected = self.byte_size();
        if data.len() as u64 != expected {
            return Err(Error::Internal(format!(
                "upload of {} bytes into image {} of {expected} bytes",
                data.len(),
                self.name
            )));
        }
        let mut staging = self.staging(expected)?;
        staging.write(0, data)?;
        self.copy_from(&format!("{}.upload", self.name), &staging, &self.copy_regions())
    }

    /// A host-visible buffer of `size` bytes to copy into this image from.
    fn staging(&self, size: u64) -> Result<Buffer> {
        Buffer::new(
            &self.ctx,
            &BufferDesc {
                name: &format!("{}.staging", self.name),
                size,
                usage: BufferUsage::TRANSFER_SRC,
                location: MemoryLocation::CpuToGpu,
            },
        )
    }

    /// Copies `regions` of `staging` into the image in one submission, waiting for it.
    fn copy_from(&self, label: &str, staging: &Buffer, regions: &[vk::BufferImageCopy]) -> Result<()> {
        self.ctx.one_shot(label, |cmd| {
            let dst = vk::ImageLayout::TRANSFER_DST_OPTIMAL;
            self.transition(cmd, vk::ImageLayout::GENERAL, dst);
            // SAFETY: both are alive until the one-shot wait returns; the image is in `dst`.
            unsafe { self.ctx.device.cmd_copy_buffer_to_image(cmd.raw, staging.raw, self.raw, dst, regions) }
            self.transition(cmd, dst, vk::ImageLayout::GENERAL);
        })
    }

    /// Fills a one-level, one-layer image band by band through one staging buffer of at most
    /// [`STAGING_BAND_BYTES`]: `fill(first_row, texels)` writes the tightly packed texels of
    /// the rows from `first_row` on. A large image (a 16k environment map is 2 GiB as RGBA32F)
    /// then never has a second copy of itself on the host.
    pub fn upload_rows(&self, mut fill: impl FnMut(u32, &mut [u8])) -> Result<()> {
        if self.levels != 1 || self.layers != 1 {
            return Err(Error::Internal(format!(
                "upload_rows into image {} of several levels or layers",
                self.name
            )));
        }
        let row_bytes = self.byte_size() / self.height as u64;
        let band_rows = (STAGING_BAND_BYTES / row_bytes.max(1)).clamp(1, self.height as u64) as u32;
        let mut staging = self.staging(row_bytes * band_rows as u64)?;
        for first in (0..self.height).step_by(band_rows as usize) {
            let rows = band_rows.min(self.height - first);
            fill(first, staging.mapped_mut(row_bytes * rows as u64)?);
            let region = vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: self.format.aspect(),
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_offset(vk::Offset3D { x: 0, y: first as i32, z: 0 })
                .image_extent(vk::Extent3D { width: self.width, height: rows, depth: 1 });
            self.copy_from(
                &format!("{}.upload rows {first}..{}", self.name, first + rows),
                &staging,
                &[region],
            )?;
        }
        Ok(())
    }

    /// Reads the whole image back (waits for the GPU).
    pub fn read(&self) -> Result<Vec<u8>> {
        let staging = Buffer::new(
            &self.ctx,
            &BufferDesc {
                name: &format!("{}.readback", self.name),
                size: self.byte_size(),
                usage: BufferUsage::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            },
        )?;
        self.ctx.one_shot(&format!("{}.readback", self.name), |cmd| self.record_copy_to(cmd, &staging))?;
        staging.read()
    }
}

/// Records `barriers`, each ordered after all earlier commands and before all later ones.
fn record_layout_barriers(ctx: &Context, cmd: Cmd, barriers: &[vk::ImageMemoryBarrier]) {
    // SAFETY: recording command buffer; the images are alive until the submission completes.
    unsafe {
        ctx.device.cmd_pipeline_barrier(
            cmd.raw,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            barriers,
        )
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: no submission using the image is pending (frames and one-shots wait).
        unsafe {
            for &view in self.layer_views.iter().chain([&self.view]) {
                if view != vk::ImageView::null() {
                    self.ctx.device.destroy_image_view(view, None);
                }
            }
            self.ctx.device.destroy_image(self.raw, None);
        }
        if let Some(allocation) = self.allocation.take() {
            let _ = self.ctx.allocator().free(allocation);
        }
    }
}

/// A sampler; Kage needs only a few kinds, chosen by the constructor's arguments.
pub struct Sampler {
    ctx: Arc<Context>,
    pub(crate) raw: vk::Sampler,
}

/// What a sampler returns beyond an image's edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edge {
    /// Wrap around (longitude of an equirectangular map).
    Repeat,
    /// The edge texel.
    Clamp,
    /// Wrap around, every other repeat mirrored.
    Mirror,
}

impl Edge {
    fn mode(self) -> vk::SamplerAddressMode {
        match self {
            Edge::Repeat => vk::SamplerAddressMode::REPEAT,
            Edge::Clamp => vk::SamplerAddressMode::CLAMP_TO_EDGE,
            Edge::Mirror => vk::SamplerAddressMode::MIRRORED_REPEAT,
        }
    }
}

/// How a sampler filters: magnified and minified texels (linear or nearest), mipmap levels
/// (`Some(linear)` between them, `None` level 0 only), and its edges in u and v.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplerDesc {
    pub magnify_linear: bool,
    pub minify_linear: bool,
    pub mipmaps: Option<bool>,
    pub u: Edge,
    pub v: Edge,
}

impl Sampler {
    /// A sampler with linear or nearest filtering of level 0 and the given behaviour beyond the
    /// edges in u and v (w, layers of arrays, clamps).
    pub fn new(ctx: &Arc<Context>, name: &str, linear: bool, u: Edge, v: Edge) -> Result<Sampler> {
        let desc = SamplerDesc { magnify_linear: linear, minify_linear: linear, mipmaps: None, u, v };
        Sampler::with_desc(ctx, name, &desc)
    }

    /// A sampler as `desc` says (w, layers of arrays, clamps).
    pub fn with_desc(ctx: &Arc<Context>, name: &str, desc: &SamplerDesc) -> Result<Sampler> {
        let filter = |linear| if linear { vk::Filter::LINEAR } else { vk::Filter::NEAREST };
        let (mipmap_mode, max_lod) = match desc.mipmaps {
            Some(true) => (vk::SamplerMipmapMode::LINEAR, vk::LOD_CLAMP_NONE),
            Some(false) => (vk::SamplerMipmapMode::NEAREST, vk::LOD_CLAMP_NONE),
            None => (vk::SamplerMipmapMode::NEAREST, 0.0),
        };
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(filter(desc.magnify_linear))
            .min_filter(filter(desc.minify_linear))
            .mipmap_mode(mipmap_mode)
            .address_mode_u(desc.u.mode())
            .address_mode_v(desc.v.mode())
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(max_lod);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_sampler(&info, None) }.map_err(Error::vk("vkCreateSampler"))?;
        ctx.set_name(raw, name);
        Ok(Sampler { ctx: ctx.clone(), raw })
    }
}

impl Sampler {
    /// A depth-comparison sampler (`sampler2DArrayShadow`): bilinear percentage-closer
    /// filtering of `reference <= texel` (1 where the reference depth is not behind the
    /// stored one), clamped at the edges.
    pub fn comparison(ctx: &Arc<Context>, name: &str) -> Result<Sampler> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .compare_enable(true)
            .compare_op(vk::CompareOp::LESS_OR_EQUAL)
            .max_lod(0.0);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_sampler(&info, None) }.map_err(Error::vk("vkCreateSampler"))?;
        ctx.set_name(raw, name);
        Ok(Sampler { ctx: ctx.clone(), raw })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        // SAFETY: no pending submission uses the sampler.
        unsafe { self.ctx.device.destroy_sampler(self.raw, None) };
    }
}
