//! Start-up (DESIGN §7, issue 11 build item 5): at the first valid device reading the mapping is
//! anchored so that the measured handle pose lands on the slave's pose, and the torques ramp in from
//! exactly zero over `SafetyConfig::ramp_time` (default 0.5 s). Before, a handle 2 cm and 1 rad off the
//! origin got (−10 N, −1 N·m) on the first tick. Also: the master-mass feed-forward acts with the
//! device's real mass matrix (before, the matrix passed was zero, so it never could).

use haptic2d::control::four_channel::FourChannelGains;
use haptic2d::device::linalg::{V3, V4};
use haptic2d::device::lowpass::LowPass2;
use haptic2d::haptic::{ControllerKind, HapticConfig, HapticSystem, SafetyConfig};
use haptic2d::scene::builtin;

const RATE: f64 = 1000.0;

fn system(config: &HapticConfig, safety: SafetyConfig) -> HapticSystem {
    let world = builtin("box-in-walls", Some(RATE)).unwrap().unwrap().world;
    HapticSystem::with_safety(world, config, safety).expect("valid system")
}

fn q_at(sys: &HapticSystem, pose: V3) -> V4 {
    sys.device().kin.ik(&pose).expect("reachable pose")
}

#[test]
fn startup_aligns_a_handle_far_from_the_origin_with_zero_force() {
    let mut sys = system(&HapticConfig::default(), SafetyConfig::default());
    let c = sys.device_start();
    let slave0 = sys.world().bodies[sys.slave()].pose;
    // The handle starts 2 cm and 1 rad away from the mapping's origin.
    let q = q_at(&sys, [c[0] + 0.02, c[1], c[2] + 1.0]);
    let out = sys.tick(&q);
    assert!(!out.tripped, "{:?}", sys.safety_trip());
    assert_eq!(
        out.torques, [0.0; 4],
        "the first tick's torques are exactly zero"
    );
    let f = out.record.f_cm;
    assert!(
        f.iter().all(|v| v.abs() < 1e-9),
        "no coupling force after alignment: {f:?}"
    );
    // The handle's pose now maps onto the slave's; the slave was not moved.
    let w = sys.map().pose_to_world(&out.record.x_m);
    assert!((w[0] - slave0.pos.x).abs() < 1e-12 && (w[1] - slave0.pos.y).abs() < 1e-12);
    assert!((w[2] - slave0.angle).abs() < 1e-12);
    assert_eq!(out.record.x_s, [slave0.pos.x, slave0.pos.y, slave0.angle]);
    // Held there, the loop stays quiet through the ramp.
    for _ in 0..600 {
        let out = sys.tick(&q);
        assert!(!out.tripped);
        assert!(
            out.record.f_cm.iter().all(|v| v.abs() < 1e-6),
            "{:?}",
            out.record.f_cm
        );
    }
}

#[test]
fn startup_torques_ramp_in_linearly_from_exactly_zero() {
    // The scene's 2 N load stays on the slave, so the coupling stretches and the device is
    // commanded a force while the handle is held still.
    let config = HapticConfig {
        keep_slave_loads: true,
        ..HapticConfig::default()
    };
    for ramp_time in [0.5, 0.1] {
        let mut sys = system(
            &config,
            SafetyConfig {
                ramp_time,
                ..SafetyConfig::default()
            },
        );
        let q = q_at(&sys, sys.device_start());
        let n_ramp = (ramp_time * RATE).round() as usize;
        let mut peak = 0.0f64;
        for k in 0..n_ramp + 50 {
            let ramp = sys.ramp();
            let out = sys.tick(&q);
            assert!(!out.tripped, "{:?}", sys.safety_trip());
            // What the same command gives unramped: the redundancy resolution of f_cm (scale 1).
            let full = sys
                .device()
                .torques_for_wrench(&out.record.f_cm, 0.0)
                .unwrap()
                .tau;
            let expect = if k == 0 {
                0.0
            } else {
                (k as f64 / n_ramp as f64).min(1.0)
            };
            assert!((ramp - expect).abs() < 1e-12, "tick {k}: ramp {ramp}");
            for (i, (got, f)) in out.torques.iter().zip(full).enumerate() {
                assert!(
                    (got - expect * f).abs() <= 1e-12 * (1.0 + f.abs()),
                    "tick {k}, motor {i}: {got} vs {expect} x {f}"
                );
            }
            if k == 0 {
                assert_eq!(out.torques, [0.0; 4]);
            }
            peak = peak.max(full.iter().fold(0.0, |m, v| m.max(v.abs())));
        }
        assert!(peak > 1e-3, "the test commands a real torque ({peak})");
    }
}

#[test]
fn re_arming_and_resuming_re_align_and_ramp_again() {
    // The spec gains: the f_cm ≈ 0 check below is on the position/velocity channels after
    // re-alignment; the default's local force feedback (C6 = −1) adds the observer's hand-wrench
    // estimate, which is not zero after a pause (the torques still start at exactly zero).
    let config = HapticConfig {
        keep_slave_loads: true,
        controller: ControllerKind::FourChannel(FourChannelGains::spec()),
        ..HapticConfig::default()
    };
    let mut sys = system(&config, SafetyConfig::default());
    let c = sys.device_start();
    let q = q_at(&sys, c);
    for _ in 0..700 {
        sys.tick(&q);
    }
    assert_eq!(sys.ramp(), 1.0);
    // Paused while the handle moves 1 cm (over 0.2 s, then held 0.1 s): the next running tick
    // anchors there and starts at zero.
    for k in 1..=200 {
        let y = c[1] + 0.01 * k as f64 / 200.0;
        sys.tick_paused(&q_at(&sys, [c[0], y, c[2]]));
    }
    let moved = q_at(&sys, [c[0], c[1] + 0.01, c[2]]);
    for _ in 0..100 {
        sys.tick_paused(&moved);
    }
    let out = sys.tick(&moved);
    assert_eq!(out.torques, [0.0; 4]);
    // (K_m·1 cm would be 5 N; what is left is the slave's own slow motion.)
    assert!(
        out.record.f_cm.iter().all(|v| v.abs() < 1e-4),
        "{:?}",
        out.record.f_cm
    );
    // A trip and a re-arm do the same.
    sys.inject_torque_fault(0, f64::NAN);
    assert!(sys.tick(&moved).tripped);
    sys.reset_safety();
    let out = sys.tick(&q);
    assert!(!out.tripped);
    assert_eq!(out.torques, [0.0; 4]);
    assert!(sys.ramp() > 0.0 && sys.ramp() < 0.01);
}

#[test]
fn master_mass_feedforward_acts_with_the_device_mass_matrix() {
    // The scene's 2 N load accelerates the slave under a still handle. Each tick's device command is
    // recomputed from the record without the feed-forward (§11.1: K_m·(x_s − x_m) + B_m·(v_s − v_m)
    // − f_e); what is left is the feed-forward, which must be M̂_x·â_s with â_s the 30 Hz low-passed
    // backward difference of v_s. Off, nothing is left.
    // The §11.1 form f_cm = K_m·Δx + B_m·Δv − f_e (+ M̂_x·â_s) that `nominal` below writes out:
    // the spec gains (C6 = 0, no damping injection), so the feed-forward is what is left over.
    let gains = FourChannelGains::spec();
    let run = |ff: bool| {
        let config = HapticConfig {
            controller: ControllerKind::FourChannel(FourChannelGains {
                master_feedforward: ff,
                ..gains
            }),
            keep_slave_loads: true,
            ..HapticConfig::default()
        };
        let mut sys = system(
            &config,
            SafetyConfig {
                ramp_time: 0.0,
                ..SafetyConfig::default()
            },
        );
        let q = q_at(&sys, sys.device_start());
        let mut peak = 0.0f64;
        let mut lp = LowPass2::new(gains.accel_cutoff_hz, 1.0 / RATE);
        let mut v_prev: Option<V3> = None;
        for k in 0..300 {
            let r = sys.tick(&q).record;
            let m = sys.device().mass_matrix();
            assert!(m[0][0] > 0.1, "a real mass matrix: {m:?}");
            let raw: V3 = match v_prev {
                Some(v) => std::array::from_fn(|i| (r.v_s[i] - v[i]) * RATE),
                None => [0.0; 3],
            };
            v_prev = Some(r.v_s);
            let a = lp.update(&raw);
            let x_m = sys.map().pose_to_world(&r.x_m);
            let v_m = sys.map().twist_to_world(&r.v_m);
            for i in 0..3 {
                let nominal = gains.k_m[i] * (r.x_s[i] - x_m[i])
                    + gains.b_m[i] * (r.v_s[i] - v_m[i])
                    - r.f_e[i];
                let left = r.f_cm[i] - nominal;
                let expect: f64 = if ff {
                    (0..3).map(|j| m[i][j] * a[j]).sum()
                } else {
                    0.0
                };
                assert!(
                    (left - expect).abs() < 1e-9,
                    "ff {ff}, tick {k}, axis {i}: {left} vs {expect}"
                );
                peak = peak.max(left.abs());
            }
        }
        peak
    };
    let (on, off) = (run(true), run(false));
    println!("feed-forward: up to {on:.3} N on, {off:.1e} N off");
    assert!(on > 0.1, "the feed-forward acted ({on} N)");
}
