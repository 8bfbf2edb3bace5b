//! The Inverse3 driver closed-loop against the Inverse Service emulator, in real time at 1 kHz
//! (issue 15): the point system (`PointSystem`: the plane point in, the plane force out, no linkage)
//! drives the box of box-in-walls into the left wall; the emulated cursor is pushed back and settles where the rendered stiffness says;
//! the third axis is held by the virtual plane.
//!
//! Expected values. The virtual coupling (K_c = 500 N/m) in series with the wall (k_c = 1000 N/m
//! per corner, the box's face on two corners: K_w = 2000 N/m) renders `K_r = 1/(1/K_c + 1/K_w)` =
//! 400 N/m. The box (centre at x = 0.04 m, half-length 0.02 m) touches the wall at x = 0 when its
//! centre is at 0.02 m, so the handle, mapped to the world, settles at `0.02 − F/K_r` under the
//! hand's push F = 0.8 N; the cursor, which started at the box centre, at
//! `x_0 − 0.02 − F/K_r`. On the held axis (z), the hand's 0.4 N against the plane's K = 1000 N/m
//! leaves it at `0.4 / 1000` = 0.4 mm from the plane. Tolerance: 20 % of each displacement (the
//! loop runs over WebSocket on a shared machine; the driver's force is applied with the service's
//! zero-order hold).

use crate::inverse3_support::*;

use std::time::Instant;

use haptic2d::haptic::{ControllerKind, PointConfig, PointSystem, WorkspaceSquare};
use haptic2d_devices::inverse3::{Emulator3Config, Hand3};

const PUSH: f64 = 0.8; // N, towards the left wall (−x)
const PRESS: f64 = 0.4; // N, into the plane (+z)
const K_R: f64 = 1.0 / (1.0 / 500.0 + 1.0 / 2000.0);

/// One tick of the tail: handle x (world, m), slave x (m), contacts, cursor position (m) and
/// velocity (m/s) in the emulator.
type Sample = (f64, f64, u32, [f64; 3], [f64; 3]);

#[test]
fn the_box_hits_the_wall_and_the_emulated_cursor_is_pushed_back() {
    let start = [0.01, -0.02, 0.0];
    let emu = emulator(Emulator3Config {
        start,
        hand: Some(Hand3 {
            target: start,
            k: [300.0; 3],
            b: [2.0; 3],
            t_hold: 1.0,
            push: [-PUSH, 0.0, PRESS],
        }),
        ..Emulator3Config::default()
    });
    let file = file_for(&emu, NOT_THE_TIMEOUT_UNDER_TEST);
    let mut dev = open(&file);
    let scene = haptic2d::scene::builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap();
    let mut world = scene.world;
    let i = world.body_index("box").unwrap();
    world.bodies[i].pose.pos.x = 0.04;
    // The system `haptic2d run` gives the Inverse3: the file's force limit and square.
    let mut c = PointConfig::new(
        file.force_limit,
        WorkspaceSquare::around(file.center, file.half_width),
    );
    c.common.controller = ControllerKind::from_name("coupling").unwrap();
    let mut system = PointSystem::new(world, c).unwrap();
    let t0 = Instant::now();
    let mut tail: Vec<Sample> = Vec::new();
    let n = 4000;
    for k in 0..n {
        let q = dev.read_point().unwrap_or_else(|e| panic!("tick {k}: {e}"));
        let out = system.tick(&q);
        assert!(
            !out.tripped,
            "safety trip at tick {k}: {:?}",
            system.safety_trip()
        );
        dev.write_force(&out.torques).unwrap();
        if k >= n - 1000 {
            let p = emu.plant();
            tail.push((
                out.record.x_m[0],
                out.record.x_s[0],
                out.record.contacts,
                p.p,
                p.v,
            ));
        }
        wait_tick(t0, k as u64 + 1);
    }
    let mean = |f: &dyn Fn(&Sample) -> f64| tail.iter().map(f).sum::<f64>() / tail.len() as f64;
    assert!(
        tail.iter().all(|s| s.2 > 0),
        "the box is not touching the wall"
    );
    let slave = mean(&|s| s.1);
    assert!(
        (slave - 0.02).abs() < 1e-3,
        "box centre at {slave} m, not at the wall"
    );
    let handle = mean(&|s| s.0);
    let expected = PUSH / K_R;
    let displacement = 0.02 - handle;
    eprintln!(
        "handle x {handle:.5} m, displacement past contact {:.3} mm (expected {:.3} mm)",
        displacement * 1e3,
        expected * 1e3
    );
    assert!(
        (displacement - expected).abs() < 0.2 * expected,
        "handle displacement {displacement} m vs F/K_r = {expected} m"
    );
    // The emulated cursor: pushed back by the wall, at rest where the stiffness says.
    let cx = mean(&|s| s.3[0]);
    let want_x = start[0] - 0.02 - expected;
    eprintln!("cursor x {cx:.5} m, expected {want_x:.5} m");
    assert!(
        (cx - want_x).abs() < 0.2 * expected,
        "cursor x {cx} vs {want_x}"
    );
    let vx = mean(&|s| s.4[0].abs());
    assert!(vx < 0.01, "the cursor still moves: |v_x| ≈ {vx} m/s");
    // The held axis.
    let cz = mean(&|s| s.3[2]);
    let want_z = file.plane_position + PRESS / file.plane_stiffness;
    eprintln!("cursor z {cz:.6} m, expected {want_z:.6} m (plane spring)");
    assert!(
        (cz - want_z).abs() < 0.2 * PRESS / file.plane_stiffness,
        "held axis at {cz} m vs {want_z} m"
    );
    drop(dev);
    let r = emu.report();
    assert!(r.forces >= 3000, "{r:?}");
    assert_eq!(r.malformed, 0, "{r:?}");
}
