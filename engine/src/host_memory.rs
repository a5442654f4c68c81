//! Host memory whose amount a caller chose (a mesh's vertices, a map's pixels, a frame read
//! back): reserved fallibly, so that too much is an error the caller can handle. An infallible
//! allocation that fails aborts the whole process, a C host included.

/// The memory for `what` could not be had: the machine's limit, not a fault of the data.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("out of host memory for {what} ({bytes} bytes)")]
pub struct OutOfHostMemory {
    pub what: String,
    pub bytes: u64,
}

/// An empty vector with room for `n` items.
pub fn with_room<T>(n: usize, what: &str) -> Result<Vec<T>, OutOfHostMemory> {
    let mut items = Vec::new();
    items.try_reserve_exact(n).map_err(|_| OutOfHostMemory {
        what: what.to_owned(),
        bytes: (n as u64).saturating_mul(size_of::<T>() as u64),
    })?;
    Ok(items)
}

/// `n` copies of `value`.
pub fn filled<T: Clone>(value: T, n: usize, what: &str) -> Result<Vec<T>, OutOfHostMemory> {
    let mut items = with_room(n, what)?;
    items.resize(n, value);
    Ok(items)
}

/// The items of an iterator that knows its length, in memory reserved for them first.
pub fn collect<T>(items: impl ExactSizeIterator<Item = T>, what: &str) -> Result<Vec<T>, OutOfHostMemory> {
    let mut collected = with_room(items.len(), what)?;
    collected.extend(items);
    Ok(collected)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_cannot_be_had_is_an_error_naming_it() {
        // 2^62 eight-byte items: more than any address space, refused without an abort.
        let error = with_room::<u64>(1 << 62, "a test").unwrap_err();
        assert_eq!(error.to_string(), format!("out of host memory for a test ({} bytes)", u64::MAX));
        assert_eq!(filled(7u8, 3, "three").unwrap(), vec![7, 7, 7]);
        assert_eq!(collect([1, 2].iter().map(|x| x * 2), "doubled").unwrap(), vec![2, 4]);
    }
}
