//! The tick's final gate and its stall check (DESIGN §7, issue 11 build item 5), through the public
//! API of `HapticSystem`:
//!
//! - the final gate clamps every motor torque to `|τ| ≤ τ_max` and trips on a request above
//!   `τ_max·(1 + torque_trip_margin)` (before: it checked finiteness only, and a finite 5 N·m went
//!   out unchanged with `τ_max = 0.5`);
//! - a tick more than `max_stall_periods` periods after the previous one trips the latch at once
//!   (before: a stall of any length was one missed deadline);
//! - a late tick within the limit differentiates over the measured interval (before: a 1 cm jump read
//!   as 2.7 m/s and saturated the torques).
//!
//! The handle is placed directly through inverse kinematics (no plant): `q = IK(pose)`.

use haptic2d::device::linalg::{V3, V4};
use haptic2d::haptic::{HapticConfig, HapticSystem, SafetyConfig, SafetyReason};
use haptic2d::scene::builtin;

const RATE: f64 = 1000.0;
const T: f64 = 1.0 / RATE;

fn system(safety: SafetyConfig) -> HapticSystem {
    let world = builtin("box-in-walls", Some(RATE)).unwrap().unwrap().world;
    HapticSystem::with_safety(world, &HapticConfig::default(), safety).expect("valid system")
}

fn no_ramp() -> SafetyConfig {
    SafetyConfig {
        ramp_time: 0.0,
        ..SafetyConfig::default()
    }
}

fn q_at(sys: &HapticSystem, pose: V3) -> V4 {
    sys.device().kin.ik(&pose).expect("reachable pose")
}

fn centre(sys: &HapticSystem) -> V3 {
    sys.device_start()
}

#[test]
fn final_gate_trips_on_a_finite_request_far_above_tau_max() {
    let mut sys = system(no_ramp());
    let q = q_at(&sys, centre(&sys));
    for _ in 0..10 {
        assert!(!sys.tick(&q).tripped);
    }
    // 5 N·m requested with τ_max = 0.5 N·m.
    sys.inject_torque_fault(1, 5.0);
    let out = sys.tick(&q);
    assert!(out.tripped);
    assert_eq!(out.torques, [0.0; 4], "zeroed in the tick of the request");
    let trip = sys.safety_trip().expect("latched");
    println!("{trip}");
    match trip.reason {
        SafetyReason::TorqueLimit {
            index,
            value,
            limit,
        } => {
            assert_eq!(index, 1);
            assert_eq!(value, 5.0);
            assert!((limit - 0.5 * 1.05).abs() < 1e-12, "default margin 5 %");
        }
        r => panic!("wrong reason {r:?}"),
    }
    // Latched: stays zero.
    for _ in 0..5 {
        assert_eq!(sys.tick(&q).torques, [0.0; 4]);
    }
}

#[test]
fn final_gate_clamps_a_request_just_above_tau_max_keeping_its_direction() {
    let mut sys = system(no_ramp());
    let q = q_at(&sys, centre(&sys));
    for _ in 0..10 {
        sys.tick(&q);
    }
    // 0.52 N·m is within the 5 % margin: clamped to τ_max, no trip.
    sys.inject_torque_fault(3, -0.52);
    let out = sys.tick(&q);
    assert!(!out.tripped, "{:?}", sys.safety_trip());
    assert!((out.torques[3] + 0.5).abs() < 1e-12, "{:?}", out.torques);
    assert!(out.torques.iter().all(|t| t.abs() <= 0.5 + 1e-12));
    // With a larger margin configured the same request that tripped above only clamps.
    let mut sys = system(SafetyConfig {
        torque_trip_margin: 10.0,
        ..no_ramp()
    });
    let q = q_at(&sys, centre(&sys));
    sys.tick(&q);
    sys.inject_torque_fault(0, 5.0);
    let out = sys.tick(&q);
    assert!(!out.tripped);
    assert!((out.torques[0] - 0.5).abs() < 1e-12);
}

#[test]
fn safety_config_errors_name_the_field() {
    for (cfg, field) in [
        (
            SafetyConfig {
                ramp_time: -1.0,
                ..SafetyConfig::default()
            },
            "ramp_time",
        ),
        (
            SafetyConfig {
                max_stall_periods: 0.5,
                ..SafetyConfig::default()
            },
            "max_stall_periods",
        ),
        (
            SafetyConfig {
                torque_trip_margin: f64::NAN,
                ..SafetyConfig::default()
            },
            "torque_trip_margin",
        ),
    ] {
        let world = builtin("box-in-walls", Some(RATE)).unwrap().unwrap().world;
        let e = HapticSystem::with_safety(world, &HapticConfig::default(), cfg).unwrap_err();
        assert!(e.contains(field), "{e}");
    }
}

#[test]
fn a_stall_longer_than_the_limit_trips_in_one_tick() {
    let mut sys = system(SafetyConfig::default());
    let c = centre(&sys);
    let q = q_at(&sys, c);
    for _ in 0..600 {
        assert!(!sys.tick(&q).tripped);
    }
    // The loop stalls for 50 ms; meanwhile the hand moved the handle 1 cm.
    let moved = q_at(&sys, [c[0] + 0.01, c[1], c[2]]);
    let out = sys.tick_elapsed(&moved, 0.05);
    assert!(out.tripped);
    assert_eq!(out.torques, [0.0; 4]);
    let trip = sys.safety_trip().unwrap();
    println!("{trip}");
    match trip.reason {
        SafetyReason::Stall { elapsed, limit } => {
            assert_eq!(elapsed, 0.05);
            assert!((limit - 5.0 * T).abs() < 1e-15);
        }
        r => panic!("wrong reason {r:?}"),
    }
    // Exactly at the limit is not a stall.
    let mut sys = system(SafetyConfig::default());
    sys.tick(&q);
    assert!(!sys.tick_elapsed(&q, 5.0 * T).tripped);
    // A non-finite interval is a stall too (a broken clock must not pass).
    assert!(sys.tick_elapsed(&q, f64::NAN).tripped);
}

#[test]
fn a_late_tick_differentiates_over_the_measured_interval() {
    // The handle moves steadily at 0.1 m/s in x; the velocity filter has converged. Then one tick
    // comes 3 ms after the previous (within the 5-period limit): the handle moved 0.3 mm.
    let v = 0.1;
    let run = |late: bool| {
        let mut sys = system(SafetyConfig::default());
        let c = centre(&sys);
        let mut x = c[0] - 0.01;
        let mut rec = None;
        for _ in 0..300 {
            let out = sys.tick(&q_at(&sys, [x, c[1], c[2]]));
            assert!(!out.tripped);
            x += v * T;
        }
        x += 2.0 * v * T;
        let q = q_at(&sys, [x, c[1], c[2]]);
        let out = if late {
            sys.tick_elapsed(&q, 3.0 * T)
        } else {
            sys.tick(&q)
        };
        assert!(!out.tripped, "{:?}", sys.safety_trip());
        rec.replace(out.record);
        rec.unwrap().v_m[0]
    };
    let measured = run(true);
    let assumed = run(false);
    println!(
        "v after a 3 ms tick: {measured:.4} m/s measured interval, {assumed:.4} m/s assuming T"
    );
    assert!((measured - v).abs() < 0.01 * v, "{measured}");
    // Assuming one period reads a 0.3 mm step as 0.3 m/s: the filter jumps by α·0.2 m/s.
    assert!(assumed > 1.4 * v, "{assumed}");
}
