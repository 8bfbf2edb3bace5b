//! DESIGN §1 / issue: once warmed up, `World::step` performs no heap allocation. A counting global
//! allocator proves it for the built-in scenes.

use haptic2d::scene::builtin;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCS: AtomicU64 = AtomicU64::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations during `measure` samples of `scene` after `warm` samples of warm-up.
fn allocations(scene: &str, warm: usize, measure: usize) -> u64 {
    let mut w = builtin(scene, None).unwrap().unwrap().world;
    for _ in 0..warm {
        w.step();
    }
    ALLOCS.store(0, Ordering::SeqCst);
    COUNTING.store(true, Ordering::SeqCst);
    for _ in 0..measure {
        w.step();
    }
    COUNTING.store(false, Ordering::SeqCst);
    ALLOCS.load(Ordering::SeqCst)
}

#[test]
fn world_step_does_not_allocate_once_warm() {
    // One test function: the counter is global, so the scenes run one after the other.
    // box-in-walls: the window covers the later bounces, releases and re-creations of contacts.
    assert_eq!(allocations("box-in-walls", 50, 2500), 0, "box-in-walls");
    assert_eq!(
        allocations("box-in-walls-tilt", 50, 2500),
        0,
        "box-in-walls-tilt"
    );
    assert_eq!(allocations("peg-in-hole", 50, 2500), 0, "peg-in-hole");
    assert_eq!(allocations("pile:25", 200, 500), 0, "pile:25");
}
