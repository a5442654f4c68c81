//! Reading the host's pointer arguments: NULL becomes `KAGE_RESULT_NULL_ARGUMENT` and a
//! malformed value `KAGE_RESULT_INVALID_VALUE`, each naming the argument.
use super::result::{kage_result, Failure};
use std::ffi::{c_char, CStr};

fn null(name: &str) -> Failure {
    Failure::new(kage_result::NullArgument, format!("{name} is NULL"))
}

/// The value behind a pointer to one `T`.
///
/// # Safety
/// `ptr` must be NULL or valid for reads of a `T` for `'a`.
pub(crate) unsafe fn value<'a, T>(ptr: *const T, name: &str) -> Result<&'a T, Failure> {
    // SAFETY: the caller promises NULL or a valid `T`.
    unsafe { ptr.as_ref() }.ok_or_else(|| null(name))
}

/// A desc struct the host filled, whose first field is its `size` (see [`check_size`]).
///
/// # Safety
/// `ptr` must be NULL or valid for reads of the host's version of `T`, whose first field is
/// its size as a `u32`.
pub(crate) unsafe fn sized<'a, T>(ptr: *const T, name: &str) -> Result<&'a T, Failure> {
    if ptr.is_null() {
        return Err(null(name));
    }
    // SAFETY: every version of the struct starts with its u32 size, so this reads within it.
    check_size::<T>(unsafe { ptr.cast::<u32>().read_unaligned() }, name)?;
    // SAFETY: the host's struct has this library's size, so it is this library's `T`.
    Ok(unsafe { &*ptr })
}

/// Checks the `size` field of a desc struct against this library's `sizeof(T)`.
pub(crate) fn check_size<T>(size: u32, name: &str) -> Result<(), Failure> {
    let own = size_of::<T>();
    if size as usize != own {
        let kind = std::any::type_name::<T>().rsplit("::").next().unwrap_or("desc");
        return Err(Failure::invalid(format!(
            "{name}.size is {size}, but this library's {kind} is {own} bytes: the host was compiled \
             against another version of kage.h (this library has ABI version {})",
            super::kage_abi::Version as u32
        )));
    }
    Ok(())
}

/// Where to write a result.
///
/// # Safety
/// `ptr` must be NULL or valid for writes of a `T` for `'a`.
pub(crate) unsafe fn out<'a, T>(ptr: *mut T, name: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: the caller promises NULL or a writable `T`.
    unsafe { ptr.as_mut() }.ok_or_else(|| null(name))
}

/// Where to write a result struct whose first field is its `size`, which the host set (see
/// [`check_size`]).
///
/// # Safety
/// `ptr` must be NULL or valid for reads and writes of the host's version of `T`, whose first
/// field is its size as a `u32`.
pub(crate) unsafe fn sized_out<'a, T>(ptr: *mut T, name: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: the caller's promise: `sized` reads only the size before checking it.
    unsafe { sized(ptr.cast_const(), name) }?;
    // SAFETY: the host's struct has this library's size, so it is this library's `T`.
    unsafe { out(ptr, name) }
}

/// Where to write a new handle; set to NULL at once, so that the host finds NULL there after
/// any failure.
///
/// # Safety
/// `ptr` must be NULL or valid for writes of a pointer for `'a`.
pub(crate) unsafe fn handle_out<'a, T>(ptr: *mut *mut T, name: &str) -> Result<&'a mut *mut T, Failure> {
    // SAFETY: the caller's promise.
    let out = unsafe { out(ptr, name) }?;
    *out = std::ptr::null_mut();
    Ok(out)
}

/// `count` values at `ptr`; NULL is allowed when `count` is 0.
///
/// # Safety
/// `ptr` must be NULL or valid for reads of `count` `T`s for `'a`.
pub(crate) unsafe fn slice<'a, T>(ptr: *const T, count: usize, name: &str) -> Result<&'a [T], Failure> {
    if count == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(null(name));
    }
    if count.checked_mul(size_of::<T>()).is_none_or(|bytes| bytes > isize::MAX as usize) {
        return Err(Failure::invalid(format!("{name}: {count} elements do not fit in memory")));
    }
    // SAFETY: non-NULL, the size fits an allocation, and the caller promises `count` readable
    // values.
    Ok(unsafe { std::slice::from_raw_parts(ptr, count) })
}

/// `groups` groups of `N` values at `ptr` (e.g. 3 floats per vertex).
///
/// # Safety
/// As for [`slice`], with `groups × N` values.
pub(crate) unsafe fn chunks<'a, const N: usize>(
    ptr: *const f32,
    groups: usize,
    name: &str,
) -> Result<&'a [[f32; N]], Failure> {
    let count = groups
        .checked_mul(N)
        .ok_or_else(|| Failure::invalid(format!("{name}: {groups} × {N} values overflow")))?;
    // SAFETY: the caller promises `groups × N` readable floats.
    let flat = unsafe { slice(ptr, count, name) }?;
    // SAFETY: [f32; N] has the size and alignment of N consecutive f32s.
    Ok(unsafe { std::slice::from_raw_parts(flat.as_ptr().cast(), groups) })
}

/// A NUL-terminated UTF-8 string.
///
/// # Safety
/// `ptr` must be NULL or a NUL-terminated string readable for `'a`.
pub(crate) unsafe fn text<'a>(ptr: *const c_char, name: &str) -> Result<&'a str, Failure> {
    if ptr.is_null() {
        return Err(null(name));
    }
    // SAFETY: non-NULL, and the caller promises a NUL-terminated string.
    let c = unsafe { CStr::from_ptr(ptr) };
    c.to_str().map_err(|_| Failure::invalid(format!("{name} is not UTF-8")))
}

/// An enumeration passed as `uint32_t`, read by the enum's `from_repr`.
pub(crate) fn enumeration<T>(value: u32, name: &str, from_repr: fn(u32) -> Option<T>) -> Result<T, Failure> {
    from_repr(value)
        .ok_or_else(|| Failure::invalid(format!("{name} {value} is not one of the values kage.h defines")))
}

/// Whether a call that fills the host's array (room for `capacity` elements at `buffer`) and
/// reports the count it needs was asked for that count alone: NULL with `capacity` 0, which
/// returns `KAGE_RESULT_OK`. NULL with room is `KAGE_RESULT_NULL_ARGUMENT`. (The rule is
/// stated once for the host, at the top of kage.h.)
pub(crate) fn count_query<T>(buffer: *const T, capacity: usize, name: &str) -> Result<bool, Failure> {
    match (buffer.is_null(), capacity) {
        (true, 0) => Ok(true),
        (true, _) => Err(null(name)),
        (false, _) => Ok(false),
    }
}

/// `KAGE_RESULT_BUFFER_TOO_SMALL` where the host's array of `capacity` elements was short of
/// the `needed` ones (after as many as fit were written).
pub(crate) fn room_for(
    capacity: usize,
    needed: usize,
    short: impl FnOnce() -> String,
) -> Result<(), Failure> {
    match capacity < needed {
        true => Err(Failure::new(kage_result::BufferTooSmall, short())),
        false => Ok(()),
    }
}

/// Copies `text` into the host's `buffer` of `capacity` bytes as a NUL-terminated string and
/// its length in bytes (without the NUL) into `*length` when that is not NULL. A buffer too
/// small gets as much as fits, still terminated, and `KAGE_RESULT_BUFFER_TOO_SMALL`; NULL with
/// `capacity` 0 asks for the length alone ([`count_query`]).
///
/// # Safety
/// `buffer` must be NULL or `capacity` writable bytes; `length` NULL or writable.
pub(crate) unsafe fn copy_text(
    text: &str,
    buffer: *mut c_char,
    capacity: usize,
    length: *mut usize,
    name: &str,
) -> Result<(), Failure> {
    // SAFETY: the caller promises NULL or writable.
    if let Some(length) = unsafe { length.as_mut() } {
        *length = text.len();
    }
    if count_query(buffer, capacity, name)? {
        return Ok(());
    }
    if capacity > 0 {
        let n = text.len().min(capacity - 1);
        // SAFETY: the caller promises `capacity` writable bytes; n + 1 <= capacity.
        let out = unsafe { std::slice::from_raw_parts_mut(buffer.cast::<u8>(), n + 1) };
        out[..n].copy_from_slice(&text.as_bytes()[..n]);
        out[n] = 0;
    }
    room_for(capacity, text.len() + 1, || {
        format!("{name}: {capacity} bytes do not hold {} bytes and the NUL", text.len())
    })
}
