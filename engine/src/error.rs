//! The engine's error type. Every `vk::Result` is mapped by [`Error::vk`] so that the failure
//! classes a host cares about (out of memory, device lost) stay distinguishable.
use ash::vk;

pub type Result<T, E = Error> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("the Vulkan loader could not be opened: {0}")]
    Loader(String),
    #[error("no usable Vulkan device: {0}")]
    NoDevice(String),
    #[error("the device lacks {0}, which Kage needs")]
    Unsupported(String),
    #[error("out of device memory in {call}")]
    OutOfDeviceMemory { call: &'static str },
    #[error("out of host memory in {call}")]
    OutOfHostMemory { call: &'static str },
    /// One resource that the device cannot hold: beyond its size limit for the format, or no
    /// memory left for it. Like the two above, a request to retry with smaller settings.
    #[error("out of device memory for {name} ({bytes} bytes): {reason}")]
    OutOfDeviceMemoryFor { name: String, bytes: u64, reason: String },
    #[error("the Vulkan device was lost in {call}")]
    DeviceLost { call: &'static str },
    #[error("{call} failed: {result:?}")]
    Vulkan { call: &'static str, result: vk::Result },
    #[error("GPU memory allocation for {name} failed: {message}")]
    Allocation { name: String, message: String },
    #[error("timed out waiting for the GPU in {0}")]
    Timeout(&'static str),
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    #[error(transparent)]
    Image(#[from] crate::imageio::ImageIoError),
    #[error(transparent)]
    Probes(#[from] crate::techniques::probes::ProbeError),
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
}

impl Error {
    /// Maps a failed Vulkan call: out-of-memory results and device loss get their own variants,
    /// everything else keeps its `vk::Result`.
    pub fn vk(call: &'static str) -> impl FnOnce(vk::Result) -> Error {
        move |result| match result {
            vk::Result::ERROR_OUT_OF_DEVICE_MEMORY => Error::OutOfDeviceMemory { call },
            vk::Result::ERROR_OUT_OF_HOST_MEMORY => Error::OutOfHostMemory { call },
            vk::Result::ERROR_DEVICE_LOST => Error::DeviceLost { call },
            vk::Result::TIMEOUT => Error::Timeout(call),
            result => Error::Vulkan { call, result },
        }
    }
}
