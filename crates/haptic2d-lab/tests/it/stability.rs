//! The loop stability analysis (`haptic2d_lab::stability`, issue 11, spec §11.4): the §11.4
//! polynomial cross-check, and the predicted sampled-data growth rate against the full simulated
//! 3-DOF loop (`HapticSystem` + simulated twin pantograph).

use haptic2d::control::four_channel::FourChannelGains;
use haptic2d::device::{DeviceParams, HandModel};
use haptic2d::haptic::{ControllerKind, DeviceInTheLoop, HapticConfig, HapticSystem, SafetyConfig};
use haptic2d::scene::{Scene, BUILTIN};
use haptic2d::world::World;
use haptic2d_lab::stability::eig::{eigenvalues, poly_roots, Complex};
use haptic2d_lab::stability::{analyse_config, AxisController, AxisModel, LoopModel, Verdict};

fn spec_axis(m: f64, b: f64, m_s: f64, k_e: f64) -> AxisModel {
    AxisModel {
        m,
        b,
        k_h: 0.0,
        b_h: 0.0,
        m_s,
        k_e,
        b_e: 0.0,
        ctrl: AxisController {
            k_m: 500.0,
            b_m: 5.0,
            k_s: 2000.0,
            b_s: 30.0,
            g_mh: 0.0,
            g_me: -1.0,
            g_sh: 1.0,
            g_se: 0.0,
            d_m: 0.0,
            d_s: 0.0,
        },
        k_o: 60.0,
        velocity_cutoff_hz: 50.0,
    }
}

fn has_root(roots: &[Complex], re: f64, im: f64, tol_re: f64, tol_im: f64) -> bool {
    roots
        .iter()
        .any(|r| (r.0 - re).abs() <= tol_re && (r.1.abs() - im).abs() <= tol_im)
}

/// §11.4: the released polynomial's roots for the spec numbers are about `+2.4 ± 67j` (spec device
/// on the Fig. 4 box: m ≈ 0.445 kg, b ≈ 0.028 N·s/m, K_e = 2000 N/m, M_s = 0.5 kg) and `+30 ± 185j`
/// (the peg's y axis at world scale 2: m = 0.33/4 kg, peg 0.2 kg, K_e = 4000 N/m), and the
/// continuous state matrix of the model has the same poles (with `C6 = 0` the observer decouples).
#[test]
fn released_polynomial_matches_section_11_4_and_the_state_matrix() {
    for (a, re, im) in [
        (spec_axis(0.445, 0.028, 0.5, 2000.0), 2.4, 67.0),
        (spec_axis(0.33 / 4.0, 0.028 / 4.0, 0.2, 4000.0), 30.0, 185.0),
    ] {
        let roots = poly_roots(&a.released_polynomial()).unwrap();
        println!("§11.4 roots {roots:?}");
        assert!(has_root(&roots, re, im, 0.5 + 0.03 * re, 2.0), "{roots:?}");
        let poles = eigenvalues(&a.continuous()).unwrap();
        for r in &roots {
            assert!(
                has_root(
                    &poles,
                    r.0,
                    r.1.abs(),
                    1e-6 * r.1.abs().max(1.0),
                    1e-6 * r.1.abs().max(1.0)
                ),
                "root {r:?} not among the state-matrix poles {poles:?}"
            );
        }
        assert!(
            has_root(&poles, -60.0, 0.0, 1e-9, 1e-9),
            "observer pole −K_O"
        );
    }
}

/// §11.4: the spec device's x axis is stable released only above b ≈ 2.65 N·s/m.
#[test]
fn spec_device_needs_about_2_65_n_s_per_m_of_damping() {
    let max_re = |b: f64| {
        poly_roots(&spec_axis(0.445, b, 0.5, 2000.0).released_polynomial())
            .unwrap()
            .iter()
            .map(|r| r.0)
            .fold(f64::MIN, f64::max)
    };
    assert!(
        max_re(2.4) > 0.0 && max_re(2.9) < 0.0,
        "{} {}",
        max_re(2.4),
        max_re(2.9)
    );
}

/// As the period goes to zero the sampled-data growth rate tends to the right-most continuous pole.
/// The continuous model is the ideal loop (`v̂ = v`); the tick's velocity filter is a 50 Hz low-pass
/// whatever the rate, so the limit is taken with its cut-off far above the loop's modes (1 MHz).
#[test]
fn sampled_growth_tends_to_the_continuous_pole() {
    let a = AxisModel {
        velocity_cutoff_hz: 1e6,
        ..spec_axis(0.445, 0.028, 0.5, 2000.0)
    };
    let sigma = eigenvalues(&a.continuous())
        .unwrap()
        .iter()
        .map(|p| p.0)
        .fold(f64::MIN, f64::max);
    let growth = |rate: f64| {
        let ev = eigenvalues(&a.discrete(1.0 / rate, 0)).unwrap();
        ev.iter().map(|e| e.0.hypot(e.1)).fold(0.0, f64::max).ln() * rate
    };
    let (g1, g2) = (growth(1e4), growth(1e5));
    println!("continuous {sigma:.3}, sampled 10 kHz {g1:.3}, 100 kHz {g2:.3}");
    assert!((g2 - sigma).abs() < (g1 - sigma).abs() + 1e-9);
    assert!((g2 - sigma).abs() < 0.5, "{g2} vs {sigma}");
}

/// Box-in-walls with a pure ZOH stiffness wall (2 × 1000 N/m, no damping), impacts off, the box
/// starting with its face on the left wall.
fn box_on_wall(rate: f64) -> World {
    let text = BUILTIN.iter().find(|b| b.0 == "box-in-walls").unwrap().2;
    let start = text.find("[normal]").unwrap();
    let end = text.find("[friction]").unwrap();
    let t = format!(
        "{}[normal]\nmodel = \"zoh\"\n\n{}",
        &text[..start],
        &text[end..]
    )
    .replace("impacts = true", "impacts = false")
    .replace("position = [0.04, 0.0]", "position = [0.02, 0.0]");
    Scene::from_toml(&t, "box-on-wall", Some(rate))
        .unwrap()
        .world
}

/// Duration of the push's smooth rise (s).
const RAMP: f64 = 0.3;

fn linear_device() -> DeviceParams {
    DeviceParams {
        f_c: 0.0,
        ..DeviceParams::default()
    }
}

/// Runs the full loop with a push on the handle that rises smoothly to 2 N over `RAMP` s and then stays
/// constant (a force source: the released dynamics, with the observer and the contact brought to
/// their operating point without a kick), and returns the slave's x per tick, relative to its
/// quasi-static equilibrium (1 mm into the wall at 2 N), until `seconds` or until the deviation exceeds `limit` (still linear: the box keeps
/// its contact).
fn simulate_x(config: &HapticConfig, rate: f64, seconds: f64, limit: f64) -> Vec<f64> {
    // The start-up torque ramp is off: the linear model is of the loop at full gain, and the
    // spec configuration's growth is fitted from 0.1 s, inside the default 0.5 s ramp.
    let safety = SafetyConfig {
        ramp_time: 0.0,
        ..SafetyConfig::default()
    };
    let sys = HapticSystem::with_safety(box_on_wall(rate), config, safety).unwrap();
    let mut l = DeviceInTheLoop::new(sys, HandModel::Free, 10, false).unwrap();
    let n = (seconds * rate) as usize;
    let mut xs = Vec::with_capacity(n);
    for k in 0..n {
        let t = k as f64 / rate;
        let f = if t < RAMP {
            1.0 - (std::f64::consts::PI * t / RAMP).cos()
        } else {
            2.0
        };
        l.hand = HandModel::Constant {
            wrench: [-f, 0.0, 0.0],
        };
        let o = l.step().unwrap();
        assert!(!o.tripped, "{:?}", l.system.safety_trip());
        // Deviation from the quasi-static equilibrium: the face f/(2000 N/m) into the wall.
        let d = o.record.x_s[0] - (0.02 - f / 2000.0);
        xs.push(d);
        if d.abs() > limit {
            break;
        }
    }
    xs
}

/// Growth rate of an oscillation (1/s): least-squares slope of ln|peak| against time over the
/// positive and negative peaks between `t0` and the end, about the window's mean.
fn envelope_growth(x: &[f64], dt: f64, t0: f64) -> f64 {
    let k0 = (t0 / dt) as usize;
    let w = &x[k0..];
    let mean = w.iter().sum::<f64>() / w.len() as f64;
    let d: Vec<f64> = w.iter().map(|v| v - mean).collect();
    let mut pts = Vec::new();
    for k in 1..d.len() - 1 {
        let (a, b, c) = (d[k - 1].abs(), d[k].abs(), d[k + 1].abs());
        if b > a && b >= c && d[k - 1].signum() == d[k].signum() {
            pts.push(((k0 + k) as f64 * dt, b.ln()));
        }
    }
    let n = pts.len() as f64;
    let (st, sy) = pts.iter().fold((0.0, 0.0), |s, p| (s.0 + p.0, s.1 + p.1));
    let (mt, my) = (st / n, sy / n);
    let (num, den) = pts.iter().fold((0.0, 0.0), |s, p| {
        (s.0 + (p.0 - mt) * (p.1 - my), s.1 + (p.0 - mt).powi(2))
    });
    num / den
}

/// The predicted growth rate of the x axis matches the simulated one, for the spec configuration
/// (growing, fitted from 0.1 s: the growing mode dominates the forced response of the ramp) and for
/// the former default (decaying, fitted after the ramp), at 1 kHz; for the default (issue 36) the
/// model is optimistic, pinned below.
///
/// Tolerance 15 % of the predicted rate (at least 1 1/s): the per-axis model is linear and 1-DOF —
/// it leaves out the device's geometric nonlinearity, its small inertial couplings between axes, and
/// the rotation of the box on its two corner contacts — and the envelope is fitted to sampled peaks.
#[test]
fn predicted_growth_rate_matches_the_simulated_loop() {
    let rate = 1000.0;
    for (name, gains, t0, seconds) in [
        ("spec", FourChannelGains::spec(), 0.1, 3.0),
        (
            "former default",
            FourChannelGains::master_force_feedback(),
            RAMP + 0.05,
            2.0,
        ),
        ("default", FourChannelGains::default(), RAMP + 0.05, 2.0),
    ] {
        let config = HapticConfig {
            device: linear_device(),
            controller: ControllerKind::FourChannel(gains),
            ..HapticConfig::default()
        };
        let report = analyse_config(&config, &box_on_wall(rate), rate, 0, name).unwrap();
        // The x axis against the normal law: the box's face on the wall.
        let model = LoopModel::new(&config, &box_on_wall(rate), rate, 0).unwrap();
        let a = model.axes[0].released();
        let ev = eigenvalues(&a.discrete(1.0 / rate, 0)).unwrap();
        let predicted = ev.iter().map(|e| e.0.hypot(e.1)).fold(0.0, f64::max).ln() * rate;
        assert_eq!(report.axes[0].contact, "normal");
        let x = simulate_x(&config, rate, seconds, 9e-4);
        let simulated = envelope_growth(&x, 1.0 / rate, t0);
        println!(
            "{name}: predicted x growth {predicted:+.2} 1/s, simulated {simulated:+.2} 1/s ({} ticks)",
            x.len()
        );
        let tol = (0.15 * predicted.abs()).max(1.0);
        if name == "default" {
            // Issue 36's default (C5 = 2) is where the 1-DOF model is optimistic: it decays at
            // 2.7 1/s in the 3-DOF simulation against 4.6 predicted (the slave is driven by
            // 3 × the 3-DOF hand-force estimate, whose cross-axis errors the model leaves out; the
            // θ gains are not the cause: the §11.1 θ gains give the same 2.7). Pinned: it still
            // decays faster than the 2 1/s margin of the verdict "stable".
            assert!(
                simulated <= -2.0 && simulated > predicted,
                "{name}: simulated {simulated} vs predicted {predicted}"
            );
            continue;
        }
        assert!(
            (simulated - predicted).abs() <= tol,
            "{name}: simulated {simulated} vs predicted {predicted}"
        );
    }
}

/// The analysis's verdicts for the built-in scenes: the default configuration is stable on every axis,
/// held and released, at 0.5, 1, 2 and 10 kHz (box-in-walls) and 1, 2, 10 kHz (peg-in-hole at scale
/// 2; at 500 Hz the peg is below the θ minimum mass), with one sample of output delay; the spec's
/// configuration is unstable released on some axis in every case.
#[test]
fn default_configuration_is_stable_released_and_the_spec_is_not() {
    let world = |name: &str, rate: f64| {
        let t = BUILTIN.iter().find(|b| b.0 == name).unwrap().2;
        Scene::from_toml(t, name, Some(rate)).unwrap().world
    };
    for (scene, scale, x0, rates) in [
        (
            "box-in-walls",
            1.0,
            None,
            vec![500.0, 1000.0, 2000.0, 10000.0],
        ),
        (
            "peg-in-hole",
            2.0,
            Some([-0.03, 0.14, 0.0]),
            vec![1000.0, 2000.0, 10000.0],
        ),
    ] {
        for rate in rates {
            for (name, gains) in [
                ("four-channel", FourChannelGains::default()),
                ("four-channel-spec", FourChannelGains::spec()),
            ] {
                let cfg = HapticConfig {
                    controller: ControllerKind::FourChannel(gains),
                    scale,
                    device_origin: x0,
                    ..HapticConfig::default()
                };
                let r = analyse_config(&cfg, &world(scene, rate), rate, 1, name).unwrap();
                let verdicts: Vec<Verdict> = r.axes.iter().map(|a| a.verdict()).collect();
                println!("{scene} {rate} Hz {name}: {verdicts:?}");
                if name == "four-channel" {
                    assert!(
                        verdicts.iter().all(|v| *v == Verdict::Stable),
                        "{}",
                        r.text()
                    );
                } else {
                    assert!(
                        verdicts.contains(&Verdict::UnstableReleased),
                        "{}",
                        r.text()
                    );
                }
            }
        }
    }
}

/// The gate `run` applies before a real device: the spec table is refused with the axis and the fix
/// named; the default and the virtual coupling pass.
#[test]
fn check_released_stability_refuses_the_spec_table_and_names_the_axis_and_fix() {
    use haptic2d_lab::stability::check_released_stability;
    let text = BUILTIN.iter().find(|b| b.0 == "box-in-walls").unwrap().2;
    let world = Scene::from_toml(text, "box-in-walls", Some(1000.0))
        .unwrap()
        .world;
    let spec = HapticConfig {
        controller: ControllerKind::FourChannel(FourChannelGains::spec()),
        ..HapticConfig::default()
    };
    let e = check_released_stability(&spec, &world).unwrap_err();
    println!("{e}");
    assert!(e.contains("axis x") || e.contains("axis y"), "{e}");
    assert!(e.contains("--controller four-channel"), "{e}");
    assert!(e.contains("--allow-unstable"), "{e}");
    assert!(check_released_stability(&HapticConfig::default(), &world).is_ok());
    let coupling = HapticConfig {
        controller: ControllerKind::from_name("coupling").unwrap(),
        ..HapticConfig::default()
    };
    assert!(check_released_stability(&coupling, &world).is_ok());
}

/// Issue 36: the default of `run` and `reproduce` is stable with margin (decay ≥ 2 1/s, the verdict
/// "stable") held and released on every axis of every built-in scene (the peg also at the mapping
/// scale 2 of Figs. 8–11) at 0.5, 1 and 2 kHz, with and without the one-sample output delay, and
/// every scene accepts its slave coupling (§6.4 minimum mass); the paper's §11.1 table is not.
#[test]
fn default_is_stable_with_margin_held_and_released_on_every_builtin_scene() {
    use haptic2d_lab::design::{margin, study_cases};
    let cases = study_cases().unwrap();
    assert_eq!(cases.len(), 15);
    let m = margin(&ControllerKind::default(), &cases).unwrap();
    println!("default: {m:?}");
    assert!(m.stable_with_margin(), "{m:?}");
    assert!(m.held >= 2.0 && m.released >= 2.0, "{m:?}");
    let spec = margin(
        &ControllerKind::FourChannel(FourChannelGains::spec()),
        &cases,
    )
    .unwrap();
    println!("spec: {spec:?}");
    assert!(spec.released < 0.0, "{spec:?}");
}
