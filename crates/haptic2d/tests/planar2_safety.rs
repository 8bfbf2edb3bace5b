//! The 2-DOF system on the shared safety layer (issue 12, task item 5): the start-up ramp of
//! `SafetyConfig::ramp_time` from the first valid reading (the first tick's torques exactly zero),
//! the stall trip within the tick with its reason, the final clamp, and a pause or re-arm that
//! re-aligns and ramps in again from zero.

use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::geom::Vec2;
use haptic2d::haptic::planar2::{Planar2Config, Planar2System};
use haptic2d::haptic::{ControllerKind, SafetyReason};
use haptic2d::scene::builtin;

const T: f64 = 1e-3;

fn linkage() -> Pantograph2 {
    Pantograph2::new(0.038, 0.07, 0.09).unwrap()
}

fn system(ramp_time: f64) -> Planar2System {
    let world = builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world;
    let mut c = Planar2Config::new(linkage(), 0.123);
    c.controller = ControllerKind::from_name("coupling").unwrap();
    c.safety.ramp_time = ramp_time;
    Planar2System::new(world, c).unwrap()
}

/// Joint angles of the handle `dx` m from the gen 3 workspace centre along x.
fn q_at(dx: f64) -> [f64; 2] {
    linkage().ik(Vec2::new(0.019 + dx, 0.10)).unwrap()
}

fn peak(t: &[f64; 2]) -> f64 {
    t[0].abs().max(t[1].abs())
}

#[test]
fn planar2_torques_start_at_zero_and_ramp_in_over_the_shared_ramp_time() {
    let mut sys = system(0.1);
    // The first valid reading anchors the mapping: zero torques, exactly.
    let out = sys.tick(&q_at(0.0));
    assert_eq!(out.torques, [0.0; 2]);
    // The handle held 5 mm off: the coupling pulls, scaled by the ramp n / 100.
    let mut prev_ramp = 0.0;
    for n in 1..=150 {
        let ramp = sys.ramp();
        assert!(
            (ramp - (n as f64 / 100.0).min(1.0)).abs() < 1e-12,
            "tick {n}: {ramp}"
        );
        assert!(ramp >= prev_ramp);
        prev_ramp = ramp;
        let out = sys.tick(&q_at(0.005));
        assert!(!out.tripped, "{:?}", sys.safety_trip());
        assert!(
            peak(&out.torques) <= 0.123 + 1e-15,
            "clamped: {:?}",
            out.torques
        );
    }
    assert_eq!(sys.ramp(), 1.0);
}

#[test]
fn planar2_a_stall_latches_zero_torques_in_the_same_tick_with_its_reason() {
    let mut sys = system(0.0);
    sys.tick(&q_at(0.0));
    let out = sys.tick_elapsed(&q_at(0.005), T);
    assert!(peak(&out.torques) > 0.0 && !out.tripped);
    // 6 periods since the previous tick, limit 5 (the shared default).
    let out = sys.tick_elapsed(&q_at(0.005), 6.0 * T);
    assert!(out.tripped);
    assert_eq!(out.torques, [0.0; 2]);
    let trip = sys.safety_trip().unwrap();
    assert!(
        matches!(trip.reason, SafetyReason::Stall { elapsed, limit } if elapsed == 6.0 * T && (limit - 5.0 * T).abs() < 1e-15),
        "{trip}"
    );
    assert!(trip.to_string().contains("stalled"), "{trip}");
    // Latched: zero from now on, even on time.
    assert_eq!(sys.tick(&q_at(0.005)).torques, [0.0; 2]);
    // A NaN interval is a stall too.
    let mut sys = system(0.0);
    sys.tick(&q_at(0.0));
    assert!(sys.tick_elapsed(&q_at(0.0), f64::NAN).tripped);
}

#[test]
fn planar2_pause_and_rearm_realign_and_ramp_in_from_zero() {
    let mut sys = system(0.05);
    sys.tick(&q_at(0.0));
    for _ in 0..100 {
        sys.tick(&q_at(0.004));
    }
    assert_eq!(sys.ramp(), 1.0);
    // Paused: zero torques while the handle moves 10 mm.
    let out = sys.tick_paused(&q_at(0.014));
    assert_eq!(out.torques, [0.0; 2]);
    // Resumed: the slave is aligned with the handle where it is now (zero torque), ramp from zero.
    assert_eq!(sys.ramp(), 0.0);
    let out = sys.tick(&q_at(0.014));
    assert_eq!(out.torques, [0.0; 2]);
    assert!((sys.device_origin().unwrap() - Vec2::new(0.033, 0.10)).length() < 1e-12);
    // A stall, then a re-arm: the same.
    sys.tick_elapsed(&q_at(0.014), 10.0 * T);
    assert!(sys.safety_trip().is_some());
    sys.reset_safety();
    assert!(sys.safety_trip().is_none());
    assert_eq!(sys.ramp(), 0.0);
    assert_eq!(sys.tick(&q_at(0.02)).torques, [0.0; 2]);
    assert!(!sys.tick(&q_at(0.025)).tripped);
}
