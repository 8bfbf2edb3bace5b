//! Issue 36 items 3 and 4: the device file of the friction comparison runs, and the second reading of
//! "the hand is replaced by a constant force" (a force injected into the hand-force estimate).

use haptic2d::control::four_channel::FourChannelGains;
use haptic2d::device::{DeviceParams, HandModel};
use haptic2d::haptic::experiment::DeviceInTheLoop;
use haptic2d::haptic::system::HapticSystem;
use haptic2d::haptic::ControllerKind;
use haptic2d::haptic::HapticConfig;
use haptic2d_lab::scenarios::{capstan_friction_device, with_capstan_friction};

#[test]
fn capstan_friction_file_has_realistic_joint_friction_and_a_bounded_compensation() {
    let d = capstan_friction_device().expect("devices/twin-pantograph-capstan-friction.toml");
    // 0.01–0.02 N·m at a joint: a small brushed motor through a 10:1 capstan (the file's reasoning).
    assert!((0.01..=0.02).contains(&d.f_c), "f_c = {}", d.f_c);
    assert!(d.f_c > DeviceParams::default().f_c);
    assert!(d.friction_compensation > 0.0 && d.friction_compensation < 1.0);
    assert!(d.friction_deadband > 0.0);
    // Every other field is the spec device's.
    let spec = DeviceParams::default();
    assert_eq!(
        (d.s, d.l1, d.n_g, d.tau_max),
        (spec.s, spec.l1, spec.n_g, spec.tau_max)
    );
    // The comparison runs: the file's friction, with and without its compensation.
    let off = with_capstan_friction(&spec, false).unwrap();
    let on = with_capstan_friction(&spec, true).unwrap();
    assert_eq!((off.f_c, off.friction_compensation), (d.f_c, 0.0));
    assert_eq!(
        (on.f_c, on.friction_compensation),
        (d.f_c, d.friction_compensation)
    );
}

/// Two identical loops, one with a wrench injected into the hand-force estimate: in the tick after
/// the injection the controller's outputs differ by exactly the hand-force channels times the
/// injection — the slave drive by `C3 = 1 + C5` times it, the device command by `C6` times it — and
/// the recorded estimate (the observer's own) does not change.
#[test]
fn hand_estimate_injection_enters_the_controller_as_the_hand_force() {
    let text = haptic2d::scene::BUILTIN
        .iter()
        .find(|b| b.0 == "box-in-walls")
        .unwrap()
        .2;
    let gains = FourChannelGains::default();
    let cfg = HapticConfig {
        controller: ControllerKind::FourChannel(gains),
        ..HapticConfig::default()
    };
    let make = || {
        let world = haptic2d::scene::Scene::from_toml(text, "box", Some(500.0))
            .unwrap()
            .world;
        let system = HapticSystem::new(world, &cfg).unwrap();
        let hold = HandModel::grip(system.device_start());
        DeviceInTheLoop::new(system, hold, 10, true).unwrap()
    };
    let (mut a, mut b) = (make(), make());
    for _ in 0..400 {
        let (ra, rb) = (a.step().unwrap().record, b.step().unwrap().record);
        assert_eq!(ra.f_cs, rb.f_cs);
    }
    let inj = [-2.0, 0.5, 0.01];
    b.system.set_hand_estimate_injection(inj);
    let (ra, rb) = (a.step().unwrap().record, b.step().unwrap().record);
    assert_eq!(ra.w_h, rb.w_h, "the recorded estimate is the observer's");
    for (i, inj_i) in inj.iter().enumerate() {
        // Scale 1: the world wrench is the handle wrench.
        let d_cs = rb.f_cs[i] - ra.f_cs[i];
        let d_cm = rb.f_cm[i] - ra.f_cm[i];
        assert!(
            (d_cs - (1.0 + gains.c5[i]) * inj_i).abs() < 1e-9,
            "axis {i}: slave drive changed by {d_cs}"
        );
        assert!(
            (d_cm - gains.c6[i] * inj_i).abs() < 1e-9,
            "axis {i}: device command changed by {d_cm}"
        );
    }
}
