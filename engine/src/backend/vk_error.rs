//! How a failed Vulkan call becomes an [`Error`]: the failure classes a host handles (out of
//! memory, device loss, a timeout) get their own variants; any other result is named.
use crate::error::Error;
use ash::vk;

impl Error {
    /// The error of `call` failing with a `VkResult`.
    pub(crate) fn vk(call: &'static str) -> impl FnOnce(vk::Result) -> Error {
        move |result| match result {
            vk::Result::ERROR_OUT_OF_DEVICE_MEMORY => Error::OutOfDeviceMemory { call },
            vk::Result::ERROR_OUT_OF_HOST_MEMORY => Error::OutOfHostMemory { call },
            vk::Result::ERROR_DEVICE_LOST => Error::DeviceLost { call },
            vk::Result::TIMEOUT => Error::Timeout(call),
            result => Error::Vulkan { call, result: format!("{result:?}") },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Device loss and running out of memory have their own errors, and their own C result
    /// codes (capi::result's unit tests map every error class to its code). Lavapipe cannot be
    /// made to lose its device on demand: it has no GPU to reset and no watchdog (a shader
    /// that never ends just occupies a CPU thread until the 10-minute fence timeout), so the
    /// mapping every call site goes through is what is tested here, and pass's unit tests check
    /// that every frame after a loss still reports the loss.
    #[test]
    fn device_loss_and_out_of_memory_results_keep_their_class() {
        let map = |result| Error::vk("vkQueueSubmit")(result);
        assert!(matches!(map(vk::Result::ERROR_DEVICE_LOST), Error::DeviceLost { call: "vkQueueSubmit" }));
        assert!(matches!(map(vk::Result::ERROR_OUT_OF_DEVICE_MEMORY), Error::OutOfDeviceMemory { .. }));
        assert!(matches!(map(vk::Result::ERROR_OUT_OF_HOST_MEMORY), Error::OutOfHostMemory { .. }));
        assert!(matches!(map(vk::Result::TIMEOUT), Error::Timeout("vkQueueSubmit")));
        let other = map(vk::Result::ERROR_INITIALIZATION_FAILED);
        assert_eq!(other.to_string(), "vkQueueSubmit failed: ERROR_INITIALIZATION_FAILED");
        assert_eq!(
            map(vk::Result::ERROR_DEVICE_LOST).to_string(),
            "the Vulkan device was lost in vkQueueSubmit"
        );
    }
}
