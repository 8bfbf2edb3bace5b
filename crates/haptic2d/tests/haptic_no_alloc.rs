//! DESIGN §1: once warm, `HapticSystem::tick` performs no heap allocation (no locks, no I/O either:
//! it only computes). A counting global allocator proves it over long windows of the box-in-walls and
//! peg-in-hole loops, with contacts coming and going, both controllers and the passivity controller.

use haptic2d::control::passivity::PlanarPassivity;
use haptic2d::device::{HandModel, SimDevice};
use haptic2d::haptic::{ControllerKind, HapticConfig, HapticSystem};
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

/// Allocations inside `tick` during `measure` ticks after `warm` ticks. The plant (a test fixture, not
/// part of the tick) steps outside the counted region.
fn tick_allocations(
    scene: &str,
    config: &HapticConfig,
    hand: HandModel,
    warm: usize,
    measure: usize,
) -> u64 {
    let world = builtin(scene, Some(1000.0)).unwrap().unwrap().world;
    let mut sys = HapticSystem::new(world, config).unwrap();
    let mut plant = SimDevice::new(&config.device, sys.device_start()).unwrap();
    let mut total = 0;
    for k in 0..warm + measure {
        let q = plant.encoders().unwrap();
        let count = k >= warm;
        if count {
            ALLOCS.store(0, Ordering::SeqCst);
            COUNTING.store(true, Ordering::SeqCst);
        }
        let out = sys.tick(&q);
        if count {
            COUNTING.store(false, Ordering::SeqCst);
            let a = ALLOCS.load(Ordering::SeqCst);
            if a > 0 {
                eprintln!(
                    "{scene}: {a} allocations in tick {k} ({} contacts after it)",
                    out.record.contacts
                );
            }
            total += a;
        }
        assert!(!out.tripped, "{scene}: {:?}", sys.safety_trip());
        plant.step(&out.torques, &hand, sys.dt()).unwrap();
    }
    total
}

#[test]
fn tick_does_not_allocate_once_warm() {
    // The hand pushes the box into the left wall, it bounces and comes to rest: contacts appear,
    // collide, go continuous, release and reappear inside the window (from tick 50 on).
    let push = HandModel::Constant {
        wrench: [-2.0, 0.0, 0.0],
    };
    let four = HapticConfig::default();
    assert_eq!(
        tick_allocations("box-in-walls", &four, push, 50, 3000),
        0,
        "box-in-walls, four-channel"
    );
    let coupling_pc = HapticConfig {
        controller: ControllerKind::from_name("coupling").unwrap(),
        passivity: Some(PlanarPassivity::default()),
        ..HapticConfig::default()
    };
    assert_eq!(
        tick_allocations("box-in-walls", &coupling_pc, push, 50, 3000),
        0,
        "box-in-walls, coupling + PC"
    );
    let sine = HandModel::Sinusoid {
        direction: [1.0, 0.0, 0.0],
        peak: 2.2,
        frequency: 1.0,
    };
    assert_eq!(
        tick_allocations("peg-in-hole", &four, sine, 800, 1400),
        0,
        "peg-in-hole"
    );
}
