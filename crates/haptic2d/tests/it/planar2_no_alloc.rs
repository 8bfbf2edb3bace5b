//! The 2-DOF system (a 2DIY in the 3-DOF world, issue 12 item 3): once warm, `Planar2System::tick`
//! performs no heap allocation, with contacts coming and going as the handle drives the box into the
//! wall and back; and the slave follows the handle with the box starting aligned to it.

use crate::counting_alloc;
use counting_alloc::allocations;
use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::geom::Vec2;
use haptic2d::haptic::planar2::{Planar2Config, Planar2System};
use haptic2d::haptic::{ControllerKind, WorkspaceSquare};
use haptic2d::scene::builtin;

/// The handle path: from the gen 3 workspace centre 30 mm towards −x and back over 4 s (m).
fn handle_at(k: usize) -> Vec2 {
    let s = (k as f64 / 4000.0 * std::f64::consts::TAU).sin().abs();
    Vec2::new(0.019 - 0.03 * s, 0.10)
}

fn run(controller: ControllerKind, grasp: [f64; 2]) -> (u64, Planar2System) {
    run_bounded(controller, grasp, None)
}

fn run_bounded(
    controller: ControllerKind,
    grasp: [f64; 2],
    workspace: Option<WorkspaceSquare>,
) -> (u64, Planar2System) {
    let world = builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world;
    let linkage = Pantograph2::new(0.038, 0.07, 0.09).unwrap();
    let mut c = Planar2Config::new(linkage, 0.123);
    c.controller = controller;
    c.grasp = grasp;
    if let Some(w) = workspace {
        c.workspace = w;
    }
    let mut sys = Planar2System::new(world, c).unwrap();
    let mut total = 0;
    let mut contacts_seen = false;
    for k in 0..4000 {
        let q = linkage.ik(handle_at(k)).unwrap();
        let before = allocations();
        let out = sys.tick(&q);
        if k >= 50 {
            total += allocations() - before;
        }
        contacts_seen |= out.record.contacts > 0;
        assert!(!out.tripped, "{:?}", sys.safety_trip());
    }
    assert!(contacts_seen, "the box never touched the wall");
    (total, sys)
}

#[test]
fn planar2_tick_does_not_allocate_once_warm() {
    for name in ["four-channel", "coupling"] {
        let (a, _) = run(ControllerKind::from_name(name).unwrap(), [0.0; 2]);
        assert_eq!(a, 0, "{name}");
    }
}

#[test]
fn planar2_slave_starts_aligned_with_the_first_handle_reading() {
    let (_, sys) = run(ControllerKind::from_name("coupling").unwrap(), [0.0; 2]);
    let o = sys.device_origin().unwrap();
    assert!((o - handle_at(0)).length() < 1e-12);
    assert!((sys.world_origin() - Vec2::new(0.04, 0.0)).length() < 1e-12);
}

#[test]
fn planar2_off_centre_grasp_lets_contact_turn_the_box() {
    // Held 5 mm above its centre and pushed into the wall, the box turns about the grasp point.
    let (_, sys) = run(ControllerKind::from_name("coupling").unwrap(), [0.0, 0.005]);
    let b = &sys.world().bodies[sys.slave()];
    eprintln!("off-centre grasp: box angle {} rad", b.pose.angle);
    assert!(
        b.pose.angle.abs() > 1e-3,
        "off-centre grasp did not turn the box: {}",
        b.pose.angle
    );
    let (_, centred) = run(ControllerKind::from_name("coupling").unwrap(), [0.0; 2]);
    let w = centred.world();
    let b = &w.bodies[centred.slave()];
    assert!(
        b.pose.angle.abs() < 1e-6,
        "centred grasp turned the box: {}",
        b.pose.angle
    );
}

/// Issue 34 build item 5: with the device file's workspace square the 2-DOF tick applies the wall
/// (the path runs 5 mm past the −x edge of a ±25 mm square) and still allocates nothing.
#[test]
fn planar2_tick_with_the_workspace_wall_does_not_allocate() {
    let square = WorkspaceSquare::around([0.019, 0.10], 0.025);
    let (a, sys) = run_bounded(
        ControllerKind::from_name("coupling").unwrap(),
        [0.0; 2],
        Some(square),
    );
    assert_eq!(a, 0);
    // The path's far point, 5 mm past the −x edge, is inside the wall (pushed back toward +x).
    let far = handle_at(1000);
    let (wall, trip) = sys.workspace().wrench(&[far.x, far.y, 0.0], &[0.0; 3]);
    assert!(
        (wall[0] - 2000.0 * 0.005).abs() < 1e-9 && trip.is_none(),
        "{wall:?}"
    );
}
