//! The passivity observer/controller on the device port inside `HapticSystem` (§12; DESIGN §7; issue
//! 11 build item 5):
//!
//! - the observer books the wrench the device actually produced (after saturation, the start-up ramp
//!   and the final gate), not the commanded one;
//! - it stops when the safety latch is set (α = 0, and a zero applied force books no energy);
//! - α is capped per axis at the explicit-damping limit `2·M_ii/T` of the device's inertia.

use haptic2d::control::coupling::CouplingGains;
use haptic2d::control::passivity::{explicit_damping_limit, PlanarPassivity};
use haptic2d::device::linalg::{jt_mul_v, V3, V4};
use haptic2d::device::{DeviceParams, HandModel};
use haptic2d::haptic::{ControllerKind, DeviceInTheLoop, HapticConfig, HapticSystem, SafetyConfig};
use haptic2d::scene::builtin;

const RATE: f64 = 1000.0;

fn pc_config() -> HapticConfig {
    HapticConfig {
        passivity: Some(PlanarPassivity::default()),
        keep_slave_loads: true,
        ..HapticConfig::default()
    }
}

fn q_at(sys: &HapticSystem, pose: V3) -> V4 {
    sys.device().kin.ik(&pose).expect("reachable pose")
}

/// The handle wrench (N, N, N·m) that torques `tau` produce at handle pose `x`: `J_aᵀ·τ`.
fn wrench_of(sys: &HapticSystem, x: &V3, tau: &V4) -> V3 {
    let j = sys.device().jacobian(x).unwrap();
    jt_mul_v(&j, tau)
}

#[test]
fn the_observer_books_the_applied_not_the_commanded_wrench() {
    // The scene's 2 N load drags the slave, so the device is commanded a force while the handle is
    // held. Mid-ramp (factor 0.1) the applied force is a tenth of it; the handle then moves 1 mm in
    // x, and the energy booked for that step must be −F_applied,x·Δx.
    let world = builtin("box-in-walls", Some(RATE)).unwrap().unwrap().world;
    let mut sys = HapticSystem::new(world, &pc_config()).unwrap();
    let c = sys.device_start();
    let q = q_at(&sys, c);
    for _ in 0..50 {
        sys.tick(&q);
    }
    let out = sys.tick(&q);
    let ramp = 50.0 / 500.0;
    let applied = wrench_of(&sys, &c, &out.torques);
    let commanded = out.record.f_cm;
    println!("commanded {commanded:?}, applied {applied:?}");
    assert!(commanded[0].abs() > 0.05, "a real command: {commanded:?}");
    assert!(
        (applied[0] - ramp * commanded[0]).abs() < 1e-9,
        "applied = ramp × commanded"
    );
    let e_before = sys.passivity().unwrap().x.e_obs();
    let moved = [c[0] + 0.001, c[1], c[2]];
    sys.tick(&q_at(&sys, moved));
    let booked = sys.passivity().unwrap().x.e_obs() - e_before;
    let expect = -applied[0] * 0.001;
    assert!(
        (booked - expect).abs() < 1e-12,
        "booked {booked:e} J, applied·Δx gives {expect:e} J, commanded·Δx {:e} J",
        -commanded[0] * 0.001
    );
}

#[test]
fn saturated_torques_are_booked_as_applied() {
    // τ_max = 0.02 N·m saturates a coupling stretched by 2 cm (10 N): the booking follows the
    // saturated torques.
    let device = DeviceParams {
        tau_max: 0.02,
        ..DeviceParams::default()
    };
    let world = builtin("box-in-walls", Some(RATE)).unwrap().unwrap().world;
    // The former default (C5 = 0): with the default's slave-side force feedback C5 = 2 the slave
    // chases the teleported handle three times harder and the coupling never stretches to 2 cm.
    let config = HapticConfig {
        device,
        controller: haptic2d::haptic::ControllerKind::FourChannel(
            haptic2d::control::four_channel::FourChannelGains::master_force_feedback(),
        ),
        ..pc_config()
    };
    let safety = SafetyConfig {
        ramp_time: 0.0,
        ..SafetyConfig::default()
    };
    let mut sys = HapticSystem::with_safety(world, &config, safety).unwrap();
    let c = sys.device_start();
    sys.tick(&q_at(&sys, c));
    // Pull the handle 2 cm away from the slave (no stall: one tick each way at 1 mm steps).
    let mut x = c[0];
    for _ in 0..20 {
        x -= 0.001;
        sys.tick(&q_at(&sys, [x, c[1], c[2]]));
    }
    let pose = [x, c[1], c[2]];
    for _ in 0..20 {
        sys.tick(&q_at(&sys, pose));
    }
    let out = sys.tick(&q_at(&sys, pose));
    assert!(out.record.flags & haptic2d::haptic::record::FLAG_SATURATED != 0);
    let applied = wrench_of(&sys, &pose, &out.torques);
    let e_before = sys.passivity().unwrap().x.e_obs();
    sys.tick(&q_at(&sys, [x - 0.0005, c[1], c[2]]));
    let booked = sys.passivity().unwrap().x.e_obs() - e_before;
    println!(
        "commanded {:.3} N, applied {:.3} N",
        out.record.f_cm[0], applied[0]
    );
    assert!(out.record.f_cm[0].abs() > 3.0 * applied[0].abs());
    assert!((booked - applied[0] * 0.0005).abs() < 1e-12, "{booked:e}");
}

#[test]
fn the_passivity_controller_stops_when_latched() {
    let world = builtin("box-in-walls", Some(RATE)).unwrap().unwrap().world;
    let mut sys = HapticSystem::new(world, &pc_config()).unwrap();
    let c = sys.device_start();
    let q = q_at(&sys, c);
    for _ in 0..600 {
        sys.tick(&q);
    }
    sys.inject_torque_fault(0, f64::NAN);
    assert!(sys.tick(&q).tripped);
    let e0 = sys.passivity().unwrap().e_obs();
    // The handle is moved around while latched: nothing is applied, so nothing is booked, and the
    // controller adds no damping.
    let mut x = c[0];
    for k in 0..100 {
        x += if k < 50 { 0.0002 } else { -0.0002 };
        let out = sys.tick(&q_at(&sys, [x, c[1], c[2]]));
        assert_eq!(out.torques, [0.0; 4]);
        assert_eq!(out.record.alpha, [0.0; 3]);
        let pc = sys.passivity().unwrap();
        assert_eq!(pc.x.alpha(), 0.0);
    }
    let e1 = sys.passivity().unwrap().e_obs();
    assert!(
        (e1 - e0).abs() < 1e-15,
        "E_obs moved by {:e} J while latched",
        e1 - e0
    );
}

/// An active start: the hand pushes from the first tick while the torques ramp in (a gain growing
/// on a stretched coupling is not passive), so the PC acts on every axis. Its α never exceeds the
/// explicit-damping limit 2·M_ii/T of the device at the measured pose, and on θ (M_θθ ≈ 6e-5 kg·m²)
/// that limit, not the 200 N·m·s/rad default, is what binds.
#[test]
fn alpha_is_capped_per_axis_by_the_explicit_damping_limit() {
    let world = builtin("box-in-walls", Some(500.0)).unwrap().unwrap().world;
    let config = HapticConfig {
        device: DeviceParams {
            f_c: 0.0,
            ..DeviceParams::default()
        },
        controller: ControllerKind::Coupling(CouplingGains::default()),
        passivity: Some(PlanarPassivity::default()),
        ..HapticConfig::default()
    };
    let sys = HapticSystem::new(world, &config).unwrap();
    let mut l = DeviceInTheLoop::new(sys, HandModel::Free, 10, false).unwrap();
    let start = l.plant.pose();
    l.hand = HandModel::SpringDamper {
        target: [start[0] - 2.0, start[1], start[2]],
        stiffness: [1.0, 1.0, 0.0],
        damping: [4.0, 4.0, 4.0 * 0.025 * 0.025],
    };
    let dt = 1.0 / 500.0;
    let mut at_cap = [false; 3];
    let mut max_alpha = [0.0f64; 3];
    for _ in 0..2000 {
        let out = l.step().unwrap();
        let m = l.system.device().mass_matrix();
        for i in 0..3 {
            let cap = explicit_damping_limit(m[i][i], dt).min(200.0);
            let a = out.record.alpha[i];
            assert!(a <= cap * (1.0 + 1e-12), "axis {i}: α {a} above {cap}");
            at_cap[i] |= a > 0.0 && a >= cap * (1.0 - 1e-12);
            max_alpha[i] = max_alpha[i].max(a);
        }
    }
    let m = l.system.device().mass_matrix();
    println!(
        "max α {max_alpha:?}; limits 2M/T = ({:.1}, {:.1}, {:.4}); at the cap: {at_cap:?}",
        explicit_damping_limit(m[0][0], dt),
        explicit_damping_limit(m[1][1], dt),
        explicit_damping_limit(m[2][2], dt)
    );
    assert!(at_cap[2], "the rotational limit binds");
    assert!(explicit_damping_limit(m[2][2], dt) < 1.0, "θ's limit ≪ 200");
}
