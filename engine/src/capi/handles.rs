//! The live handles: every handle given to the host is registered here until it is destroyed,
//! so that a destroyed, foreign or wrong-kind pointer is caught before it is dereferenced.
use super::result::{kage_result, Failure};
use std::any::TypeId;
use std::collections::HashSet;
use std::sync::{Mutex, MutexGuard};

/// (kind, address) of each live handle ([`key`]). Addresses of live boxes are unique, so the
/// pair names one object.
static LIVE: Mutex<Option<HashSet<(TypeId, usize)>>> = Mutex::new(None);

fn live() -> MutexGuard<'static, Option<HashSet<(TypeId, usize)>>> {
    // A panic while the lock was held cannot leave the set half-changed (insert and remove
    // are single calls), so a poisoned lock is still good.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// The address is kept inverted: a leak checker (valgrind) would take it for a pointer and call
/// every handle the host forgets to destroy "still reachable"; inverted, it reports it as lost.
fn key<T: 'static>(handle: *const T) -> (TypeId, usize) {
    (TypeId::of::<T>(), !(handle as usize))
}

/// Gives `object` to the host as a handle.
pub(crate) fn register<T: 'static>(object: T) -> *mut T {
    let handle = Box::into_raw(Box::new(object));
    live().get_or_insert_with(HashSet::new).insert(key(handle));
    handle
}

fn check<T: 'static>(handle: *const T, name: &str) -> Result<(), Failure> {
    if handle.is_null() {
        return Err(Failure::new(kage_result::NullArgument, format!("{name} is NULL")));
    }
    if !live().as_ref().is_some_and(|set| set.contains(&key(handle))) {
        return Err(Failure::new(
            kage_result::InvalidHandle,
            format!("{name} is not a live {} (destroyed already, or never created)", kind::<T>()),
        ));
    }
    Ok(())
}

/// The handle's type name as C sees it (`kage_scene`).
fn kind<T>() -> &'static str {
    std::any::type_name::<T>().rsplit("::").next().unwrap_or("handle")
}

/// The object behind a live handle.
///
/// # Safety
/// The host must not destroy the handle, or use it from another thread, while the reference
/// lives (the threading rules of the C ABI).
pub(crate) unsafe fn get<'a, T: 'static>(handle: *const T, name: &str) -> Result<&'a T, Failure> {
    check(handle, name)?;
    // SAFETY: registered, so it came from Box::into_raw and is not freed yet; the caller
    // promises no concurrent destroy.
    Ok(unsafe { &*handle })
}

/// As [`get`], for changing the object.
///
/// # Safety
/// As for [`get`]; also no other reference to the object may be alive.
pub(crate) unsafe fn get_mut<'a, T: 'static>(handle: *mut T, name: &str) -> Result<&'a mut T, Failure> {
    check(handle, name)?;
    // SAFETY: as in `get`; the caller promises exclusive use.
    Ok(unsafe { &mut *handle })
}

/// Takes a handle back from the host and drops its object. NULL is accepted and does nothing,
/// like `free(NULL)`.
pub(crate) fn destroy<T: 'static>(handle: *mut T, name: &str) -> Result<(), Failure> {
    if handle.is_null() {
        return Ok(());
    }
    // Removed under the lock, so that of two racing destroys only one frees the object.
    let removed = live().as_mut().is_some_and(|set| set.remove(&key(handle)));
    if !removed {
        return check(handle, name);
    }
    // SAFETY: it was registered, so it came from Box::into_raw, and removing it from the set
    // made this the only place that frees it.
    drop(unsafe { Box::from_raw(handle) });
    Ok(())
}
