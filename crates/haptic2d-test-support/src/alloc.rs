//! A global allocator that counts the allocations of the current thread and the largest single
//! request, for the no-allocation tests (the hot path does not allocate) and the fuzz tests'
//! allocation bound. Install it in a test binary with
//!
//! ```ignore
//! #[global_allocator]
//! static GLOBAL: haptic2d_test_support::alloc::Counting = haptic2d_test_support::alloc::Counting;
//! ```
//!
//! The counters are per thread: other threads (an emulator, a server) allocate freely.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting allocations and reallocations of the current thread and
/// recording the largest single request (bytes).
pub struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note(size: usize) {
    // `try_with`: a thread being torn down may still allocate; its counters are gone.
    let _ = ALLOCATIONS.try_with(|a| a.set(a.get() + 1));
    let _ = LARGEST.try_with(|m| m.set(m.get().max(size)));
}

// SAFETY: every call is forwarded to `System` unchanged; the bookkeeping touches const-initialised
// thread-local `Cell`s only (no allocation, no destructor).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Allocations (and reallocations) made by the current thread so far. Counts only where
/// [`Counting`] is the binary's global allocator.
pub fn allocations() -> u64 {
    ALLOCATIONS.try_with(|a| a.get()).unwrap_or(0)
}

/// The largest single request (bytes) of the current thread since the last [`reset_largest`].
pub fn largest() -> usize {
    LARGEST.try_with(|m| m.get()).unwrap_or(0)
}

/// Forgets the current thread's largest request (the next [`largest`] covers what follows).
pub fn reset_largest() {
    let _ = LARGEST.try_with(|m| m.set(0));
}

/// Installs [`Counting`] as the global allocator of the test binary that invokes it (once, at
/// the crate root of the binary, or in a `#[cfg(test)]` module of a library's unit tests).
#[macro_export]
macro_rules! install_counting_allocator {
    () => {
        #[global_allocator]
        static COUNTING_ALLOCATOR: $crate::alloc::Counting = $crate::alloc::Counting;
    };
}
