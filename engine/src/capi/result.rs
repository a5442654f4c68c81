//! Result codes, the thread's last error message, and the panic boundary around every export.
use super::args;
use crate::error::Error;
use crate::host_memory::OutOfHostMemory;
use std::cell::RefCell;
use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What every Kage function returns. `KAGE_RESULT_OK` is 0; every failure class has its own
/// value, and `kage_last_error_message` gives the details.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum kage_result {
    Ok = 0,
    /// A required pointer argument was NULL.
    NullArgument = 1,
    /// A handle that is not a live handle of the expected kind (destroyed, or never made).
    InvalidHandle = 2,
    /// An argument is out of range or malformed: NaN, a wrong size, an unknown enumeration
    /// value, a bad mesh, a call out of order.
    InvalidValue = 3,
    /// The host's buffer is too small; the count or length needed was written where the
    /// function says.
    BufferTooSmall = 4,
    /// A file could not be read or is malformed (the message names it).
    File = 5,
    /// No Vulkan loader or no usable device.
    NoDevice = 6,
    /// The device lacks a feature or extension Kage needs.
    Unsupported = 7,
    /// A Vulkan call failed (other than out of memory or device loss).
    Vulkan = 8,
    /// The Vulkan device was lost; destroy everything made from the context.
    DeviceLost = 9,
    /// Host or device memory ran out.
    OutOfMemory = 10,
    /// The context was created with validation on, and the validation layer reported a
    /// warning or error during the call (the message holds the first ones).
    Validation = 11,
    /// Kage hit an internal error (a bug); the message holds the panic message.
    Panic = 12,
    /// Kage found an internal error (a bug) without panicking, such as a pass reading what no
    /// earlier pass wrote; the message names it.
    Internal = 13,
    /// The handle is in use by a call on another thread (calls on one handle must not overlap);
    /// nothing was done.
    Busy = 14,
    /// The host's progress callback returned false: the work stopped, and nothing it was to
    /// change was changed.
    Cancelled = 15,
}

/// A failure on its way to the host: the code and the message for `kage_last_error_message`.
#[derive(Debug)]
pub(crate) struct Failure {
    pub code: kage_result,
    pub message: String,
}

impl Failure {
    pub fn new(code: kage_result, message: impl Into<String>) -> Failure {
        Failure { code, message: message.into() }
    }

    pub fn invalid(message: impl Into<String>) -> Failure {
        Failure::new(kage_result::InvalidValue, message)
    }
}

impl From<Error> for Failure {
    fn from(error: Error) -> Failure {
        Failure { code: code_of(&error), message: error.to_string() }
    }
}

impl From<OutOfHostMemory> for Failure {
    fn from(error: OutOfHostMemory) -> Failure {
        Error::from(error).into()
    }
}

/// The one place engine errors become result codes.
fn code_of(error: &Error) -> kage_result {
    match error {
        Error::Loader(_) | Error::NoDevice(_) => kage_result::NoDevice,
        Error::Unsupported(_) => kage_result::Unsupported,
        Error::OutOfDeviceMemory { .. }
        | Error::OutOfHostMemory { .. }
        | Error::OutOfDeviceMemoryFor { .. }
        | Error::OutOfHostMemoryFor(_)
        | Error::Allocation { .. } => kage_result::OutOfMemory,
        Error::Scene(e) if e.out_of_memory() => kage_result::OutOfMemory,
        Error::DeviceLost { .. } => kage_result::DeviceLost,
        Error::Vulkan { .. } | Error::Timeout(_) => kage_result::Vulkan,
        // A scene error names a file when one was read; otherwise the host's data is at fault.
        Error::Scene(e) if e.file().is_some() => kage_result::File,
        // An image the host asked for in a format or at an exposure Kage does not write.
        Error::Image(e) if e.by_caller() => kage_result::InvalidValue,
        Error::Image(_) => kage_result::File,
        Error::Probes(crate::error::ProbeError::FitDiverged { .. }) | Error::Internal(_) => {
            kage_result::Internal
        }
        Error::Scene(_) | Error::Probes(_) | Error::InvalidArgument(_) => kage_result::InvalidValue,
        Error::Cancelled(_) => kage_result::Cancelled,
    }
}

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

fn set_last_error(message: &str) {
    // An interior NUL would cut the C string short: show it as a space instead. A name of any
    // length the host passed is quoted clipped.
    let message = crate::scene::clip_message(message).replace('\0', " ");
    LAST_ERROR.with(|last| *last.borrow_mut() = message);
}

/// Runs an export's body: its error becomes the code and the thread's last message, and a
/// panic is caught here, so that it never unwinds into the host.
pub(crate) fn boundary(body: impl FnOnce() -> Result<(), Failure>) -> kage_result {
    let failure = match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => return kage_result::Ok,
        Ok(Err(failure)) => failure,
        Err(payload) => {
            let text = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic without a message".into());
            Failure::new(kage_result::Panic, format!("internal error (please report): {text}"))
        }
    };
    set_last_error(&failure.message);
    failure.code
}

/// Copies the message of the last failed Kage call on this thread into `buffer`, as a
/// NUL-terminated UTF-8 string (empty if no call has failed yet; a successful call leaves it).
/// This call never changes the stored message.
///
/// `length`, when not NULL, receives the message's length in bytes without the NUL. When
/// `capacity` is too small for it and the NUL, as much as fits is written (NUL-terminated if
/// `capacity` > 0) and `KAGE_RESULT_BUFFER_TOO_SMALL` is returned. `buffer` may be NULL only
/// when `capacity` is 0 (to ask for the length).
///
/// # Safety
/// `buffer` must be NULL or point to `capacity` writable bytes; `length` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_last_error_message(
    buffer: *mut c_char,
    capacity: usize,
    length: *mut usize,
) -> kage_result {
    // Not through `boundary`: a failure here must not replace the message being asked for.
    let copy = || {
        LAST_ERROR.with(|last| {
            // SAFETY: the caller's promises about buffer and length.
            match unsafe { args::copy_text(&last.borrow(), buffer, capacity, length, "buffer") } {
                Ok(()) => kage_result::Ok,
                Err(failure) => failure.code,
            }
        })
    };
    catch_unwind(copy).unwrap_or(kage_result::Panic)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn last_message() -> String {
        let mut buffer = [0 as c_char; 256];
        let mut length = 0;
        // SAFETY: a local buffer of the stated size and a local length.
        let code = unsafe { kage_last_error_message(buffer.as_mut_ptr(), buffer.len(), &mut length) };
        assert_eq!(code, kage_result::Ok);
        let bytes: Vec<u8> = buffer[..length].iter().map(|c| *c as u8).collect();
        String::from_utf8(bytes).unwrap()
    }

    #[test]
    fn a_panic_becomes_a_code_and_a_message() {
        let code = boundary(|| panic!("boom {}", 7));
        assert_eq!(code, kage_result::Panic);
        assert!(last_message().contains("boom 7"));
    }

    #[test]
    fn errors_map_to_their_class() {
        let code = boundary(|| Err(Error::OutOfHostMemory { call: "vkX" }.into()));
        assert_eq!(code, kage_result::OutOfMemory);
        assert_eq!(last_message(), "out of host memory in vkX");
        assert_eq!(boundary(|| Ok(())), kage_result::Ok);
        // Success leaves the last failure's message in place.
        assert_eq!(last_message(), "out of host memory in vkX");
        // Device loss and one resource too large keep their own codes.
        assert_eq!(
            boundary(|| Err(Error::DeviceLost { call: "vkQueueSubmit" }.into())),
            kage_result::DeviceLost
        );
        let too_large =
            Error::OutOfDeviceMemoryFor { name: "mask".into(), bytes: 1 << 32, reason: "limit".into() };
        assert_eq!(boundary(|| Err(too_large.into())), kage_result::OutOfMemory);
        assert_eq!(last_message(), "out of device memory for mask (4294967296 bytes): limit");
        // Kage's own bugs never blame the caller.
        assert_eq!(boundary(|| Err(Error::Internal("pass order".into()).into())), kage_result::Internal);
        // Host memory that ran out, alone or on the way to a mesh, is not the data's fault.
        let host = OutOfHostMemory { what: "positions".into(), bytes: 12 };
        assert_eq!(boundary(|| Err(host.clone().into())), kage_result::OutOfMemory);
        let in_mesh = crate::scene::SceneError::from(host).within("mesh 0");
        assert_eq!(boundary(|| Err(Error::from(in_mesh).into())), kage_result::OutOfMemory);
        assert_eq!(last_message(), "mesh 0: out of host memory for positions (12 bytes)");
        // An image format Kage does not write is the caller's value, not a file's fault.
        let jpg = crate::imageio::ImageIoError::UnsupportedExtension { path: "a/b.jpg".into() };
        assert_eq!(boundary(|| Err(Error::from(jpg).into())), kage_result::InvalidValue);
        assert!(last_message().contains("\".jpg\""), "{}", last_message());
    }

    #[test]
    fn a_short_buffer_gets_a_truncated_terminated_message() {
        boundary(|| Err(Failure::invalid("0123456789")));
        let mut buffer = [1 as c_char; 4];
        let mut length = 0;
        // SAFETY: a local buffer of the stated size and a local length.
        let code = unsafe { kage_last_error_message(buffer.as_mut_ptr(), buffer.len(), &mut length) };
        assert_eq!((code, length), (kage_result::BufferTooSmall, 10));
        assert_eq!(buffer.map(|c| c as u8), *b"012\0");
    }
}
