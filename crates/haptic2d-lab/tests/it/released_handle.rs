//! Released-handle regression (issue 11, spec §11.4): the full 3-DOF loop (`HapticSystem`, the
//! simulated twin pantograph, no hand impedance) against a stiff wall and inside the peg's channel,
//! at 0.5, 1, 2 and 10 kHz for 10 s. With the default configuration
//! (`FourChannelGains::local_force_feedback`) every run is bounded and ends without a safety stop;
//! the same runs with the §11.1 table (`FourChannelGains::spec`) are unstable.
//!
//! - **Wall**: box-in-walls with an undamped ZOH wall (2 × 1000 N/m), impacts off, the box's face on
//!   the left wall; the handle is pushed toward the wall by a force that rises smoothly to 2 N over
//!   0.3 s and then stays constant — a force source, i.e. no hand impedance: the released handle of
//!   §11.4 with the contact kept loaded. Bounded: over the last second the box's x varies by less
//!   than 10 µm (the default decays at about 3 1/s from tens of µm).
//! - **Channel**: peg-in-hole at world scale 2, the peg squeezed in its channel (1 mm interference
//!   per side), the hand free from the start. Bounded: `|y| < 0.5 mm` throughout (the interference
//!   is 1 mm) and the peg's x within 1 cm of its start. At 500 Hz the peg's 3.3e-5 kg·m² is below the
//!   rotational minimum mass of the §11.1 table's θ gains (§6.4) and the system refuses to start the
//!   spec configuration, which is checked instead; the default's θ gains (issue 36) accept it.
//!
//! The device is the spec's without joint Coulomb friction and without encoder quantisation (the
//! linear loop the analysis models): its 0.005 N·m per joint of Coulomb friction and the encoder's
//! 1.6e-5 m count turn the spec table's slow x-axis growth (2–19 1/s) into a ~0.1 mm limit cycle
//! that looks like the default's, which would hide the instability this test pins.

use haptic2d::control::coupling::CouplingGains;
use haptic2d::control::four_channel::FourChannelGains;
use haptic2d::device::{DeviceParams, HandModel};
use haptic2d::haptic::{ControllerKind, DeviceInTheLoop, HapticConfig, HapticSystem};
use haptic2d::scene::{Scene, BUILTIN};
use haptic2d::world::World;

const RATES: [f64; 4] = [500.0, 1000.0, 2000.0, 10000.0];
const SECONDS: f64 = 10.0;

fn builtin(name: &str) -> &'static str {
    BUILTIN.iter().find(|b| b.0 == name).expect("built-in").2
}

fn wall_world(rate: f64) -> World {
    let text = builtin("box-in-walls");
    let (a, b) = (
        text.find("[normal]").expect("[normal]"),
        text.find("[friction]").expect("[friction]"),
    );
    let t = format!("{}[normal]\nmodel = \"zoh\"\n\n{}", &text[..a], &text[b..])
        .replace("impacts = true", "impacts = false")
        .replace("position = [0.04, 0.0]", "position = [0.02, 0.0]");
    Scene::from_toml(&t, "wall", Some(rate))
        .expect("scene")
        .world
}

fn channel_world(rate: f64) -> World {
    Scene::from_toml(builtin("peg-in-hole"), "channel", Some(rate))
        .expect("scene")
        .world
}

fn config(gains: FourChannelGains, scale: f64, x0: Option<[f64; 3]>) -> HapticConfig {
    HapticConfig {
        device: DeviceParams {
            f_c: 0.0,
            ..DeviceParams::default()
        },
        controller: ControllerKind::FourChannel(gains),
        scale,
        device_origin: x0,
        ..HapticConfig::default()
    }
}

/// What a run did: the safety stop (if any), the box/peg x range over the last second, the largest
/// `|y|` and the largest x excursion from the start.
#[derive(Debug)]
struct Outcome {
    stopped: Option<String>,
    late_x_pp: f64,
    max_abs_y: f64,
    max_dx: f64,
}

fn run(world: World, cfg: &HapticConfig, rate: f64, push: bool) -> Outcome {
    run_with(world, cfg, rate, push, false)
}

fn run_with(world: World, cfg: &HapticConfig, rate: f64, push: bool, quantize: bool) -> Outcome {
    let sys = HapticSystem::new(world, cfg).expect("system");
    let mut l = DeviceInTheLoop::new(sys, HandModel::Free, 4, quantize).expect("loop");
    // Channel: the hand first nudges the handle 0.5 mm along y (a grip for 0.3 s), then lets go.
    let start = l.plant.pose();
    let nudge = HandModel::SpringDamper {
        target: [start[0], start[1] + 5e-4, start[2]],
        stiffness: [300.0, 300.0, 0.5],
        damping: [5.0, 5.0, 0.005],
    };
    let n_nudge = (0.3 * rate) as usize;
    let n = (SECONDS * rate) as usize;
    let late = n - rate as usize;
    let x_start = l.system.world().bodies[l.system.slave()].pose.pos.x;
    let (mut lo, mut hi, mut max_abs_y, mut max_dx) = (f64::MAX, f64::MIN, 0.0f64, 0.0f64);
    for k in 0..n {
        if !push {
            l.hand = if k < n_nudge { nudge } else { HandModel::Free };
        } else {
            let t = k as f64 / rate;
            let f = if t < 0.3 {
                1.0 - (std::f64::consts::PI * t / 0.3).cos()
            } else {
                2.0
            };
            l.hand = HandModel::Constant {
                wrench: [-f * cfg.scale, 0.0, 0.0],
            };
        }
        let o = match l.step() {
            Ok(o) => o,
            Err(e) => {
                return Outcome {
                    stopped: Some(format!("plant: {e}")),
                    late_x_pp: f64::INFINITY,
                    max_abs_y,
                    max_dx,
                }
            }
        };
        if o.tripped {
            return Outcome {
                stopped: l.system.safety_trip().map(|t| t.to_string()),
                late_x_pp: f64::INFINITY,
                max_abs_y,
                max_dx,
            };
        }
        let x = o.record.x_s;
        max_abs_y = max_abs_y.max(x[1].abs());
        max_dx = max_dx.max((x[0] - x_start).abs());
        if k >= late {
            lo = lo.min(x[0]);
            hi = hi.max(x[0]);
        }
    }
    Outcome {
        stopped: None,
        late_x_pp: hi - lo,
        max_abs_y,
        max_dx,
    }
}

#[test]
fn released_handle_against_a_stiff_wall_default_is_bounded_spec_is_not() {
    for rate in RATES {
        let ok = run(
            wall_world(rate),
            &config(FourChannelGains::default(), 1.0, None),
            rate,
            true,
        );
        println!("wall {rate} Hz default: {ok:?}");
        assert!(ok.stopped.is_none(), "{rate} Hz: {:?}", ok.stopped);
        assert!(
            ok.late_x_pp < 1e-5,
            "{rate} Hz: late p-p {:e}",
            ok.late_x_pp
        );
        let bad = run(
            wall_world(rate),
            &config(FourChannelGains::spec(), 1.0, None),
            rate,
            true,
        );
        println!("wall {rate} Hz spec: {bad:?}");
        assert!(
            bad.stopped.is_some() || bad.late_x_pp > 1e-4,
            "{rate} Hz: the spec configuration should be unstable: {bad:?}"
        );
    }
}

#[test]
fn released_handle_in_the_peg_channel_default_is_bounded_spec_is_not() {
    let x0 = Some([-0.03, 0.14, 0.0]);
    for rate in RATES {
        let ok = run(
            channel_world(rate),
            &config(FourChannelGains::default(), 2.0, x0),
            rate,
            false,
        );
        println!("channel {rate} Hz default: {ok:?}");
        assert!(ok.stopped.is_none(), "{rate} Hz: {:?}", ok.stopped);
        assert!(ok.max_abs_y < 5e-4 && ok.max_dx < 1e-2, "{rate} Hz: {ok:?}");
        if rate < 1000.0 {
            // The §11.1 table's θ slave PD: the peg is below 1.5 x its minimum mass (§6.4).
            let e = HapticSystem::new(
                channel_world(rate),
                &config(FourChannelGains::spec(), 2.0, x0),
            )
            .expect_err("below the rotational minimum mass");
            assert!(e.contains("min_mass"), "{e}");
            continue;
        }
        let bad = run(
            channel_world(rate),
            &config(FourChannelGains::spec(), 2.0, x0),
            rate,
            false,
        );
        println!("channel {rate} Hz spec: {bad:?}");
        assert!(
            bad.stopped.is_some() || bad.max_abs_y > 5e-4,
            "{rate} Hz: the spec configuration should be unstable: {bad:?}"
        );
    }
}

/// The default configuration on the spec's device as it is (joint Coulomb friction, encoder
/// quantisation), same two situations at the four rates: no safety stop, and bounded — the box keeps
/// its wall contact (its x varies by less than 0.5 mm over the last second; the penetration is 1 mm),
/// the peg stays squeezed (`|y| < 0.5 mm`).
#[test]
fn released_handle_default_on_the_real_device_model_is_bounded() {
    let x0 = Some([-0.03, 0.14, 0.0]);
    for rate in RATES {
        let mut cfg = config(FourChannelGains::default(), 1.0, None);
        cfg.device = DeviceParams::default();
        let w = run_with(wall_world(rate), &cfg, rate, true, true);
        println!("wall {rate} Hz default, real device: {w:?}");
        assert!(
            w.stopped.is_none() && w.late_x_pp < 5e-4,
            "{rate} Hz: {w:?}"
        );
        let mut cfg = config(FourChannelGains::default(), 2.0, x0);
        cfg.device = DeviceParams::default();
        let c = run_with(channel_world(rate), &cfg, rate, false, true);
        println!("channel {rate} Hz default, real device: {c:?}");
        assert!(
            c.stopped.is_none() && c.max_abs_y < 5e-4,
            "{rate} Hz: {c:?}"
        );
    }
}

/// The virtual coupling (the other controller `run` offers, at its default gains) in the same two
/// 3-DOF situations at the four rates: no safety stop and bounded, like the four-channel default.
/// Long variant (about 11 s): the CI set covers the coupling in 1-DOF at every rate.
#[test]
#[ignore = "long variant: the 3-DOF loop with the virtual coupling at 0.5-10 kHz (the 1-DOF tests cover it in CI)"]
fn released_handle_coupling_is_bounded_long() {
    let x0 = Some([-0.03, 0.14, 0.0]);
    let coupling = |scale: f64, x0: Option<[f64; 3]>| HapticConfig {
        device: DeviceParams {
            f_c: 0.0,
            ..DeviceParams::default()
        },
        controller: ControllerKind::Coupling(CouplingGains::default()),
        scale,
        device_origin: x0,
        ..HapticConfig::default()
    };
    for rate in RATES {
        let w = run(wall_world(rate), &coupling(1.0, None), rate, true);
        println!("wall {rate} Hz coupling: {w:?}");
        assert!(
            w.stopped.is_none() && w.late_x_pp < 1e-5,
            "{rate} Hz: {w:?}"
        );
        if rate >= 1000.0 {
            let c = run(channel_world(rate), &coupling(2.0, x0), rate, false);
            println!("channel {rate} Hz coupling: {c:?}");
            assert!(
                c.stopped.is_none() && c.max_abs_y < 5e-4 && c.max_dx < 1e-2,
                "{rate} Hz: {c:?}"
            );
        }
    }
}

/// A controller of the 1-DOF loop: the four-channel (any gains) or the virtual coupling.
#[derive(Clone, Copy, Debug)]
#[allow(clippy::large_enum_variant)]
enum OneDofController {
    FourChannel(FourChannelGains),
    Coupling,
}

/// The 1-DOF situations: the spec device's x axis pushed into a one-sided wall, or its y axis at
/// world scale 2 with the peg squeezed in its channel (a two-sided spring).
#[derive(Clone, Copy, Debug, PartialEq)]
enum OneDofCase {
    /// The spec device's x axis (0.445 kg, 0.028 N·s/m), the 0.5 kg box on a one-sided 2000 N/m wall
    /// at x = 0; the handle pushed toward the wall by a force rising smoothly to 2 N over 0.3 s and
    /// then constant (a force source: no hand impedance).
    Wall,
    /// The spec device's y axis in world units at scale 2 (inertia and damping divided by 4:
    /// 0.0613 kg, 0.0037 N·s/m, `haptic2d stability peg-in-hole --scale 2`), the 0.2 kg peg
    /// squeezed between the channel's corner springs (4 × 1000 N/m, two-sided about the centre);
    /// a 0.1 N pulse (raised cosine over 0.3 s) nudges the handle, then nothing touches it.
    Channel,
}

/// The 1-DOF loop of §11.4 in the time domain, with the tick's own pieces: the device integrated
/// exactly under the held command, the 50 Hz velocity filter and a 1-DOF momentum observer
/// (`K_O = 60 1/s`), the controller of `haptic2d::control`, and the slave (semi-implicit Euler) on
/// the case's environment. Returns the slave's x range over the last second and its largest `|x|`
/// after the first 0.3 s (both infinite if a value became non-finite; the range is infinite if the
/// box lost the wall).
fn one_dof(ctrl: OneDofController, case: OneDofCase, rate: f64) -> (f64, f64) {
    use haptic2d::control::coupling::VirtualCoupling;
    use haptic2d::control::four_channel::{FourChannel, TeleopSignals};
    use haptic2d::device::filter::VelocityFilter;
    let (m, b, m_s, k_e) = match case {
        OneDofCase::Wall => (0.445, 0.028, 0.5, 2000.0),
        OneDofCase::Channel => (0.0613, 0.0037, 0.2, 4000.0),
    };
    let k_o = 60.0;
    let dt = 1.0 / rate;
    let mut four = match ctrl {
        OneDofController::FourChannel(g) => Some(FourChannel::new(g, dt).expect("gains")),
        OneDofController::Coupling => None,
    };
    let mut coupling = VirtualCoupling::new(CouplingGains::default()).expect("gains");
    let mut filter = VelocityFilter::new(50.0, dt);
    let (mut x_m, mut v_m, mut x_s, mut v_s) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut p0, mut integral, mut r, mut u_prev, mut v_prev) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let n = (SECONDS * rate) as usize;
    let (mut lo, mut hi, mut max_abs) = (f64::MAX, f64::MIN, 0.0f64);
    for k in 0..n {
        let t = k as f64 * dt;
        let rise = 1.0 - (std::f64::consts::PI * t.min(0.3) / 0.3).cos(); // 0 → 2 over 0.3 s
        let push = match case {
            OneDofCase::Wall => rise,
            OneDofCase::Channel if t < 0.3 => {
                0.05 * (1.0 - (2.0 * std::f64::consts::PI * t / 0.3).cos())
            }
            OneDofCase::Channel => 0.0,
        };
        let v_hat = filter.update(&[x_m, 0.0, 0.0])[0];
        let p = m * v_hat;
        if k == 0 {
            p0 = p;
        } else {
            integral += dt * (u_prev - b * v_prev + r);
            r = k_o * (p - p0 - integral);
        }
        // The environment's force on the slave; f_e is what the slave applies to it.
        let f_contact = match case {
            OneDofCase::Wall if x_s < 0.0 => -k_e * x_s,
            OneDofCase::Wall => 0.0,
            OneDofCase::Channel => -k_e * x_s,
        };
        let sig = TeleopSignals {
            x_m: [x_m, 0.0, 0.0],
            v_m: [v_hat, 0.0, 0.0],
            f_h: [r, 0.0, 0.0],
            x_s: [x_s, 0.0, 0.0],
            v_s: [v_s, 0.0, 0.0],
            f_e: [-f_contact, 0.0, 0.0],
            ..Default::default()
        };
        let (f_cm, f_cs) = match four.as_mut() {
            Some(c) => c.step(&sig),
            None => coupling.step(&sig),
        };
        v_s += dt * (f_cs[0] + f_contact) / m_s;
        x_s += dt * v_s;
        // Device under the held force u = f_cm − push: m·v̇ = u − b·v, exactly over dt.
        let u = f_cm[0] - push;
        let decay = (-b * dt / m).exp();
        let v_inf = u / b;
        x_m += v_inf * dt + (v_m - v_inf) * (m / b) * (1.0 - decay);
        v_m = v_inf + (v_m - v_inf) * decay;
        u_prev = f_cm[0];
        v_prev = v_hat;
        if !(x_s.is_finite() && x_m.is_finite()) {
            return (f64::INFINITY, f64::INFINITY);
        }
        if t > 0.3 {
            if case == OneDofCase::Wall && x_s > 0.0 {
                return (f64::INFINITY, max_abs);
            }
            max_abs = max_abs.max(x_s.abs());
        }
        if k + rate as usize >= n {
            lo = lo.min(x_s);
            hi = hi.max(x_s);
        }
    }
    (hi - lo, max_abs)
}

/// The 1-DOF released-handle regression against the wall at 0.5, 1, 2 and 10 kHz: each default
/// configuration (the four-channel default and the virtual coupling) settles on the wall (x range
/// over the last second below 1 µm); the §11.1 table loses the contact (the slave is thrown off the
/// wall by the growing oscillation, §11.4: `+2.5 ± 67j`) or keeps oscillating above 0.1 mm.
#[test]
fn released_handle_one_dof_default_settles_spec_grows() {
    for rate in RATES {
        for (name, ctrl) in [
            (
                "default",
                OneDofController::FourChannel(FourChannelGains::default()),
            ),
            ("coupling", OneDofController::Coupling),
        ] {
            let (ok, _) = one_dof(ctrl, OneDofCase::Wall, rate);
            println!("1-DOF wall {rate} Hz: {name} late range {ok:e} m");
            assert!(ok < 1e-6, "{rate} Hz {name}: {ok:e}");
        }
        let (bad, _) = one_dof(
            OneDofController::FourChannel(FourChannelGains::spec()),
            OneDofCase::Wall,
            rate,
        );
        println!("1-DOF wall {rate} Hz: spec late range {bad:e} m");
        assert!(bad > 1e-4, "{rate} Hz spec: {bad:e}");
    }
}

/// The 1-DOF released-handle regression inside the peg's channel (the y axis at scale 2) at 0.5, 1,
/// 2 and 10 kHz — in 1-DOF the 500 Hz case runs too (the 3-DOF loop refuses it for the θ axis'
/// minimum mass): after the nudge the handle is free; each default configuration stays within
/// 0.5 mm (the interference is 1 mm) and comes to rest (x range over the last second below 1 µm);
/// the §11.1 table grows (§11.4: `+38 ± 201j` for these numbers) past 0.5 mm.
#[test]
fn released_handle_one_dof_channel_default_settles_spec_grows() {
    for rate in RATES {
        for (name, ctrl) in [
            (
                "default",
                OneDofController::FourChannel(FourChannelGains::default()),
            ),
            ("coupling", OneDofController::Coupling),
        ] {
            let (late, max_abs) = one_dof(ctrl, OneDofCase::Channel, rate);
            println!(
                "1-DOF channel {rate} Hz: {name} late range {late:e} m, max |y| {max_abs:e} m"
            );
            assert!(
                late < 1e-6 && max_abs < 5e-4,
                "{rate} Hz {name}: {late:e}, {max_abs:e}"
            );
        }
        let (late, max_abs) = one_dof(
            OneDofController::FourChannel(FourChannelGains::spec()),
            OneDofCase::Channel,
            rate,
        );
        println!("1-DOF channel {rate} Hz: spec late range {late:e} m, max |y| {max_abs:e} m");
        assert!(max_abs > 5e-4, "{rate} Hz spec: {late:e}, {max_abs:e}");
    }
}
