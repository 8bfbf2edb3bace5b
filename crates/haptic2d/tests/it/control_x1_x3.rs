//! Checkable behaviour of the teleoperation controllers, spec §11.3 (X1–X3), in the 1-DOF reference
//! setup: device 0.3 kg + 0.5 N·s/m, rigidly held by a hand of 0.4 kg + 4 N·s/m that pushes with a
//! constant 2 N toward a virtual wall (`K_e = 2000 N/m`, `B_e = 5 N·s/m`, surface at x = 0) at the slave
//! (0.5 kg, semi-implicit Euler); `T = 2 ms`, 4 s. The device + hand is a continuous plant integrated
//! exactly under the zero-order-held command `f_cm`. The controllers run on 3-vectors; only x is used.
//! The §11.3 references are for the §11.1 table ([`FourChannelGains::spec`]); the default
//! configuration (local force feedback `C6 = −1`, damping injection) is checked by
//! `x1_x3_default_configuration`.
//!
//! The device velocity is estimated by the §10.7 filter. The hand-force signal `f_h` fed to the
//! four-channel controller is selectable ([`HandForce`]):
//!
//! - `Applied`: the operator's applied push (the constant 2 N). This reproduces the reference numbers of
//!   §11.3 (device and slave at −1.000 mm, sub-µm oscillation) and is used for X1–X3.
//! - `Observer`: a 1-DOF generalized-momentum observer (§10.6, `K_O = 60 1/s`) on the device alone
//!   (0.3 kg, 0.5 N·s/m). It estimates the *interaction* force `F − m_h·ẍ_m − b_h·v_m`, which contains
//!   the hand's inertial reaction. See `x2_with_observer_estimated_hand_force` for what that does to
//!   the default gains (the spec's X2 claim does not hold there; the mechanics is explained in that test).

use haptic2d::control::coupling::{CouplingGains, VirtualCoupling};
use haptic2d::control::four_channel::{FourChannel, FourChannelGains, TeleopSignals};
use haptic2d::device::filter::VelocityFilter;
use haptic2d::device::linalg::V3;

const T: f64 = 0.002;
const M_DEV: f64 = 0.3;
const B_DEV: f64 = 0.5;
const M_HAND: f64 = 0.4;
const B_HAND: f64 = 4.0;
const F_PUSH: f64 = -2.0; // toward the wall at x = 0 (the free side is x > 0)
const K_E: f64 = 2000.0;
const B_E: f64 = 5.0;
const M_S: f64 = 0.5;
const K_O: f64 = 60.0;
const DURATION: f64 = 4.0;

/// Either architecture behind one call.
#[allow(clippy::large_enum_variant)]
enum Controller {
    FourChannel(FourChannel),
    Coupling(VirtualCoupling),
}

impl Controller {
    fn step(&mut self, s: &TeleopSignals) -> (V3, V3) {
        match self {
            Controller::FourChannel(c) => c.step(s),
            Controller::Coupling(c) => c.step(s),
        }
    }
}

/// What one run produces: per-sample device and slave positions, `f_cm` and `f_e` (x components).
struct Trace {
    x_m: Vec<f64>,
    x_s: Vec<f64>,
    f_cm: Vec<f64>,
    f_e: Vec<f64>,
}

/// Exact solution of `m·v̇ = F − b·v` over `dt` with `F` held: returns `(x(dt), v(dt))`.
fn zoh_step(x: f64, v: f64, f: f64, m: f64, b: f64, dt: f64) -> (f64, f64) {
    let v_inf = f / b;
    let decay = (-b * dt / m).exp();
    let v1 = v_inf + (v - v_inf) * decay;
    let x1 = x + v_inf * dt + (v - v_inf) * (m / b) * (1.0 - decay);
    (x1, v1)
}

/// Which hand-force signal the controller receives.
#[derive(Clone, Copy, Debug, PartialEq)]
enum HandForce {
    /// The operator's applied force (the constant push).
    Applied,
    /// The momentum-observer estimate of the hand–device interaction force.
    Observer,
}

fn run(ctrl: Controller, hand: HandForce) -> Trace {
    run_released_at(ctrl, hand, f64::INFINITY, DURATION)
}

/// [`run`] for `duration` (s), with the hand let go at `t_release` (s): from then on the plant is the device alone
/// (0.3 kg, 0.5 N·s/m), nothing pushes it, and the hand-force signal is zero (`Applied`) or the
/// observer's estimate of a zero interaction force (`Observer`).
fn run_released_at(mut ctrl: Controller, hand: HandForce, t_release: f64, duration: f64) -> Trace {
    // Start 3 mm from the wall, at rest; the slave starts on the device.
    let (mut x_m, mut v_m) = (0.003, 0.0);
    let (mut x_s, mut v_s) = (0.003, 0.0);
    let mut filter = VelocityFilter::new(50.0, T);
    // 1-DOF momentum observer state.
    let (mut p0, mut integral, mut r) = (0.0, 0.0, 0.0);
    let (mut f_cm_prev, mut v_hat_prev) = (0.0, 0.0);
    let n = (duration / T).round() as usize;
    let mut tr = Trace {
        x_m: Vec::with_capacity(n),
        x_s: Vec::with_capacity(n),
        f_cm: Vec::with_capacity(n),
        f_e: Vec::with_capacity(n),
    };
    for k in 0..n {
        let held = (k as f64) * T < t_release;
        let (m_tot, b_tot, push) = if held {
            (M_DEV + M_HAND, B_DEV + B_HAND, F_PUSH)
        } else {
            (M_DEV, B_DEV, 0.0)
        };
        // 1. Sense the device; filtered velocity.
        let v_hat = filter.update(&[x_m, 0.0, 0.0])[0];
        // 2. Hand-force estimate: r_k = K_O·(p_k − p_0 − Σ T·(f_cm,j−1 − b·v̂_j−1 + r_j−1)).
        let p = M_DEV * v_hat;
        if k == 0 {
            p0 = p;
        } else {
            integral += T * (f_cm_prev - B_DEV * v_hat_prev + r);
            r = K_O * (p - p0 - integral);
        }
        // 6. Wall force on the slave; f_e is what the slave applies to the environment.
        let f_contact = if x_s < 0.0 {
            (K_E * (-x_s) - B_E * v_s).max(0.0)
        } else {
            0.0
        };
        let f_e = -f_contact;
        // 7. Controller.
        let sig = TeleopSignals {
            x_m: [x_m, 0.0, 0.0],
            v_m: [v_hat, 0.0, 0.0],
            f_h: [
                match hand {
                    HandForce::Applied => push,
                    HandForce::Observer => r,
                },
                0.0,
                0.0,
            ],
            x_s: [x_s, 0.0, 0.0],
            v_s: [v_s, 0.0, 0.0],
            f_e: [f_e, 0.0, 0.0],
            ..Default::default()
        };
        let (f_cm, f_cs) = ctrl.step(&sig);
        tr.x_m.push(x_m);
        tr.x_s.push(x_s);
        tr.f_cm.push(f_cm[0]);
        tr.f_e.push(f_e);
        // 10. Slave: semi-implicit Euler.
        v_s += T * (f_cs[0] - f_e) / M_S;
        x_s += T * v_s;
        // Device + hand: continuous plant, f_cm held over the period.
        (x_m, v_m) = zoh_step(x_m, v_m, push + f_cm[0], m_tot, b_tot, T);
        f_cm_prev = f_cm[0];
        v_hat_prev = v_hat;
    }
    tr
}

fn four_channel(k_m: f64) -> Controller {
    four_channel_with(k_m, false)
}

fn four_channel_with(k_m: f64, slave_feedforward: bool) -> Controller {
    let gains = FourChannelGains {
        k_m: [k_m, k_m, 1.0],
        slave_feedforward,
        ..FourChannelGains::spec()
    };
    gains
        .check_slave_mass(&[M_S, M_S, 1e-4], T)
        .expect("slave heavier than 1.5 min_mass");
    Controller::FourChannel(FourChannel::new(gains, T).expect("valid gains"))
}

fn coupling(k_vc: f64) -> Controller {
    let gains = CouplingGains {
        k: [k_vc, k_vc, 1.0],
        ..CouplingGains::default()
    };
    Controller::Coupling(VirtualCoupling::new(gains).expect("valid gains"))
}

/// Peak-to-peak of a series over `[t0, t0 + 1 s)`.
fn window_pp(v: &[f64], t0: f64) -> f64 {
    let i0 = (t0 / T).round() as usize;
    let tail = &v[i0..(i0 + (1.0 / T) as usize).min(v.len())];
    let max = tail.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = tail.iter().copied().fold(f64::INFINITY, f64::min);
    max - min
}

#[test]
fn x1_transparency_four_channel() {
    let tr = run(four_channel(500.0), HandForce::Applied);
    let (xm, xs) = (
        *tr.x_m.last().unwrap_or(&0.0),
        *tr.x_s.last().unwrap_or(&0.0),
    );
    let k_hat = 2.0 / (-xm);
    println!(
        "X1 four-channel: device {:.4} mm, slave {:.4} mm, k_hat = {k_hat:.1} N/m (K_e = {K_E})",
        xm * 1e3,
        xs * 1e3
    );
    assert!((k_hat - K_E).abs() <= 0.1 * K_E, "k_hat = {k_hat}");
    assert!(
        (xs - xm).abs() < 1e-5,
        "device and slave coincide in steady contact"
    );
}

#[test]
fn x1_transparency_virtual_coupling() {
    let k_vc = 500.0;
    let tr = run(coupling(k_vc), HandForce::Applied);
    let (xm, xs) = (
        *tr.x_m.last().unwrap_or(&0.0),
        *tr.x_s.last().unwrap_or(&0.0),
    );
    let k_hat = 2.0 / (-xm);
    let k_series = K_E * k_vc / (K_E + k_vc);
    println!(
        "X1 virtual coupling: device {:.4} mm, slave {:.4} mm, k_hat = {k_hat:.1} N/m (series {k_series})",
        xm * 1e3,
        xs * 1e3
    );
    assert!(
        (k_hat - k_series).abs() <= 0.1 * k_series,
        "k_hat = {k_hat}"
    );
}

#[test]
fn x2_stability() {
    for (name, ctrl) in [
        ("four-channel, K_m = 500", four_channel(500.0)),
        ("four-channel, K_m = 2000", four_channel(2000.0)),
        ("virtual coupling, K_vc = 500", coupling(500.0)),
        ("virtual coupling, K_vc = 2000", coupling(2000.0)),
    ] {
        let tr = run(ctrl, HandForce::Applied);
        let pp = window_pp(&tr.x_m, DURATION - 1.0);
        println!("X2 {name}: device peak-to-peak over the last 1 s = {pp:.3e} m");
        assert!(pp < 1e-5, "{name}: p-p {pp:e} m");
        assert!(tr.x_m.iter().all(|x| x.is_finite() && x.abs() < 0.05));
    }
}

#[test]
fn x3_force_tracking() {
    let tr = run(four_channel(500.0), HandForce::Applied);
    let (f_cm, f_e) = (
        *tr.f_cm.last().unwrap_or(&0.0),
        *tr.f_e.last().unwrap_or(&0.0),
    );
    let rel = (f_cm + f_e).abs() / f_e.abs();
    println!("X3: f_cm = {f_cm:.5} N, f_e = {f_e:.5} N, |f_cm + f_e|/|f_e| = {rel:.2e}");
    assert!(f_e < -1.9, "steady contact reached (f_e = {f_e})");
    assert!(rel < 0.01);
}

/// X2 with the hand force *estimated* by the device-only momentum observer (spec-faithful §10.6 signal).
///
/// Finding (mechanics, not a code defect): the observer estimates the interaction force
/// `f_h = F − m_h·ẍ_m − b_h·v_m`. Substituting the device equation `f_h = m_d·ẍ_m + b_d·v_m − f_cm` into
/// the slave equation `M_s·ẍ_s = K_s(x_m − x_s) + B_s(v_m − v_s) + f_h − f_e` with the default
/// `f_cm = K_m(x_s − x_m) + B_m(v_s − v_m) − f_e` makes `f_e` cancel:
/// `M_s·ẍ_s = (K_s + K_m)(x_m − x_s) + (B_s + B_m)(v_m − v_s) + m_d·ẍ_m + b_d·v_m`. The slave no longer
/// sees the wall directly; the wall acts only through the device (hand + device, 0.7 kg, against
/// `K_e = 2000 N/m`, physical damping 4.5 + `B_e` 5 N·s/m), and the master–slave error mode is driven by
/// `(M_s − m_d)·ẍ_m`. With `K_m = 500` the sampled loop (velocity-filter and observer lag) leaves a
/// very lightly damped ~7 Hz contact mode: after 4 s the device still oscillates with ≈ 1 mm p-p
/// (decaying), so `k̂` is not yet settled. Raising `K_m` to 2000 N/m, or enabling the slave-mass
/// feedforward `M_s·â_m` (the `Z_s` part of `C1 = Z_s + C_s`), restores a well-damped loop; so does
/// feeding the operator's applied force (as the reference prototype evidently did). The virtual
/// coupling does not use `f_h` and is unaffected.
#[test]
fn x2_with_observer_estimated_hand_force() {
    for (name, ctrl) in [
        ("four-channel, K_m = 2000", four_channel(2000.0)),
        (
            "four-channel, K_m = 500, slave feedforward",
            four_channel_with(500.0, true),
        ),
        ("virtual coupling, K_vc = 500", coupling(500.0)),
        ("virtual coupling, K_vc = 2000", coupling(2000.0)),
    ] {
        let tr = run(ctrl, HandForce::Observer);
        let pp = window_pp(&tr.x_m, DURATION - 1.0);
        let xm = tr.x_m.last().copied().unwrap_or(0.0);
        println!(
            "X2 (observer f_h) {name}: device {:.4} mm, p-p over the last 1 s = {pp:.3e} m",
            xm * 1e3
        );
        assert!(pp < 1e-5, "{name}: p-p {pp:e} m");
    }
    // Defaults (K_m = 500, no feedforward): lightly damped but decaying, not unstable.
    let tr = run(four_channel(500.0), HandForce::Observer);
    let early = window_pp(&tr.x_m, 1.0);
    let late = window_pp(&tr.x_m, DURATION - 1.0);
    let xm = tr.x_m.last().copied().unwrap_or(0.0);
    println!(
        "X2 (observer f_h) four-channel defaults: device {:.4} mm at 4 s, p-p in [1, 2) s = {early:.3e} m, in [3, 4) s = {late:.3e} m (spec claims < 1e-5)",
        xm * 1e3
    );
    assert!(late < early, "the contact oscillation decays");
    assert!(
        late > 1e-5,
        "documents the lightly damped mode; if this fails, the loop improved"
    );
}

/// X1 and X3 (and X2 at the default `K_m`) for the default configuration, local force feedback
/// `C6 = −1` plus damping injection (§11.4): in steady contact the master cancels the hand force and
/// the slave carries it (`f_e = f_h`, `x_s = x_m`), so the perceived stiffness is still `K_e` and
/// `f_cm = −f_h`, of the magnitude of `f_e` (the injection adds nothing at rest).
#[test]
fn x1_x3_default_configuration() {
    let gains = FourChannelGains::default();
    assert_eq!(gains.c6, [-1.0; 3]);
    let tr = run(
        Controller::FourChannel(FourChannel::new(gains, T).expect("valid gains")),
        HandForce::Applied,
    );
    let (xm, xs) = (
        *tr.x_m.last().unwrap_or(&0.0),
        *tr.x_s.last().unwrap_or(&0.0),
    );
    let k_hat = 2.0 / (-xm);
    println!(
        "X1 default four-channel: device {:.4} mm, slave {:.4} mm, k_hat = {k_hat:.1} N/m",
        xm * 1e3,
        xs * 1e3
    );
    assert!((k_hat - K_E).abs() <= 0.1 * K_E, "k_hat = {k_hat}");
    let pp = window_pp(&tr.x_m, DURATION - 1.0);
    println!("X2 default four-channel: device p-p over the last 1 s = {pp:.3e} m");
    assert!(pp < 1e-5, "p-p {pp:e} m");
    let (f_cm, f_e) = (
        *tr.f_cm.last().unwrap_or(&0.0),
        *tr.f_e.last().unwrap_or(&0.0),
    );
    // With C6 = −1 the device command is −f_h (the hand push is 2 N): |f_cm| = |f_e| in steady contact.
    let rel = (f_cm.abs() - f_e.abs()).abs() / f_e.abs();
    println!("X3 default four-channel: f_cm = {f_cm:.5} N, f_e = {f_e:.5} N");
    assert!(f_e < -1.9, "steady contact reached (f_e = {f_e})");
    assert!(rel < 0.01, "rel {rel}");
}

/// The default configuration with the gains of [`FourChannelGains::default`] and `K_m` (N/m) on x.
fn default_four_channel(k_m: f64) -> Controller {
    let gains = FourChannelGains {
        k_m: [k_m, k_m, 1.0],
        ..FourChannelGains::default()
    };
    Controller::FourChannel(FourChannel::new(gains, T).expect("valid gains"))
}

/// X2 (§11.3) for the default configuration at `K_m = 2000 N/m`, hand held (the spec's second X2
/// case; the default `K_m` is checked in `x1_x3_default_configuration`).
///
/// Finding: the claim does not hold in its 4 s window. The loop is stable, but its contact mode is
/// slow. With `C6 = −1` the environment force does not reach the master (`C2 = 0`); the linearised
/// held loop (master + hand `m = 0.7 kg`, `b = 4.5 N·s/m`; slave `M_s = 0.5 kg` on `K_s + K_e`,
/// damped by `B_s + B_e`) has the characteristic polynomial
///
/// ```text
/// (m·s² + (b + B_m + D_m)·s + K_m)·(M_s·s² + (B_s + B_e)·s + K_s + K_e) − (B_m·s + K_m)·(B_s·s + K_s)
/// ```
///
/// whose right-most roots are `−5.0 ± 17.8j` at `K_m = 500` but `−1.89 ± 33.5j` at `K_m = 2000`
/// (`B_m = 5`, `D_m = 2`; damping ratio 0.056: `B_m` was sized for `K_m = 500`). From the ≈ 1 mm
/// transient of the first contact, a decay of 1.9 1/s reaches 1e-5 m only after about 4 s, so the
/// last-second window still holds 4e-5 m. (With `D_m = 10` the root is `−6.2 ± 33j`, with `B_m =
/// 20` `−5.3 ± 34j`.) The test pins both: the measured decay rate matches the polynomial's
/// (sampled at 500 Hz behind the velocity filter: within 20 %), and the X2 bound is missed, so a
/// change of defaults that fixes it shows here.
#[test]
fn x2_default_configuration_raised_k_m() {
    const PREDICTED_DECAY: f64 = 1.89; // 1/s, right-most root of the polynomial above
    let tr = run_released_at(
        default_four_channel(2000.0),
        HandForce::Applied,
        f64::INFINITY,
        8.0,
    );
    let pp = window_pp(&tr.x_m, DURATION - 1.0);
    let xm = tr.x_m[(DURATION / T) as usize - 1];
    // Peak-to-peak over successive 1 s windows decays like exp(−σ·t).
    let (a, b) = (window_pp(&tr.x_m, 3.0), window_pp(&tr.x_m, 7.0));
    let sigma = (a / b).ln() / 4.0;
    println!(
        "X2 default four-channel, K_m = 2000: device {:.4} mm at 4 s, p-p over [3, 4) s = {pp:.3e} m, over [7, 8) s = {b:.3e} m, decay {sigma:.2} 1/s (polynomial {PREDICTED_DECAY})",
        xm * 1e3
    );
    assert!(xm < -0.9e-3, "in steady contact (device at {xm:e} m)");
    assert!(
        (sigma - PREDICTED_DECAY).abs() <= 0.2 * PREDICTED_DECAY,
        "decay {sigma} 1/s vs the polynomial's {PREDICTED_DECAY} 1/s"
    );
    assert!(
        pp > 1e-5,
        "documents the slow mode: p-p {pp:e} m; if this fails, X2 holds at K_m = 2000 (update the doc)"
    );
}

/// Hand let go after 1.5 s of steady contact, then 4 s with no hand (spec §11.4: "X2 must also
/// hold with no hand"); the window is the last 1 s.
const RELEASE_AT: f64 = 1.5;

/// Runs `ctrl` held for [`RELEASE_AT`], then released for [`DURATION`]; returns the trace and the
/// device's peak-to-peak over the last 1 s.
fn released_pp(ctrl: Controller, hand: HandForce) -> (Trace, f64) {
    let tr = run_released_at(ctrl, hand, RELEASE_AT, RELEASE_AT + DURATION);
    let pp = window_pp(&tr.x_m, RELEASE_AT + DURATION - 1.0);
    (tr, pp)
}

/// X2 with no hand (§11.4) for the default configuration at its `K_m` (500 N/m), with the
/// applied-force signal (zero once released) and with the momentum observer's estimate: the device,
/// let go in steady contact, is pushed out of the wall and comes to rest; its peak-to-peak over the
/// last 1 s is < 1e-5 m and it stays out of the wall's far side. (At `K_m = 2000 N/m` the default's
/// `C5 = 2` ejects the pair farther and it still coasts after 4 s:
/// `released_default_is_pushed_out_of_the_wall_by_slave_force_feedback`.)
#[test]
fn x2_default_configuration_released() {
    for hand in [HandForce::Applied, HandForce::Observer] {
        {
            let k_m = 500.0;
            let (tr, pp) = released_pp(default_four_channel(k_m), hand);
            let i_rel = (RELEASE_AT / T).round() as usize;
            let xm = tr.x_m.last().copied().unwrap_or(0.0);
            println!(
                "X2 released, default four-channel, K_m = {k_m}, {hand:?}: device {:.4} mm at release, {:.4} mm at the end, p-p over the last 1 s = {pp:.3e} m",
                tr.x_m[i_rel] * 1e3,
                xm * 1e3
            );
            assert!(tr.x_m[i_rel] < -0.5e-3, "in contact when released");
            assert!(tr.x_m.iter().all(|x| x.is_finite() && x.abs() < 0.05));
            assert!(pp < 1e-5, "K_m = {k_m}, {hand:?}: p-p {pp:e} m");
        }
    }
}

/// The same released run with the §11.1 table (`four-channel-spec`): §11.4 predicts a growing
/// contact oscillation for the released handle (the 1-DOF device here, 0.3 kg with 0.5 N·s/m, is
/// below the `b ≈ 2.65 N·s/m` it would need); the test pins that the spec configuration does not
/// meet X2 with no hand, so the default's pass above is not a property of the setup.
#[test]
fn x2_spec_configuration_released_is_not_stable() {
    let (tr, pp) = released_pp(four_channel(500.0), HandForce::Applied);
    let xm_max = tr.x_m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    println!("X2 released, four-channel-spec: p-p over the last 1 s = {pp:.3e} m, max |x_m| = {xm_max:.3e} m");
    assert!(pp > 1e-5, "p-p {pp:e} m");
}

/// Issue 36's default drives the slave with `(1 + C5)·f_h − C5·f_e`, `C5 = 2`: let go in steady
/// contact, the wall force is fed back to the slave three times over and pushes the slave, and the
/// handle following it, out of the wall. Measured: at `K_m = 500 N/m` (the default) the device ends
/// about 8 mm out of the wall, at rest (X2 above); at `K_m = 2000 N/m` it is thrown about 40 mm and
/// still coasts after 4 s (peak-to-peak over the last 1 s about 0.2 mm, above X2's 1e-5 m), bounded
/// and slowing. The former default (`C5 = 0`) ends 3.5 mm out: less than half as far.
#[test]
fn released_default_is_pushed_out_of_the_wall_by_slave_force_feedback() {
    let end = |ctrl: Controller| {
        let (tr, pp) = released_pp(ctrl, HandForce::Applied);
        (tr.x_m.last().copied().unwrap_or(f64::NAN), pp, tr)
    };
    let (x500, pp500, _) = end(default_four_channel(500.0));
    let (x2000, pp2000, tr) = end(default_four_channel(2000.0));
    let former = FourChannelGains {
        k_m: [500.0, 500.0, 1.0],
        ..FourChannelGains::master_force_feedback()
    };
    let (x_former, _, _) = end(Controller::FourChannel(
        FourChannel::new(former, T).expect("valid gains"),
    ));
    println!(
        "released: default K_m 500 ends at {:.2} mm (p-p {pp500:.1e}), K_m 2000 at {:.2} mm (p-p {pp2000:.1e}), former default at {:.2} mm",
        x500 * 1e3,
        x2000 * 1e3,
        x_former * 1e3
    );
    assert!(x500 > 5e-3 && x500 < 12e-3 && pp500 < 1e-5);
    assert!(x2000 > 20e-3 && pp2000 > 1e-5 && pp2000 < 1e-3);
    assert!(tr.x_m.iter().all(|x| x.is_finite() && x.abs() < 0.05));
    assert!(
        x_former > 0.0 && x_former < 0.5 * x500,
        "former default ends at {x_former}"
    );
}
