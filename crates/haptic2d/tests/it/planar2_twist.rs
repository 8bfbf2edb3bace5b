//! Issue 12 item 3: on a 2-DOF device the body's rotation is left to the world, or set from the
//! display (wheel / Q–E) through a twist target: a critically damped 5 Hz torsion spring-damper on the
//! slave, world side only (the motors never see it).

use haptic2d::geom::Vec2;
use haptic2d::haptic::planar2::{Planar2System, TWIST_TARGET_HZ};

use crate::shared::gen3_linkage as linkage;

fn system() -> Planar2System {
    crate::shared::planar2_system(0.0, |_| {})
}

/// The handle held still at the gen 3 workspace centre.
fn q_centre() -> [f64; 2] {
    linkage().ik(Vec2::new(0.019, 0.10)).unwrap()
}

fn slave_angle(s: &Planar2System) -> f64 {
    let w = s.world();
    w.bodies.iter().find(|b| b.is_dynamic()).unwrap().pose.angle
}

#[test]
fn twist_target_turns_the_slave_like_a_critically_damped_5_hz_spring_without_motor_torque() {
    let q = q_centre();
    // Reference run: no target, the same handle: the torques it needs to hold the box.
    let mut free = system();
    let mut s = system();
    free.tick(&q);
    s.tick(&q);
    let target = 0.2;
    s.set_twist_target(Some(target));
    let (k, b) = s.twist_gains();
    let inertia = s
        .world()
        .bodies
        .iter()
        .find(|b| b.is_dynamic())
        .unwrap()
        .inertia;
    let wn = 2.0 * std::f64::consts::PI * TWIST_TARGET_HZ;
    assert!(
        (k - inertia * wn * wn).abs() <= 1e-12 * k && (b - 2.0 * inertia * wn).abs() <= 1e-12 * b
    );
    // Critically damped: θ(t) = θ_t·(1 − (1 + ω_n t)·e^{−ω_n t}); at t = 1 s the error is
    // (1 + 31.4)·e^{−31.4} ≈ 8e-13 of θ_t, so the body sits at the target up to the sampling.
    let mut overshoot: f64 = 0.0;
    let mut at_0_1 = 0.0;
    for n in 1..=1000 {
        let a = s.tick(&q);
        let f = free.tick(&q);
        // World side only: the motors' torques do not see the twist (the box does not touch a
        // wall, and the coupling acts on x and y of the grasp point, the centre).
        for i in 0..2 {
            assert!(
                (a.torques[i] - f.torques[i]).abs() <= 1e-9,
                "tick {n}: {:?} vs {:?}",
                a.torques,
                f.torques
            );
        }
        let th = slave_angle(&s);
        overshoot = overshoot.max(th - target);
        if n == 100 {
            at_0_1 = th;
        }
    }
    let th = slave_angle(&s);
    assert!((th - target).abs() < 1e-4, "θ = {th} rad after 1 s");
    // At t = 0.1 s the closed form gives θ_t·(1 − (1 + π)·e^{−π}) = 0.8271·θ_t; the sampled
    // (semi-implicit) spring is within a few per cent of it at 1 kHz.
    let expect = target * (1.0 - (1.0 + wn * 0.1) * (-wn * 0.1f64).exp());
    assert!(
        (at_0_1 - expect).abs() < 0.03 * target,
        "θ(0.1 s) = {at_0_1} vs {expect}"
    );
    assert!(overshoot < 0.01 * target, "overshoot {overshoot} rad");
    // No target: the free run's box did not turn.
    assert!(slave_angle(&free).abs() < 1e-12);
    // Turned off: the body stays where the spring left it (no restoring torque).
    s.set_twist_target(None);
    assert_eq!(s.twist_target(), None);
    s.set_twist_target(Some(f64::NAN));
    assert_eq!(s.twist_target(), None, "a non-finite target turns it off");
}
