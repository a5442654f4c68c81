//! The live handles. A handle is not its object's address but a slot number and the slot's
//! generation, which rises each time an object in the slot is destroyed: a destroyed handle
//! never becomes valid again, even when a later object reuses its memory or its slot. A handle
//! is busy while a call uses it; a call from another thread on a busy handle (or a destroy of
//! it) gets `KAGE_RESULT_BUSY` instead of racing inside the driver.
use super::result::{kage_result, Failure};
use std::any::TypeId;
use std::marker::PhantomData;
use std::ops::{Deref, DerefMut};
use std::sync::{Mutex, MutexGuard};

struct Slot {
    /// Part of every handle to this slot; 0 is never handed out.
    generation: u32,
    kind: TypeId,
    /// The object's address (from `Box::into_raw`), kept inverted: a leak checker (valgrind)
    /// would take it for a pointer and call every handle the host forgets to destroy "still
    /// reachable"; inverted, it reports it as lost. 0: the slot is free.
    object: usize,
    busy: bool,
}

struct Table {
    slots: Vec<Slot>,
    /// Free slots whose generation can still rise.
    free: Vec<usize>,
}

static TABLE: Mutex<Table> = Mutex::new(Table { slots: Vec::new(), free: Vec::new() });

fn table() -> MutexGuard<'static, Table> {
    // Every change to the table is complete before anything that can panic, so a poisoned
    // lock still guards a consistent table.
    TABLE.lock().unwrap_or_else(|e| e.into_inner())
}

// Handles carry a 32-bit generation above a 32-bit slot number.
const _: () = assert!(usize::BITS >= 64, "Kage's C ABI needs 64-bit pointers");

/// The handle of slot `index` at `generation`: the index + 1 in the low 32 bits (never NULL),
/// the generation above.
fn handle_of<T>(index: usize, generation: u32) -> *mut T {
    (((generation as usize) << 32) | (index + 1)) as *mut T
}

/// Gives `object` to the host as a handle.
pub(crate) fn register<T: 'static>(object: T) -> *mut T {
    let object = !(Box::into_raw(Box::new(object)) as usize);
    let mut table = table();
    let index = match table.free.pop() {
        Some(index) => index,
        None => {
            table.slots.push(Slot { generation: 0, kind: TypeId::of::<T>(), object: 0, busy: false });
            table.slots.len() - 1
        }
    };
    let slot = &mut table.slots[index];
    slot.generation += 1;
    (slot.kind, slot.object) = (TypeId::of::<T>(), object);
    handle_of(index, slot.generation)
}

/// The slot a live handle of kind `T` names.
fn find<T: 'static>(table: &Table, handle: *const T, name: &str) -> Result<usize, Failure> {
    if handle.is_null() {
        return Err(Failure::new(kage_result::NullArgument, format!("{name} is NULL")));
    }
    let (low, generation) = (handle as usize & 0xffff_ffff, (handle as usize >> 32) as u32);
    let slot = low.checked_sub(1).and_then(|index| Some((index, table.slots.get(index)?)));
    match slot {
        Some((index, slot))
            if slot.generation == generation && slot.object != 0 && slot.kind == TypeId::of::<T>() =>
        {
            Ok(index)
        }
        _ => Err(Failure::new(
            kage_result::InvalidHandle,
            format!("{name} is not a live {} (destroyed already, or never created)", kind::<T>()),
        )),
    }
}

fn busy<T>(name: &str) -> Failure {
    Failure::new(
        kage_result::Busy,
        format!("{name}: this {} is in use by a call on another thread", kind::<T>()),
    )
}

/// The handle's type name as C sees it (`kage_scene`).
fn kind<T>() -> &'static str {
    std::any::type_name::<T>().rsplit("::").next().unwrap_or("handle")
}

/// The object behind a live handle, marked busy until the guard is dropped.
pub(crate) struct Guard<'a, T> {
    index: usize,
    object: *mut T,
    lifetime: PhantomData<&'a mut T>,
}

impl<T> Deref for Guard<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        // SAFETY: the slot is busy while the guard lives, so no other call reaches the object
        // and no destroy frees it.
        unsafe { &*self.object }
    }
}

impl<T> DerefMut for Guard<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        // SAFETY: as in `deref`; the busy slot makes this the only reference.
        unsafe { &mut *self.object }
    }
}

impl<T> Drop for Guard<'_, T> {
    fn drop(&mut self) {
        table().slots[self.index].busy = false;
    }
}

/// The object behind a live handle of kind `T`, for the length of a call.
pub(crate) fn get<'a, T: 'static>(handle: *const T, name: &str) -> Result<Guard<'a, T>, Failure> {
    let mut table = table();
    let index = find(&table, handle, name)?;
    let slot = &mut table.slots[index];
    if slot.busy {
        return Err(busy::<T>(name));
    }
    slot.busy = true;
    Ok(Guard { index, object: !slot.object as *mut T, lifetime: PhantomData })
}

/// Takes a handle back from the host and drops its object. NULL is accepted and does nothing,
/// like `free(NULL)`.
pub(crate) fn destroy<T: 'static>(handle: *mut T, name: &str) -> Result<(), Failure> {
    if handle.is_null() {
        return Ok(());
    }
    let object = {
        let mut table = table();
        let index = find(&table, handle, name)?;
        let slot = &mut table.slots[index];
        if slot.busy {
            return Err(busy::<T>(name));
        }
        let object = std::mem::take(&mut slot.object);
        // A slot whose generation cannot rise again is retired, never reused.
        if slot.generation < u32::MAX {
            table.free.push(index);
        }
        object
    };
    // SAFETY: it came from Box::into_raw in `register`, and clearing the slot under the lock
    // made this the only place that frees it.
    drop(unsafe { Box::from_raw(!object as *mut T) });
    Ok(())
}
