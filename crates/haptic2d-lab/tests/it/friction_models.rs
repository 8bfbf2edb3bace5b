//! Checkable behaviour of the friction models, §1–§4: R1–R5 (reset integrator), H1–H5
//! (Hayward–Armstrong and Dahl), N1–N3 (Nahvi finger pad), C1–C2 (classical Karnopp), S1–S3
//! (Salcudean–Vlaar), plus the scene-facing API (names, parameters, validation).
//!
//! "Harness" tests use the 1-D peg harness of §13.2 (point mass, semi-implicit Euler, `T = 0.002 s`);
//! "kinematic" tests drive one model instance directly with a prescribed motion.

use haptic2d::laws::friction::{
    FingerPad, FrictionInput, FrictionLaw, FrictionMode, FrictionModel, HaywardArmstrong, Karnopp,
    LoadScaling, ResetIntegrator, SalcudeanVlaar,
};
use haptic2d_lab::harness::peg::{PegHarness, PegPush, PegResult};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const T: f64 = 0.002;
const FN: f64 = 2.0;
const MU_S: f64 = 0.5;
const MU_K: f64 = 0.45;

/// The §13.2 harness (0.2 kg, two contacts with `F_n = 2 N`) for `model`, lasting `duration` s.
fn harness(model: FrictionModel, duration: f64) -> PegHarness {
    PegHarness {
        duration,
        ..PegHarness::fig7(model)
    }
}

/// Drives `law` kinematically at constant velocity `v` (m/s) for `n` samples from `s`, returning the
/// forces and modes and the final `s`.
fn drive<L: FrictionLaw>(law: &mut L, s: &mut f64, v: f64, n: usize) -> Vec<(f64, FrictionMode)> {
    (0..n)
        .map(|_| {
            *s += v * T;
            let f = law.update(&FrictionInput {
                ds: v * T,
                s: *s,
                s0: v,
                fn_: FN,
                dt: T,
                f_ext_t: 0.0,
            });
            (f, law.mode())
        })
        .collect()
}

fn stick_windows_max_creep(r: &PegResult) -> f64 {
    r.creep.iter().cloned().fold(f64::MIN, f64::max)
}

/// The Fig. 7 staircase checks shared by R5, N3 and S3 (thresholds of F7-2 and F7-3).
fn assert_clean_stick_slip(name: &str) -> PegResult {
    let model = FrictionModel::from_name(name, false).expect("name");
    let r = PegHarness::fig7(model)
        .run(&PegPush::fig7(2.1))
        .expect("harness");
    assert!(
        stick_windows_max_creep(&r) <= 2e-4,
        "{name}: creep {:?}",
        r.creep
    );
    for w in r.creep[1..].windows(2) {
        assert!(
            (w[1] - w[0]).abs() < 1e-5,
            "{name}: creep not periodic {:?}",
            r.creep
        );
    }
    for w in r.advance[1..].windows(2) {
        assert!(
            (w[1] - w[0]).abs() < 1e-5,
            "{name}: advance not periodic {:?}",
            r.advance
        );
    }
    assert!(
        r.advance.iter().all(|&a| a > 5e-3),
        "{name}: no slip {:?}",
        r.advance
    );
    r
}

// ---------------------------------------------------------------- §1 reset integrator

#[test]
fn r1_no_slip_below_stiction() {
    let ri = ResetIntegrator::one_d();
    let f_max = 0.95 * 2.0 * MU_S * FN; // 1.9 N on the two contacts together
    let bound = f_max / (2.0 * (1.0 + ri.a()) * ri.kr) + 1e-6;
    // Ramp at 1 N/s to 1.9 N (t = 1.9 s), hold 1 s, then release the push at once and wait 1 s.
    let r = harness(FrictionModel::ResetIntegrator(ri), 3.9)
        .run_with(|t| if t < 2.9 { t.min(f_max) } else { 0.0 })
        .expect("harness");
    assert!(
        r.max_abs_x <= bound,
        "max|x| = {:e} > bound {bound:e}",
        r.max_abs_x
    );
    assert!(
        r.mode.iter().all(|&m| m == FrictionMode::Stick),
        "a contact slipped"
    );
    let x_end = *r.x.last().expect("samples");
    assert!(
        x_end.abs() <= 1e-6,
        "presliding is not elastic: x = {x_end:e}"
    );
}

#[test]
fn r2_breakaway_level() {
    let r = harness(
        FrictionModel::ResetIntegrator(ResetIntegrator::one_d()),
        3.0,
    )
    .run(&PegPush::Ramp {
        rate: 1.0,
        f_max: 3.0,
    })
    .expect("harness");
    let j = r
        .mode
        .iter()
        .position(|&m| m == FrictionMode::Slip)
        .expect("the ramp must break the contacts away");
    let f = r.f_push[j];
    let level = 2.0 * MU_S * FN;
    assert!(
        (f - level).abs() <= 0.02 * level,
        "first slip at applied force {f} N, expected {level} N ± 2 %"
    );
}

#[test]
fn r3_kinetic_level() {
    for scaling in [LoadScaling::Limit, LoadScaling::Stiffness] {
        let mut ri = ResetIntegrator::one_d();
        ri.scaling = scaling;
        let mut s = 0.0;
        for v in [0.05, -0.05] {
            let out = drive(&mut ri, &mut s, v, 500);
            for (f, mode) in &out[100..] {
                assert_eq!(*mode, FrictionMode::Slip);
                assert!(
                    ((f.abs() - MU_K * FN) / (MU_K * FN)).abs() <= 1e-9,
                    "{scaling:?}: |F_t| = {f} in steady sliding"
                );
                assert_eq!(f.signum(), -v.signum(), "friction must oppose sliding");
            }
        }
    }
}

#[test]
fn r4_bounded_strain() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    for scaling in [LoadScaling::Limit, LoadScaling::Stiffness] {
        let mut ri = ResetIntegrator::one_d();
        ri.scaling = scaling;
        let (mut s, mut fn_) = (0.0, FN);
        for k in 0..20_000 {
            // Random motion, and every 50 samples a random step of the normal force (mostly down).
            if k % 50 == 0 {
                fn_ = if rng.random_bool(0.2) {
                    FN
                } else {
                    fn_ * rng.random_range(0.05..1.0)
                };
            }
            let ds = rng.random_range(-1e-4..1e-4);
            s += ds;
            ri.update(&FrictionInput {
                ds,
                s,
                s0: ds / T,
                fn_,
                dt: T,
                f_ext_t: 0.0,
            });
            let p0 = ri.p0(fn_);
            assert!(
                ri.strain().abs() <= p0 + 1e-12,
                "{scaling:?} sample {k}: |p| = {:e} > p0 = {p0:e}",
                ri.strain().abs()
            );
        }
    }
}

#[test]
fn r5_fig7_stick_slip_without_creep() {
    let r = assert_clean_stick_slip("reset-integrator");
    // In the stick windows [k − 0.1, k + 0.2] s the contacts never slip: the motion is presliding.
    for k in 1..=4 {
        let (j0, j1) = (
            r.index(k as f64 - 0.1).expect("t"),
            r.index(k as f64 + 0.2).expect("t"),
        );
        assert!(
            r.mode[j0..=j1].iter().all(|&m| m == FrictionMode::Stick),
            "slip inside the stick window of cycle {k}"
        );
    }
}

// ---------------------------------------------------------------- §2 Hayward–Armstrong / Dahl

/// H1–H3 set-up: 0.2 kg on ONE contact with `μk·F_n = 0.9 N` (`F_n = 2 N`), `k = 5000`, `r_stick = 0.5`,
/// `σ1 = 10`, push `F(t) = mean + amp·sin(2π·5t)` for 4 s. Drift = mean x over [3.8, 4.0) s minus the
/// mean over [1.0, 1.2) s (one 5 Hz period each).
fn ha_drift(model: HaywardArmstrong, mean: f64, amp: f64) -> f64 {
    let h = PegHarness {
        n_contacts: 1,
        duration: 4.0,
        ..PegHarness::fig7(FrictionModel::HaywardArmstrong(model))
    };
    let r = h
        .run_with(|t| mean + amp * (2.0 * std::f64::consts::PI * 5.0 * t).sin())
        .expect("harness");
    r.mean_x(3.8, 4.0).expect("window") - r.mean_x(1.0, 1.2).expect("window")
}

#[test]
fn h1_drift_free_below_z_stick() {
    let drift = ha_drift(HaywardArmstrong::one_d(), 0.3, 0.1);
    println!("H1 HA drift = {drift:e} m (reference ≈ 1e-17)");
    assert!(drift.abs() < 1e-6, "HA drift {drift:e} m");
}

#[test]
fn h2_dahl_drifts() {
    let drift = ha_drift(HaywardArmstrong::one_d().dahl(), 0.3, 0.1);
    println!("H2 Dahl drift = {drift:e} m (reference 3.0e-4)");
    assert!(drift > 1e-4, "Dahl drift {drift:e} m");
}

#[test]
fn h3_plastic_zone_creeps() {
    let ha = ha_drift(HaywardArmstrong::one_d(), 0.6, 0.2);
    let dahl = ha_drift(HaywardArmstrong::one_d().dahl(), 0.6, 0.2);
    println!(
        "H3 HA drift = {ha:e} m (reference 9.1e-4), Dahl drift = {dahl:e} m (reference 3.9e-3)"
    );
    assert!(ha > 1e-4, "HA drift {ha:e} m");
    assert!(ha < dahl, "HA drift {ha:e} ≥ Dahl drift {dahl:e}");
}

#[test]
fn h4_sliding_level() {
    for model in [HaywardArmstrong::one_d(), HaywardArmstrong::one_d().dahl()] {
        let mut ha = model;
        ha.sigma1 = 0.0;
        ha.sigma2 = 0.0;
        let mut s = 0.0;
        for v in [0.05, -0.05] {
            let out = drive(&mut ha, &mut s, v, 500);
            for (f, _) in &out[200..] {
                assert!(
                    ((f.abs() - MU_K * FN) / (MU_K * FN)).abs() <= 1e-9,
                    "|F_t| = {f} in steady sliding"
                );
                assert_eq!(f.signum(), -v.signum());
            }
        }
    }
}

#[test]
fn h5_alpha_continuity() {
    let ha = HaywardArmstrong::one_d();
    let z_max = MU_K * FN / ha.k;
    let z_stick = ha.r_stick * z_max;
    let eps = 1e-9 * z_max;
    assert!(ha.alpha(z_stick + eps, 1.0, z_max) < 1e-9);
    assert!(ha.alpha(z_max - eps, 1.0, z_max) > 1.0 - 1e-9);
    assert!(ha.alpha(-(z_stick + eps), -1.0, z_max) < 1e-9);
    assert!(ha.alpha(-(z_max - eps), -1.0, z_max) > 1.0 - 1e-9);
    // No jumps anywhere on [0, 1.2·z_max]: the largest step between neighbours shrinks with the grid.
    let n = 100_000;
    let h = 1.2 * z_max / n as f64;
    let max_jump = (0..n)
        .map(|i| {
            (ha.alpha((i + 1) as f64 * h, 1.0, z_max) - ha.alpha(i as f64 * h, 1.0, z_max)).abs()
        })
        .fold(0.0, f64::max);
    // |α'| ≤ π/(2(z_max − z_stick)), so a step of h moves α by at most π·h/(2·0.5·z_max) ≈ 3.8e-5.
    assert!(max_jump < 4e-5, "α jumps by {max_jump:e}");
    // Unloading is elastic.
    assert_eq!(ha.alpha(0.9 * z_max, -1.0, z_max), 0.0);
}

// ---------------------------------------------------------------- §3 Nahvi finger pad

#[test]
fn n1_breakaway_and_sliding_levels() {
    let mut pad = FingerPad::one_d();
    pad.begin(0.0);
    // Very slow loading (ds = 1e-8 m per sample) so the breakaway is resolved to k·ds = 4e-5 N.
    let v = 1e-8 / T;
    let mut s = 0.0;
    let out = drive(&mut pad, &mut s, v, 40_000);
    let j = out
        .iter()
        .position(|(_, m)| *m == FrictionMode::Slip)
        .expect("must break away");
    let f_break = out[..j].iter().map(|(f, _)| f.abs()).fold(0.0, f64::max);
    assert!(
        ((f_break - MU_S * FN) / (MU_S * FN)).abs() < 1e-3,
        "break-away at {f_break} N, expected μs·F_n = {} N",
        MU_S * FN
    );
    for (f, m) in &out[j..] {
        assert_eq!(*m, FrictionMode::Slip);
        assert!(
            ((f.abs() - MU_K * FN) / (MU_K * FN)).abs() <= 1e-9,
            "sliding at {f} N"
        );
    }
}

#[test]
fn n2_relaxes_on_reversal() {
    let mut pad = FingerPad::one_d();
    pad.begin(0.0);
    let mut s = 0.0;
    let out = drive(&mut pad, &mut s, 0.05, 200);
    assert_eq!(out.last().expect("samples").1, FrictionMode::Slip);
    // First sample of the reversed motion: stick, and the force is below the kinetic level.
    let (f, m) = drive(&mut pad, &mut s, -0.01, 1)[0];
    assert_eq!(m, FrictionMode::Stick, "mode after velocity reversal");
    assert!(
        f.abs() < MU_K * FN,
        "force {f} N not below μk·F_n after reversal"
    );
}

#[test]
fn n3_fig7_no_creep_periodic_advance() {
    assert_clean_stick_slip("nahvi");
}

// ---------------------------------------------------------------- §4.1 classical (Karnopp)

#[test]
fn c1_no_motion_from_rest_below_stiction() {
    let r = PegHarness::fig7(FrictionModel::Karnopp(Karnopp::one_d()))
        .run(&PegPush::fig7(1.8))
        .expect("harness");
    assert!(r.x.iter().all(|&x| x == 0.0), "x must stay exactly 0");
    assert!(r.v.iter().all(|&v| v == 0.0), "v must stay exactly 0");
}

#[test]
fn c2_creep_after_slip() {
    let r = PegHarness::fig7(FrictionModel::Karnopp(Karnopp::one_d()))
        .run(&PegPush::fig7(2.1))
        .expect("harness");
    let min = r.creep.iter().cloned().fold(f64::MAX, f64::min);
    let max = stick_windows_max_creep(&r);
    assert!(min > 5e-4, "creep {:?}", r.creep);
    assert!(
        max - min > 1e-4,
        "creep does not vary between cycles: {:?}",
        r.creep
    );
    // The creep happens inside the stick band: a residual velocity 0 < |v| < v_th.
    for k in 1..=4 {
        let (j0, j1) = (
            r.index(k as f64 - 0.1).expect("t"),
            r.index(k as f64 + 0.2).expect("t"),
        );
        assert!(
            r.v[j0..=j1].iter().all(|v| v.abs() <= 0.01),
            "cycle {k} slides"
        );
        assert!(
            r.v[j0..=j1].iter().any(|v| v.abs() > 0.0),
            "cycle {k} at rest"
        );
    }
}

// ---------------------------------------------------------------- §4.2 Salcudean–Vlaar

#[test]
fn s1_stick_offset_bounded() {
    let sv = SalcudeanVlaar::one_d();
    // Ramp to 1.5 N (0.75 N per contact, below μs·F_n = 1 N) and hold.
    let f = 1.5;
    let r = harness(FrictionModel::SalcudeanVlaar(sv), 4.0)
        .run(&PegPush::Ramp {
            rate: 1.0,
            f_max: f,
        })
        .expect("harness");
    assert!(
        r.mode.iter().all(|&m| m == FrictionMode::Stick),
        "broke away"
    );
    let offset = f / 2.0 / sv.k_p;
    let x_end = *r.x.last().expect("samples");
    assert!(
        (x_end - offset).abs() < 1e-8,
        "offset {x_end:e}, expected F/K_p = {offset:e}"
    );
    let x3 = r.x_at(3.0).expect("t");
    assert!(
        (x_end - x3).abs() < 1e-9,
        "creep while stuck: {:e}",
        x_end - x3
    );
}

#[test]
fn s2_sliding_force() {
    let mut sv = SalcudeanVlaar::one_d();
    sv.begin(0.0);
    let mut s = 0.0;
    for v in [0.05, -0.08] {
        let out = drive(&mut sv, &mut s, v, 200);
        for (f, m) in &out[50..] {
            assert_eq!(*m, FrictionMode::Slip);
            let expected = MU_K * FN + sv.b_v * v.abs();
            assert!(
                ((f.abs() - expected) / expected).abs() <= 1e-12,
                "{f} vs {expected}"
            );
            assert_eq!(f.signum(), -v.signum());
        }
    }
}

#[test]
fn s3_fig7_bounded_periodic_stick() {
    assert_clean_stick_slip("salcudean-vlaar");
}

// ---------------------------------------------------------------- API used by the scene loader

#[test]
fn model_names_round_trip() {
    for &name in FrictionModel::NAMES {
        for per_contact in [false, true] {
            let m = FrictionModel::from_name(name, per_contact).expect("valid name");
            assert_eq!(m.name(), name);
            m.validate().expect("defaults are valid");
        }
    }
    let err = FrictionModel::from_name("coulomb", false).expect_err("unknown");
    assert!(err.contains("coulomb") && err.contains("reset-integrator") && err.contains("dahl"));
}

#[test]
fn per_contact_defaults_are_the_2d_peg_values() {
    assert_eq!(ResetIntegrator::per_contact().kr, 2000.0);
    assert_eq!(ResetIntegrator::per_contact().beta, 10.0);
    assert_eq!(HaywardArmstrong::per_contact().k, 2500.0);
    assert_eq!(HaywardArmstrong::per_contact().sigma1, 5.0);
    assert_eq!(FingerPad::per_contact().k_p0, 2000.0);
    assert_eq!(FingerPad::per_contact().b_pad, 5.0);
    let sv = SalcudeanVlaar::per_contact();
    assert_eq!((sv.k_p, sv.k_d, sv.b_v, sv.v_th), (1500.0, 7.5, 1.0, 0.01));
    assert_eq!(Karnopp::per_contact(), Karnopp::one_d());
}

#[test]
fn set_param_and_validate_name_the_parameter() {
    let mut m = FrictionModel::from_name("reset-integrator", false).expect("name");
    m.set_param("kr", 3000.0).expect("kr");
    m.set_param("mu_k", 0.6).expect("mu_k");
    let err = m.validate().expect_err("μk > μs");
    assert!(
        err.contains("mu_s") && err.contains("reset-integrator"),
        "{err}"
    );
    let err = m.set_param("k", 1.0).expect_err("wrong key");
    assert!(err.contains("kr") && err.contains("beta"), "{err}");
    assert!(m.set_param("beta", f64::NAN).is_err());
    m.set_load_scaling(LoadScaling::Stiffness)
        .expect("RI has load scaling");
    assert!(LoadScaling::from_name("stiff").is_err());

    let mut m = FrictionModel::from_name("hayward-armstrong", false).expect("name");
    m.set_param("r_stick", 1.0).expect("r_stick");
    assert!(m.validate().expect_err("r_stick").contains("r_stick"));
    assert!(m.set_load_scaling(LoadScaling::Limit).is_err());

    let mut m = FrictionModel::from_name("nahvi", false).expect("name");
    m.set_param("k_p0", -1.0).expect("k_p0");
    assert!(m
        .validate()
        .expect_err("negative stiffness")
        .contains("k_p0"));

    let mut m = FrictionModel::from_name("salcudean-vlaar", true).expect("name");
    m.set_param("v_th", 0.0).expect("v_th");
    assert!(m.validate().expect_err("v_th").contains("v_th"));

    let mut m = FrictionModel::from_name("classical", true).expect("name");
    let err = m.set_param("k_p", 1.0).expect_err("wrong key");
    assert!(err.contains("v_th"), "{err}");
    assert!(FrictionModel::None.clone().set_param("mu_s", 0.5).is_err());
}

#[test]
fn anchors_follow_the_god_object_rules() {
    // §8.3: RI s_g = s − p; Nahvi and SV s_g = s_a (the entry point at creation); HA s_g = s − z.
    let input = FrictionInput {
        ds: 1e-5,
        s: 0.10001,
        s0: 0.005,
        fn_: FN,
        dt: T,
        f_ext_t: 0.0,
    };
    let mut ri = ResetIntegrator::one_d();
    ri.begin(0.1);
    ri.update(&input);
    assert_eq!(ri.anchor(input.s), Some(input.s - ri.strain()));
    let mut ha = HaywardArmstrong::one_d();
    ha.begin(0.1);
    ha.update(&input);
    assert_eq!(ha.anchor(input.s), Some(input.s - ha.z()));
    let mut pad = FingerPad::one_d();
    pad.begin(0.1);
    pad.update(&input);
    assert_eq!(pad.anchor(input.s), Some(0.1));
    let mut sv = SalcudeanVlaar::one_d();
    sv.begin(0.1);
    sv.update(&input);
    assert_eq!(sv.anchor(input.s), Some(0.1));
    assert_eq!(Karnopp::one_d().anchor(input.s), None);
}
