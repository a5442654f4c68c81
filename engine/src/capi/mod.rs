//! The C ABI: what `engine/include/kage.h` declares (generated from this folder by cbindgen;
//! `cargo test -p kage-tests --test c_header` checks it, `KAGE_BLESS=1` rewrites it).
//!
//! Rules every function follows, so that a host cannot crash Kage from the outside:
//! - It returns a [`kage_result`]; on failure [`kage_last_error_message`] says why.
//! - It runs behind a panic boundary (`result::boundary`): a panic becomes
//!   `KAGE_RESULT_PANIC`, never an unwind into C.
//! - Handles are opaque values (a slot and its generation, not addresses) checked against the
//!   table of live handles (`handles.rs`) before use: NULL is `KAGE_RESULT_NULL_ARGUMENT`; a
//!   destroyed, foreign or wrong-kind handle is `KAGE_RESULT_INVALID_HANDLE`, for good, even
//!   after later objects are made.
//! - Enumerations arrive as `uint32_t`, so that an out-of-range value from C is
//!   `KAGE_RESULT_INVALID_VALUE` rather than an invalid Rust enum.
//! - Counts are checked against the engine's limits before anything is allocated for them, and
//!   what the host's data is copied into is allocated fallibly ([`crate::host_memory`]): too
//!   much is `KAGE_RESULT_OUT_OF_MEMORY`, never an abort of the host.
//! - A call that fills the host's array answers a count query (NULL, capacity 0) with OK
//!   (`args::count_query`).
//!
//! Threading: any function may be called from any thread. A call on a handle that a call on
//! another thread is using returns `KAGE_RESULT_BUSY` and does nothing; calls on different
//! handles run at the same time (a context's queue is locked inside, each renderer records its
//! own command buffers). The last error message is per thread.
#![allow(non_camel_case_types)]

/// The version of the C ABI kage.h declares. It rises with every incompatible change that no
/// `size` field catches (a field of a small struct added, removed or moved, a function's
/// parameters, an enumeration's values), and libkage.so carries it in its SONAME
/// (`libkage.so.1`). A host checks at start-up that `kage_abi_version()` equals the
/// `KAGE_ABI_VERSION` it was compiled with; beyond that, every top-level desc struct carries its
/// `size`, which each call checks: one that grew (fields appended) refuses a host compiled
/// against the older kage.h with `KAGE_RESULT_INVALID_VALUE` naming it.
#[repr(u32)]
pub enum kage_abi {
    Version = 1,
}

/// The C ABI version of this library: `KAGE_ABI_VERSION` of the kage.h it was built with.
#[no_mangle]
pub extern "C" fn kage_abi_version() -> u32 {
    kage_abi::Version as u32
}

/// This library's version, e.g. "0.1.0": a NUL-terminated string that lives as long as the
/// library.
#[no_mangle]
pub extern "C" fn kage_version() -> *const std::ffi::c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

mod args;
pub mod context;
mod handles;
pub mod renderer;
pub mod result;
pub mod scene;
pub mod technique;

pub use result::{kage_last_error_message, kage_result};
