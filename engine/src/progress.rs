//! How long work reports how far it has come, and how its caller stops it.

/// Called with (units done, units in all) as long work goes on (a PRT precomputation: vertices;
/// a probe capture: probes); returns whether to go on. `false` stops the work with
/// [`crate::error::Error::Cancelled`]; the call with done = total comes when the work is done, and
/// its answer changes nothing.
pub type Progress<'a> = dyn FnMut(usize, usize) -> bool + 'a;

/// A report that never stops the work.
pub fn silent(_done: usize, _total: usize) -> bool {
    true
}
