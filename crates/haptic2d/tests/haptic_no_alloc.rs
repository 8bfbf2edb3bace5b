//! DESIGN §1: once warm, `HapticSystem::tick` performs no heap allocation (no locks, no I/O either:
//! it only computes). A counting global allocator proves it over long windows of the box-in-walls and
//! peg-in-hole loops, with contacts coming and going, both controllers and the passivity controller.

use haptic2d::control::passivity::PlanarPassivity;
use haptic2d::device::{HandModel, SimDevice};
use haptic2d::haptic::{ControllerKind, HapticConfig, HapticSystem};
use haptic2d::scene::builtin;
#[path = "support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations;

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
        let before = allocations();
        let out = sys.tick(&q);
        if count {
            let a = allocations() - before;
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
