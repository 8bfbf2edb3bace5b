//! Buffer capacity, shared by the stages that size their buffers ahead of the samples that fill
//! them (so that those samples allocate nothing).

/// Grows `v`'s capacity to at least `n` (no allocation when it has that room already).
#[inline]
pub(crate) fn room<T>(v: &mut Vec<T>, n: usize) {
    if v.capacity() < n {
        v.reserve(n - v.len());
    }
}
