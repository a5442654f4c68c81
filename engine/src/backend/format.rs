//! The texel and vertex formats Kage's resources use, named once here (with their size) so
//! that the layers above the backend never spell a Vulkan format.
use ash::vk;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Format {
    pub(super) raw: vk::Format,
    bytes: u8,
}

impl Format {
    pub const RGBA32_FLOAT: Format = Format { raw: vk::Format::R32G32B32A32_SFLOAT, bytes: 16 };
    pub const RGB32_FLOAT: Format = Format { raw: vk::Format::R32G32B32_SFLOAT, bytes: 12 };
    pub const RG32_FLOAT: Format = Format { raw: vk::Format::R32G32_SFLOAT, bytes: 8 };
    pub const RGBA16_FLOAT: Format = Format { raw: vk::Format::R16G16B16A16_SFLOAT, bytes: 8 };
    pub const RGBA8_SRGB: Format = Format { raw: vk::Format::R8G8B8A8_SRGB, bytes: 4 };
    pub const R32_UINT: Format = Format { raw: vk::Format::R32_UINT, bytes: 4 };
    pub const DEPTH32_FLOAT: Format = Format { raw: vk::Format::D32_SFLOAT, bytes: 4 };

    /// Bytes per texel (or per vertex attribute).
    pub fn texel_bytes(self) -> u64 {
        u64::from(self.bytes)
    }

    pub(super) fn aspect(self) -> vk::ImageAspectFlags {
        match self == Format::DEPTH32_FLOAT {
            true => vk::ImageAspectFlags::DEPTH,
            false => vk::ImageAspectFlags::COLOR,
        }
    }
}
