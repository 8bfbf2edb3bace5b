//! DESIGN §1: once warm, `HapticSystem::tick` performs no heap allocation (no locks, no I/O either:
//! it only computes). A counting global allocator proves it over long windows of the box-in-walls and
//! peg-in-hole loops, with contacts coming and going, both controllers and the passivity controller.

use crate::counting_alloc;
use counting_alloc::allocations;
use haptic2d::control::passivity::PlanarPassivity;
use haptic2d::device::{HandModel, SimDevice};
use haptic2d::haptic::{ControllerKind, HapticConfig, HapticSystem, SafetyConfig};
use haptic2d::scene::builtin;

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
    // The hands here push from the first tick; with the start-up ramp the handle would give way and
    // reach the workspace bound (a safety stop, by design). The ramp's own path is counted in
    // `safety_paths_of_the_tick_do_not_allocate`.
    // The coupling with the passivity controller under this zero-impedance push chatters: from
    // t ≈ 0.2 s the PC's y channel sits at its α cap and the torques flip between ±τ_max at about
    // 120 Hz, which the limit-cycle check stops at 0.4 s (issue 34; its own tests are in
    // `safety_gate.rs` and the lib). Here the windows are only counted for allocations: it is off.
    let safety = SafetyConfig {
        ramp_time: 0.0,
        limit_cycle_window: 0.0,
        ..SafetyConfig::default()
    };
    let mut sys = HapticSystem::with_safety(world, config, safety).unwrap();
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

/// The safety paths of the tick (the start-up ramp, late ticks over the measured interval, the
/// workspace wall, the final clamp, the passivity controller's booking) allocate nothing either.
#[test]
fn safety_paths_of_the_tick_do_not_allocate() {
    let world = builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world;
    let config = HapticConfig {
        passivity: Some(PlanarPassivity::default()),
        keep_slave_loads: true,
        ..HapticConfig::default()
    };
    let mut sys = HapticSystem::new(world, &config).unwrap();
    let p = config.device;
    let c = sys.device_start();
    let edge = p.workspace_center_x + p.workspace_half_width;
    // Warm up inside, then walk out past the edge (wall active) with every third tick 3 periods
    // late, and a torque request just above τ_max (clamped) now and then.
    let q0 = sys.device().kin.ik(&c).unwrap();
    for _ in 0..50 {
        sys.tick(&q0);
    }
    let mut total = 0;
    let mut x = c[0];
    for k in 0..1500 {
        x = (x + 0.00003).min(edge + 0.005);
        let q = sys.device().kin.ik(&[x, c[1], c[2]]).unwrap();
        if k % 97 == 0 {
            sys.inject_torque_fault(1, 0.51);
        }
        let before = allocations();
        let out = if k % 3 == 0 {
            sys.tick_elapsed(&q, 0.003)
        } else {
            sys.tick(&q)
        };
        total += allocations() - before;
        assert!(!out.tripped, "tick {k}: {:?}", sys.safety_trip());
    }
    assert!(sys.last_record().x_m[0] > edge, "the wall was reached");
    assert_eq!(total, 0);
}

/// Issue 34 build item 5: the safety written once for every device allocates nothing in the tick,
/// on the path that trips either: the plausibility check (1e30 rad), the stall check with the
/// device's share (`tick_timed`, `check_stall`), and the limit-cycle monitor through a trip.
#[test]
fn the_shared_trips_do_not_allocate() {
    use haptic2d::haptic::{LimitCycleMonitor, SafetyReason};
    let world = builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world;
    let config = HapticConfig::default();
    let fresh = HapticSystem::new(world, &config).unwrap();
    let q0 = fresh.device().kin.ik(&fresh.device_start()).unwrap();
    let mut total = 0;
    // Plausibility.
    let mut sys = fresh.clone();
    for _ in 0..50 {
        sys.tick(&q0);
    }
    let before = allocations();
    let out = sys.tick(&[q0[0], 1e30, q0[2], q0[3]]);
    total += allocations() - before;
    assert!(out.tripped);
    // Stall, with and without the device's share.
    let mut sys = fresh.clone();
    for _ in 0..50 {
        sys.tick(&q0);
    }
    let before = allocations();
    let out = sys.tick_timed(&q0, 0.05, 0.01);
    let stalled = sys.check_stall(0.05, f64::NAN);
    total += allocations() - before;
    assert!(out.tripped && stalled);
    // The limit-cycle monitor through a trip.
    let mut m = LimitCycleMonitor::new(&SafetyConfig::default(), 1e-3);
    let before = allocations();
    let mut tripped = None;
    for k in 0..400 {
        let s = if k % 20 < 10 { 0.123 } else { -0.123 };
        tripped = tripped.or(m.observe(&[s, 0.0, 0.0, 0.0], &[0.123; 4]));
    }
    total += allocations() - before;
    assert!(matches!(tripped, Some(SafetyReason::LimitCycle { .. })));
    assert_eq!(total, 0);
}
