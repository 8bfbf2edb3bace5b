//! The 2-DOF system on the shared safety layer (issue 12, task item 5): the start-up ramp of
//! `SafetyConfig::ramp_time` from the first valid reading (the first tick's torques exactly zero),
//! the stall trip within the tick with its reason, the final clamp, and a pause or re-arm that
//! re-aligns and ramps in again from zero.

use haptic2d::geom::Vec2;
use haptic2d::haptic::planar2::{Planar2Config, Planar2System};
use haptic2d::haptic::{SafetyReason, WorkspaceSquare};
use haptic2d::scene::builtin;

const T: f64 = 1e-3;

use crate::shared::{gen3_linkage as linkage, planar2_system};

fn system(ramp_time: f64) -> Planar2System {
    // The periods rule alone (the 20 ms floor has its own test in safety_gate.rs).
    planar2_system(ramp_time, |c| c.safety.min_stall_time = 0.0)
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
        matches!(trip.reason, SafetyReason::Stall { elapsed, limit, .. } if elapsed == 6.0 * T && (limit - 5.0 * T).abs() < 1e-15),
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

/// Issue 34 finding 5: the 2-DOF path had no workspace bound. With the device file's square set
/// (`Planar2Config::workspace`), the handle 2 mm past the +x edge feels the twin's wall (the same
/// `WorkspaceBound`): the first tick's command is the wall alone, −K·2 mm = −4 N.
#[test]
fn planar2_past_the_edge_the_handle_feels_the_same_wall_as_the_twin() {
    // Two systems on the same prescribed handle path, one with the bound and one without: the world
    // and the controller see the same handle, so the difference of their device commands is the
    // wall alone. The handle starts inside (the bound arms there), moves 2 mm past the +x edge and
    // is held there.
    let make = |square: WorkspaceSquare| planar2_system(0.0, |c| c.workspace = square);
    let mut walled = make(WorkspaceSquare::around([0.019, 0.10], 0.03));
    // "Without": a square far past the linkage's reach (1 m), whose wall the handle never meets.
    let mut free = make(WorkspaceSquare::around([0.019, 0.10], 1.0));
    assert_eq!(walled.workspace().stiffness, 2000.0);
    let path = (0..=160)
        .map(|i| 0.0002 * i as f64)
        .chain(std::iter::repeat_n(0.032, 200));
    let (mut a, mut b) = (walled.tick(&q_at(0.0)), free.tick(&q_at(0.0)));
    for dx in path {
        a = walled.tick(&q_at(dx));
        b = free.tick(&q_at(dx));
    }
    assert!(!a.tripped, "{:?}", walled.safety_trip());
    // The wall of the twin's bound: −(K·2 mm + B·v), K 2000 N/m, B 5 N·s/m, on x only.
    let v = a.record.v_m[0];
    let expected = -(2000.0 * 0.002 + 5.0 * v).max(0.0);
    let wall = [
        a.record.f_cm[0] - b.record.f_cm[0],
        a.record.f_cm[1] - b.record.f_cm[1],
    ];
    assert!(
        (wall[0] - expected).abs() < 1e-6 && wall[1].abs() < 1e-9,
        "{wall:?} against {expected}"
    );
    assert!(
        (expected + 4.0).abs() < 0.05,
        "held still: 4 N, got {expected}"
    );
    assert!(peak(&a.torques) > 1e-3, "{:?}", a.torques);
}

/// … and past the trip distance (10 mm) the latch trips in the tick that reads it.
#[test]
fn planar2_beyond_the_trip_distance_the_latch_trips() {
    let world = builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world;
    let mut c = Planar2Config::new(linkage(), 0.123);
    c.workspace = WorkspaceSquare::around([0.019, 0.10], 0.03);
    let mut sys = Planar2System::new(world, c).unwrap();
    let mut dx = 0.0;
    for _ in 0..400 {
        let out = sys.tick(&q_at(dx));
        if out.tripped {
            assert_eq!(out.torques, [0.0; 2]);
            break;
        }
        dx += 0.0002;
    }
    let trip = sys.safety_trip().expect("tripped");
    println!("{trip}");
    assert!(dx - 0.03 > 0.01 && dx - 0.03 < 0.0103, "{dx}");
    assert!(
        matches!(trip.reason, SafetyReason::Workspace { axis: 0, edge, .. } if (edge - 0.049).abs() < 1e-12),
        "{trip}"
    );
}

/// Issue 37 (the 2-DOF path lacked the twin's bound: `Planar2Config::new` had none, so a 2-DOF
/// system built without a device-file square let the handle run off under torque): with the
/// defaults alone, a handle driven out of its workspace latches. The default square is the
/// linkage's reach square, (0.019, 0.088) ± 0.032 m for this geometry, so walking +x along
/// y = 0.10 m from the centre trips 10 mm past the edge x = 0.051 m, with the workspace reason.
#[test]
fn a_two_dof_handle_driven_outside_its_workspace_latches_with_the_default_config() {
    let world = builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world;
    let mut sys = Planar2System::new(world, Planar2Config::new(linkage(), 0.123)).unwrap();
    let square = WorkspaceSquare::five_bar(&linkage());
    let edge = square.centre[0] + square.half_width;
    assert!((edge - 0.051).abs() < 1e-12, "{edge}");
    let mut dx = 0.0;
    let mut tripped_at = None;
    while dx < 0.06 {
        let out = sys.tick(&q_at(dx));
        if out.tripped {
            assert_eq!(out.torques, [0.0; 2]);
            tripped_at = Some(0.019 + dx);
            break;
        }
        dx += 0.0002;
    }
    let x = tripped_at.unwrap_or_else(|| panic!("no trip up to x = {}", 0.019 + dx));
    assert!(x - edge > 0.01 && x - edge < 0.0103, "tripped at x = {x}");
    let trip = sys.safety_trip().expect("tripped");
    assert!(
        matches!(trip.reason, SafetyReason::Workspace { axis: 0, edge: e, .. } if (e - edge).abs() < 1e-12),
        "{trip}"
    );
    // Latched: the handle brought back inside gets no torque until a re-arm.
    assert_eq!(sys.tick(&q_at(0.0)).torques, [0.0; 2]);
}

/// The square of a five-bar whose device file has none (a UDP pantograph): for the 2DIY gen 3
/// geometry, (0.019, 0.088) ± 0.032 m, with the default wall.
#[test]
fn a_five_bar_without_a_square_gets_one_around_its_reach_centre() {
    let s = WorkspaceSquare::five_bar(&linkage());
    assert!((s.centre[0] - 0.019).abs() < 1e-12);
    // r = (0.07 + 0.09 + 0.02)/2 = 0.09, y = √(0.09² − 0.019²).
    assert!((s.centre[1] - (0.0081f64 - 0.000361).sqrt()).abs() < 1e-12);
    assert!((s.half_width - 0.032).abs() < 1e-12);
    assert_eq!(s.trip_distance, 0.01);
    assert!(s.validate().is_ok());
    let bad = WorkspaceSquare {
        half_width: 0.0,
        ..s
    };
    assert!(bad.validate().unwrap_err().contains("half_width"));
}

/// Issue 34 build item 5: a joint angle no linkage can reach (1e30 rad, a garbage word) trips in
/// the tick that reads it, with a reason that names the joint and the bound.
#[test]
fn planar2_an_implausible_joint_angle_trips_with_its_reason() {
    let mut sys = system(0.0);
    sys.tick(&q_at(0.0));
    let q = q_at(0.0);
    let out = sys.tick(&[q[0], 1e30]);
    assert!(out.tripped);
    assert_eq!(out.torques, [0.0; 2]);
    let trip = sys.safety_trip().unwrap();
    println!("{trip}");
    assert!(
        matches!(trip.reason, SafetyReason::JointAngle { index: 1, value, .. } if value == 1e30),
        "{trip}"
    );
    assert!(trip.to_string().contains("plausible"), "{trip}");
}

/// … and so does a joint that jumps faster than any hand moves it (1.5 rad in one 1 ms tick:
/// 1500 rad/s against the 1000 rad/s bound).
#[test]
fn planar2_an_implausible_joint_speed_trips_with_its_reason() {
    let mut sys = system(0.0);
    let q = q_at(0.0);
    for _ in 0..10 {
        assert!(!sys.tick(&q).tripped);
    }
    let out = sys.tick(&[q[0] + 1.5, q[1]]);
    assert!(out.tripped && out.torques == [0.0; 2]);
    let trip = sys.safety_trip().unwrap();
    assert!(
        matches!(trip.reason, SafetyReason::JointSpeed { index: 0, value, limit } if (value - 1500.0).abs() < 1e-6 && limit == 1000.0),
        "{trip}"
    );
}
