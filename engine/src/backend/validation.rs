//! Collects what `VK_LAYER_KHRONOS_validation` reports, so that tests can fail on any message
//! of warning or error severity instead of letting it scroll past on stderr.
use ash::vk;
use std::ffi::{c_void, CStr};
use std::sync::Mutex;

#[derive(Default)]
pub struct ValidationLog {
    messages: Mutex<Vec<String>>,
}

impl ValidationLog {
    pub fn push(&self, message: String) {
        self.messages.lock().unwrap_or_else(|e| e.into_inner()).push(message);
    }

    /// Returns and clears every message collected so far.
    pub fn take(&self) -> Vec<String> {
        std::mem::take(&mut *self.messages.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

pub(crate) const SEVERITIES: vk::DebugUtilsMessageSeverityFlagsEXT =
    vk::DebugUtilsMessageSeverityFlagsEXT::from_raw(
        vk::DebugUtilsMessageSeverityFlagsEXT::WARNING.as_raw()
            | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR.as_raw(),
    );

/// The messenger callback. `user_data` is the `ValidationLog` owned by the context, which
/// destroys the messenger before dropping the log.
pub(crate) unsafe extern "system" fn callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut c_void,
) -> vk::Bool32 {
    if data.is_null() || user_data.is_null() {
        return vk::FALSE;
    }
    // SAFETY: the layer passes valid callback data for the duration of the call.
    let data = unsafe { &*data };
    let text = if data.p_message.is_null() {
        String::from("(no message)")
    } else {
        // SAFETY: p_message is a NUL-terminated string owned by the layer.
        unsafe { CStr::from_ptr(data.p_message) }.to_string_lossy().into_owned()
    };
    let message = format!("[{severity:?} {kind:?}] {text}");
    eprintln!("kage validation: {message}");
    // SAFETY: user_data is the context's ValidationLog, alive while the messenger exists.
    let log = unsafe { &*(user_data as *const ValidationLog) };
    log.push(message);
    vk::FALSE
}
