//! `kage_context`: a Vulkan device for Kage, created by Kage or adopted from the host.
use super::args;
use super::handles;
use super::result::{boundary, kage_result, Failure};
use crate::backend::{Context, ContextDesc, HostVulkan};
use std::ffi::{c_char, c_void};
use std::sync::Arc;

/// A Vulkan device, queue and memory allocator that scenes are precomputed and rendered with.
pub struct kage_context {
    pub(crate) ctx: Arc<Context>,
}

impl kage_context {
    /// Fails the call with `KAGE_RESULT_VALIDATION` when the validation layer reported
    /// anything since the last check (only with validation on).
    pub(crate) fn check_validation(ctx: &Context) -> Result<(), Failure> {
        let messages = ctx.take_validation_messages();
        if messages.is_empty() {
            return Ok(());
        }
        Err(Failure::new(
            kage_result::Validation,
            format!("validation reported {} message(s):\n{}", messages.len(), messages.join("\n")),
        ))
    }
}

/// How `kage_context_create` makes its device.
#[repr(C)]
pub struct kage_context_desc {
    /// `sizeof(kage_context_desc)` as the host's kage.h declares it: checked, so that a host built
    /// against another version of the header gets an error instead of a misread struct.
    pub size: u32,
    /// Use the first Vulkan device whose name contains this (case-insensitive), e.g.
    /// "llvmpipe". NULL: the `KAGE_DEVICE` environment variable, else a discrete GPU, else any.
    pub device_name: *const c_char,
    /// Turn on VK_LAYER_KHRONOS_validation. Then any warning or error it reports during a call
    /// makes that call fail with `KAGE_RESULT_VALIDATION`. A missing layer is an error.
    pub validation: bool,
}

/// Creates a context with its own Vulkan instance and device.
///
/// On success `*context` is a new handle that the host owns and frees with
/// `kage_context_destroy`; on failure it is set to NULL. `desc` is only read during the call.
///
/// # Safety
/// `desc` must be NULL or point to a valid `kage_context_desc` whose `device_name` is NULL or a
/// NUL-terminated string; `context` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_context_create(
    desc: *const kage_context_desc,
    context: *mut *mut kage_context,
) -> kage_result {
    boundary(|| {
        // SAFETY: the caller promises NULL or a writable pointer.
        let context = unsafe { args::handle_out(context, "context") }?;
        // SAFETY: the caller promises NULL or a valid desc.
        let desc = unsafe { args::sized(desc, "desc") }?;
        let device = match desc.device_name.is_null() {
            true => None,
            // SAFETY: the caller promises a NUL-terminated string.
            false => Some(unsafe { args::text(desc.device_name, "desc->device_name") }?.to_owned()),
        };
        let ctx = Context::new(&ContextDesc { validation: desc.validation, device })?;
        kage_context::check_validation(&ctx)?;
        *context = handles::register(kage_context { ctx });
        Ok(())
    })
}

/// The host's Vulkan objects for `kage_context_create_from_vulkan`. Each handle is passed as a
/// pointer (dispatchable Vulkan handles are pointers), so that kage.h needs no Vulkan header.
#[repr(C)]
pub struct kage_vulkan_handles {
    /// `sizeof(kage_vulkan_handles)` as the host's kage.h declares it: checked, so that a host built
    /// against another version of the header gets an error instead of a misread struct.
    pub size: u32,
    /// The VkInstance, created with apiVersion 1.2 or later.
    pub instance: *mut c_void,
    /// The VkPhysicalDevice the device was created on.
    pub physical_device: *mut c_void,
    /// The VkDevice, created with the device extensions VK_KHR_dynamic_rendering and
    /// VK_KHR_push_descriptor enabled and the features dynamicRendering and
    /// shaderStorageImageExtendedFormats on.
    pub device: *mut c_void,
    /// A queue family with graphics and compute; Kage's command pool is made for it.
    pub queue_family: u32,
    /// The VkQueue Kage submits to, of that family.
    pub queue: *mut c_void,
    /// Whether the instance has VK_EXT_debug_utils enabled; Kage then names its objects and
    /// labels its passes (for RenderDoc and validation messages).
    pub debug_utils: bool,
}

/// Creates a context on the host's Vulkan instance and device instead of its own.
///
/// Kage never destroys the host's objects: the host destroys them after `kage_context_destroy`
/// and after destroying every renderer made with this context. While any Kage call on this
/// context (or on its renderers) runs, the host must not use `handles->queue` (Vulkan requires
/// external synchronization of a queue) nor destroy the device. Validation is the host's
/// business here: enable the layer on its own instance and watch its own messenger.
///
/// On success `*context` is a new handle that the host owns and frees with
/// `kage_context_destroy`; on failure it is set to NULL. `handles` is only read during the call.
///
/// # Safety
/// `handles` must be NULL or point to valid, live Vulkan handles created as described, through
/// the system Vulkan loader; `context` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_context_create_from_vulkan(
    handles: *const kage_vulkan_handles,
    context: *mut *mut kage_context,
) -> kage_result {
    boundary(|| {
        // SAFETY: the caller promises NULL or a writable pointer.
        let context = unsafe { args::handle_out(context, "context") }?;
        // SAFETY: the caller promises NULL or a valid struct.
        let host = unsafe { args::sized(handles, "handles") }?;
        for (name, handle) in [
            ("handles->instance", host.instance),
            ("handles->physical_device", host.physical_device),
            ("handles->device", host.device),
            ("handles->queue", host.queue),
        ] {
            if handle.is_null() {
                return Err(Failure::new(kage_result::NullArgument, format!("{name} is NULL")));
            }
        }
        let host = HostVulkan {
            instance: host.instance as u64,
            physical_device: host.physical_device as u64,
            device: host.device as u64,
            queue_family: host.queue_family,
            queue: host.queue as u64,
            debug_utils: host.debug_utils,
        };
        // SAFETY: the caller promises live handles created as `kage_vulkan_handles` says.
        let ctx = unsafe { Context::adopt(&host) }?;
        *context = handles::register(kage_context { ctx });
        Ok(())
    })
}

/// Destroys a context handle. Renderers made with it keep the device alive until they are
/// destroyed too (they hold their own reference); scenes do not depend on it. NULL is allowed
/// and does nothing. The handle must not be used after OK; on `KAGE_RESULT_BUSY` (a call on
/// another thread is using it) nothing was destroyed: call again once that call has returned.
#[no_mangle]
pub extern "C" fn kage_context_destroy(context: *mut kage_context) -> kage_result {
    boundary(|| handles::destroy(context, "context"))
}

/// Writes the device's name (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)") into `buffer` as a
/// NUL-terminated string; as `kage_last_error_message` for `capacity` and `length` (NULL with
/// capacity 0 asks for the length alone).
///
/// # Safety
/// `context` must be NULL or a handle; `buffer` NULL or `capacity` writable bytes; `length`
/// NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_context_device_name(
    context: *const kage_context,
    buffer: *mut c_char,
    capacity: usize,
    length: *mut usize,
) -> kage_result {
    boundary(|| {
        let context = handles::get(context, "context")?;
        // SAFETY: the caller's promises about buffer and length.
        unsafe { args::copy_text(&context.ctx.info().name, buffer, capacity, length, "buffer") }
    })
}
