//! What a buffer or an image is used for, as the layers above the backend name it; each value
//! is the set of Vulkan usage flags it stands for.
use ash::vk;
use std::ops::BitOr;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BufferUsage(pub(super) vk::BufferUsageFlags);

impl BufferUsage {
    pub const STORAGE: BufferUsage = BufferUsage(vk::BufferUsageFlags::STORAGE_BUFFER);
    pub const UNIFORM: BufferUsage = BufferUsage(vk::BufferUsageFlags::UNIFORM_BUFFER);
    pub const UNIFORM_TEXEL: BufferUsage = BufferUsage(vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER);
    pub const STORAGE_TEXEL: BufferUsage = BufferUsage(vk::BufferUsageFlags::STORAGE_TEXEL_BUFFER);
    pub const VERTEX: BufferUsage = BufferUsage(vk::BufferUsageFlags::VERTEX_BUFFER);
    pub const INDEX: BufferUsage = BufferUsage(vk::BufferUsageFlags::INDEX_BUFFER);
    pub const TRANSFER_SRC: BufferUsage = BufferUsage(vk::BufferUsageFlags::TRANSFER_SRC);
    pub const TRANSFER_DST: BufferUsage = BufferUsage(vk::BufferUsageFlags::TRANSFER_DST);
}

impl BitOr for BufferUsage {
    type Output = BufferUsage;
    fn bitor(self, other: BufferUsage) -> BufferUsage {
        BufferUsage(self.0 | other.0)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageUsage(pub(super) vk::ImageUsageFlags);

impl ImageUsage {
    pub const SAMPLED: ImageUsage = ImageUsage(vk::ImageUsageFlags::SAMPLED);
    pub const STORAGE: ImageUsage = ImageUsage(vk::ImageUsageFlags::STORAGE);
    pub const COLOR_ATTACHMENT: ImageUsage = ImageUsage(vk::ImageUsageFlags::COLOR_ATTACHMENT);
    pub const DEPTH_ATTACHMENT: ImageUsage = ImageUsage(vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT);
    pub const TRANSFER_SRC: ImageUsage = ImageUsage(vk::ImageUsageFlags::TRANSFER_SRC);
    pub const TRANSFER_DST: ImageUsage = ImageUsage(vk::ImageUsageFlags::TRANSFER_DST);
}

impl BitOr for ImageUsage {
    type Output = ImageUsage;
    fn bitor(self, other: ImageUsage) -> ImageUsage {
        ImageUsage(self.0 | other.0)
    }
}
