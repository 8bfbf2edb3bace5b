//! The workspace bound of the device file (DESIGN §7, issue 11 build item 5): past the edge of the
//! workspace square (`workspace_center_* ± workspace_half_width`) the handle feels a stiff passive wall
//! (`workspace_wall_stiffness`, `workspace_wall_damping`), and beyond `workspace_trip_distance` the
//! safety latch trips. Before, nothing held the handle: it left the ±32 mm square by 100 mm before the
//! singularity margin tripped.

use haptic2d::control::coupling::CouplingGains;
use haptic2d::device::linalg::{V3, V4};
use haptic2d::device::{DeviceParams, HandModel};
use haptic2d::haptic::{
    ControllerKind, DeviceInTheLoop, HapticConfig, HapticSystem, SafetyConfig, SafetyReason,
    WorkspaceBound,
};
use haptic2d::scene::builtin;

const RATE: f64 = 1000.0;

fn system(device: DeviceParams) -> HapticSystem {
    let world = builtin("box-in-walls", Some(RATE)).unwrap().unwrap().world;
    let config = HapticConfig {
        device,
        ..HapticConfig::default()
    };
    let safety = SafetyConfig {
        ramp_time: 0.0,
        ..SafetyConfig::default()
    };
    HapticSystem::with_safety(world, &config, safety).expect("valid system")
}

fn q_at(sys: &HapticSystem, pose: V3) -> V4 {
    sys.device().kin.ik(&pose).expect("reachable pose")
}

#[test]
fn past_the_edge_the_handle_feels_a_stiff_wall() {
    let p = DeviceParams::default();
    let mut sys = system(p);
    let edge_x = p.workspace_center_x + p.workspace_half_width;
    // Started at rest 2 mm past the +x edge: the start-up alignment anchors the coupling there, so
    // the first tick's command is the wall alone, −K·2 mm = −4 N.
    let q = q_at(&sys, [edge_x + 0.002, p.workspace_center_y, 0.3]);
    let out = sys.tick(&q);
    assert!(!out.tripped, "{:?}", sys.safety_trip());
    let f = out.record.f_cm;
    assert!((f[0] + 4.0).abs() < 1e-9, "{f:?}");
    assert!(f[1].abs() < 1e-9 && f[2].abs() < 1e-9, "{f:?}");
    assert!(
        out.torques.iter().any(|t| t.abs() > 1e-3),
        "{:?}",
        out.torques
    );
}

#[test]
fn the_wall_is_a_spring_damper_that_only_pushes_back() {
    let p = DeviceParams::default();
    let w = WorkspaceBound::new(&p, 1.0 / RATE);
    assert_eq!(w.stiffness, 2000.0);
    let (cx, cy, h) = (
        p.workspace_center_x,
        p.workspace_center_y,
        p.workspace_half_width,
    );
    // Inside: nothing.
    assert_eq!(
        w.wrench(&[cx + h, cy - h, 5.0], &[1.0, -1.0, 1.0]).0,
        [0.0; 3]
    );
    // 3 mm past −y, moving out at 0.1 m/s: spring 6 N plus damper 0.5 N, inward (+y).
    let (f, trip) = w.wrench(&[cx, cy - h - 0.003, 0.0], &[0.0, -0.1, 0.0]);
    assert!(
        (f[1] - 6.5).abs() < 1e-9 && f[0] == 0.0 && f[2] == 0.0,
        "{f:?}"
    );
    assert!(trip.is_none());
    // 0.1 mm past +x moving in at 0.1 m/s: K·p − B·|v| = 0.2 − 0.5 < 0, so zero, never a pull.
    let (f, _) = w.wrench(&[cx + h + 0.0001, cy, 0.0], &[-0.1, 0.0, 0.0]);
    assert_eq!(f, [0.0; 3]);
    // Both axes at a corner.
    let (f, _) = w.wrench(&[cx + h + 0.001, cy + h + 0.002, 0.0], &[0.0; 3]);
    assert!(
        (f[0] + 2.0).abs() < 1e-9 && (f[1] + 4.0).abs() < 1e-9,
        "{f:?}"
    );
    // Colgate: at 100 Hz, 5 N·s/m renders at most 2·B/T = 1000 N/m.
    assert_eq!(WorkspaceBound::new(&p, 0.01).stiffness, 1000.0);
}

#[test]
fn beyond_the_trip_distance_the_latch_trips() {
    let p = DeviceParams::default();
    let mut sys = system(p);
    let c = sys.device_start();
    let mut x = c[0];
    let edge = p.workspace_center_x + p.workspace_half_width;
    let mut tripped_at = None;
    // Walk the handle out at 0.2 m/s.
    for k in 0..400 {
        let out = sys.tick(&q_at(&sys, [x, c[1], c[2]]));
        if out.tripped {
            assert_eq!(out.torques, [0.0; 4]);
            tripped_at = Some((k, x));
            break;
        }
        x += 0.0002;
    }
    let (_, x_trip) = tripped_at.expect("tripped");
    let trip = sys.safety_trip().unwrap();
    println!("{trip}");
    assert!(x_trip - edge > p.workspace_trip_distance);
    assert!(x_trip - edge < p.workspace_trip_distance + 0.0003);
    match trip.reason {
        SafetyReason::Workspace { axis, edge: e, .. } => {
            assert_eq!(axis, 0);
            assert_eq!(e, edge);
        }
        r => panic!("wrong reason {r:?}"),
    }
    // A device file with a tighter square trips sooner.
    let tight = DeviceParams {
        workspace_half_width: 0.02,
        workspace_trip_distance: 0.002,
        ..p
    };
    let mut sys = system(tight);
    let q = q_at(&sys, [0.0225, 0.14, 0.0]);
    assert!(sys.tick(&q).tripped);
}

#[test]
fn device_file_workspace_fields_are_checked() {
    for (field, p) in [
        (
            "workspace_trip_distance",
            DeviceParams {
                workspace_trip_distance: 0.0,
                ..DeviceParams::default()
            },
        ),
        (
            "workspace_wall_stiffness",
            DeviceParams {
                workspace_wall_stiffness: -1.0,
                ..DeviceParams::default()
            },
        ),
        (
            "workspace_wall_damping",
            DeviceParams {
                workspace_wall_damping: f64::NAN,
                ..DeviceParams::default()
            },
        ),
    ] {
        let e = p.validate().unwrap_err();
        assert!(e.contains(field), "{e}");
    }
}

/// The box in the walls on the twin with device `p` through the virtual coupling, the hand gripping
/// the handle at its start pose (encoder quantisation on or off).
fn gripped_box_in_walls(p: DeviceParams, quantize: bool) -> DeviceInTheLoop {
    let world = builtin("box-in-walls", Some(RATE)).unwrap().unwrap().world;
    let config = HapticConfig {
        device: p,
        controller: ControllerKind::Coupling(CouplingGains::default()),
        ..HapticConfig::default()
    };
    let sys = HapticSystem::new(world, &config).unwrap();
    let mut l = DeviceInTheLoop::new(sys, HandModel::Free, 4, quantize).unwrap();
    l.hand = HandModel::grip(l.plant.pose());
    l
}

/// The closed loop: a hand pushes the handle with 1.5 N toward +x after a 0.6 s grip, through the
/// virtual coupling, with the box free to follow for 0.24 m. The handle arrives at the edge at speed,
/// overshoots by a few mm (less than the 10 mm trip distance) and comes to rest about F/K = 0.75 mm past
/// the edge, with no trip.
#[test]
fn a_pushing_hand_is_held_at_the_edge() {
    let p = DeviceParams::default();
    let mut l = gripped_box_in_walls(p, true);
    let edge = p.workspace_center_x + p.workspace_half_width;
    let mut max_x = f64::NEG_INFINITY;
    for k in 0..(3.0 * RATE) as usize {
        if k == 600 {
            l.hand = HandModel::Constant {
                wrench: [1.5, 0.0, 0.0],
            };
        }
        let out = l.step().expect("the plant stays in reach");
        assert!(!out.tripped, "tick {k}: {:?}", l.system.safety_trip());
        max_x = max_x.max(l.plant_pose()[0]);
    }
    let last = l.plant_pose()[0];
    println!(
        "max {:.2} mm past the edge, at rest {:.3} mm past it",
        (max_x - edge) * 1e3,
        (last - edge) * 1e3
    );
    assert!(
        max_x - edge < 0.6 * p.workspace_trip_distance,
        "overshoot {}",
        max_x - edge
    );
    assert!((last - edge - 1.5 / 2000.0).abs() < 2e-4, "{}", last - edge);
}

/// Issue 34 build item 5, the twin's half of "a push that overpowers the wall trips at the
/// documented distance": a hand pushing 30 N toward +x (more than the wall's 20 N at 10 mm) after a
/// 0.6 s grip runs the plant past the edge; the latch trips in the tick whose reading is more than
/// `workspace_trip_distance` (10 mm) past it, by less than that tick's travel, and zeroes the torques.
#[test]
fn a_push_that_overpowers_the_wall_trips_at_the_trip_distance() {
    let p = DeviceParams::default();
    let mut l = gripped_box_in_walls(p, false);
    let edge = p.workspace_center_x + p.workspace_half_width;
    let mut prev = l.plant_pose()[0];
    for k in 0..(3.0 * RATE) as usize {
        if k == 600 {
            l.hand = HandModel::Constant {
                wrench: [30.0, 0.0, 0.0],
            };
        }
        let read = l.plant_pose()[0];
        let out = l.step().expect("the plant stays in reach");
        if out.tripped {
            assert_eq!(out.torques, [0.0; 4]);
            let trip = l.system.safety_trip().unwrap();
            println!("{trip}");
            assert!(
                matches!(trip.reason, SafetyReason::Workspace { axis: 0, .. }),
                "{trip}"
            );
            assert!(read - edge > p.workspace_trip_distance, "{read}");
            assert!(
                read - edge <= p.workspace_trip_distance + (read - prev).abs() + 1e-9,
                "{read} (previous {prev})"
            );
            return;
        }
        prev = read;
    }
    panic!("never tripped");
}
