//! The thin Vulkan layer: everything that talks to ash lives here, one concern per file.
//!
//! Resources hold an `Arc<Context>` and destroy themselves on drop, so a host cannot leak them
//! or outlive the device. Every object gets a debug name when `VK_EXT_debug_utils` is present.
mod access;
mod buffer;
mod commands;
mod context;
mod descriptor;
mod device;
mod format;
mod image;
mod pipeline;
mod reflect;
mod rendering;
mod texel_buffer;
mod timestamps;
mod usage;
mod validation;
mod vk_error;

pub use access::{AccessLog, Touch};
pub use buffer::{Buffer, BufferDesc};
pub use commands::{Cmd, CommandRecorder};
pub use context::{Calibration, Context, ContextDesc, DeviceInfo, HostVulkan};
pub use descriptor::{Binding, BindingKind};
pub use device::{CALIBRATED_TIMESTAMPS, FRAGMENT_STORES, GEOMETRY_SHADER};
pub use format::Format;
pub use image::{Edge, Image, ImageDesc, Sampler, SamplerDesc, STAGING_BAND_BYTES};
pub use pipeline::{
    ComputePipeline, DepthTest, GraphicsDesc, GraphicsPipeline, Topology, VertexAttribute, VertexBuffer,
};
pub use rendering::{Depth, Target};
pub use texel_buffer::TexelBuffer;
pub use timestamps::TimestampPool;
pub use usage::{BufferUsage, ImageUsage};
pub use validation::ValidationLog;

pub use ash::vk;
pub use gpu_allocator::MemoryLocation;
