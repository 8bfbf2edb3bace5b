//! Issue 40 item 6: the two studies that answer the paper's question, run on the simulated observer.
//!
//! (a) Perceived stiffness across the wall laws (`studies/wall-laws-tap.toml`,
//! `studies/wall-laws-press.toml`): PSE of a pure spring against the pulse, hysteretic and SEH walls.
//! (b) The friction models' stick (`studies/friction-models.toml`): PSE of the reset integrator's
//! `kr` against Dahl, Hayward–Armstrong, Nahvi and classical friction.
//!
//! The observer feels each stimulus through the stepped world (`study::explore`). The expected
//! values come from docs/MODELS.md and textbook mechanics where they can be derived (a tapped mass on
//! a spring, the hysteretic wall's slip deflections, the stick springs of §1–§3), and otherwise from
//! the physical PSE: the comparison value whose felt stiffness equals the reference's, found by
//! bisection on the exploration alone, without the psychophysics.

use haptic2d_lab::study::analyse::{ConditionResult, Pse};
use haptic2d_lab::study::observer::explore;
use haptic2d_lab::study::{stimulus, Study};

use super::study_support::{analyse, load, run_one};

/// The felt stiffness of condition `c`'s reference (`None`) or comparison at `delta`.
fn felt(study: &Study, c: usize, delta: Option<f64>) -> f64 {
    let cond = &study.conditions[c];
    let (name, vary) = match delta {
        None => (&cond.reference, None),
        Some(d) => (&cond.comparison, Some((&cond.vary, d))),
    };
    let w = stimulus::world(study, name, vary).unwrap();
    let probe = w.body_index(&study.probe).unwrap();
    explore(w, probe, study.toward, &study.observer)
        .unwrap()
        .stiffness
}

/// The physical PSE of condition `c` (value of the varied parameter): bisection of the comparison's
/// felt stiffness onto the reference's, in `[lo, hi]` (deltas).
fn physical_pse(study: &Study, c: usize, lo: f64, hi: f64) -> f64 {
    let target = felt(study, c, None);
    let (mut a, mut b) = (lo, hi);
    assert!(felt(study, c, Some(a)) < target && felt(study, c, Some(b)) > target);
    for _ in 0..24 {
        let m = 0.5 * (a + b);
        if felt(study, c, Some(m)) < target {
            a = m
        } else {
            b = m
        }
    }
    study.conditions[c].base_value + 0.5 * (a + b)
}

/// Simulated participants per study: each one's session is analysed on its own.
const PARTICIPANTS: [&str; 6] = ["p1", "p2", "p3", "p4", "p5", "p6"];

/// Runs the study for every participant and analyses each session on its own.
fn run_each(study: &Study, text: &str) -> Vec<Vec<ConditionResult>> {
    run_for(study, text, &PARTICIPANTS, 200)
}

fn run_for(study: &Study, text: &str, ids: &[&str], bootstrap: u32) -> Vec<Vec<ConditionResult>> {
    let dir = tempfile::tempdir().unwrap();
    ids.iter()
        .map(|id| {
            let s = run_one(study, text, dir.path(), id);
            assert!(s.complete);
            analyse(&s.dir, bootstrap)
        })
        .collect()
}

fn pse_of<'a>(res: &'a [ConditionResult], name: &str) -> &'a Pse {
    res.iter()
        .find(|r| r.condition == name)
        .unwrap()
        .pse
        .as_ref()
        .expect("a PSE condition")
}

/// Each participant's 95 % interval contains `expected` (at least 4 of 6: with honest intervals
/// three or more misses happen in 0.2 % of studies), every interval is informative (narrower than
/// ±15 %), and the participants' mean PSE is within 4 % of `expected` (no bias).
fn assert_pse_recovered(each: &[Vec<ConditionResult>], name: &str, expected: f64) {
    let pses: Vec<&Pse> = each.iter().map(|r| pse_of(r, name)).collect();
    for p in &pses {
        eprintln!(
            "{name}: PSE {:.1} [{:.1}, {:.1}], expected {expected:.1}",
            p.value, p.ci.0, p.ci.1
        );
        assert!(p.outside.is_none(), "{name}: {:?}", p.outside);
        assert!(p.ci.1 - p.ci.0 < 0.3 * expected, "{name}: {:?}", p.ci);
    }
    let hits = pses
        .iter()
        .filter(|p| p.ci.0 <= expected && expected <= p.ci.1)
        .count();
    let mean = pses.iter().map(|p| p.value).sum::<f64>() / pses.len() as f64;
    eprintln!(
        "{name}: {hits} of {} intervals contain {expected:.1}; mean PSE {mean:.1}",
        pses.len()
    );
    assert!(
        hits >= 4,
        "{name}: {hits} of {} intervals contain {expected}",
        pses.len()
    );
    assert!(
        (mean / expected - 1.0).abs() < 0.04,
        "{name}: mean PSE {mean}, expected {expected}"
    );
}

/// A tapped mass on a spring: the probe (m = 0.5 kg) meets two corner springs k in parallel
/// (K = 2k) at speed v, crossing the surface at mid-sample. The force at the window's last sample,
/// (N_w − ½)·T after the crossing, is `K·v·sin(ω t)/ω` (`ω² = K/m`: the free mass–spring solution,
/// Thomson, Theory of Vibration, section 2.1), so the rate-hardness is `K·sin(ω t)/(ω·N_w·T)`.
#[test]
fn tapping_a_spring_gives_the_rate_hardness_of_the_mass_spring_solution() {
    let (study, _) = load("wall-laws-tap.toml");
    let t = 0.002;
    let nw = (study.observer.tap_window / t).round();
    for delta in [-400.0, 0.0, 3000.0] {
        let k = 2.0 * (1000.0 + delta);
        let w = (k / 0.5f64).sqrt();
        let tc = (nw - 0.5) * t;
        let expected = k * (w * tc).sin() / (w * nw * t);
        let got = felt(&study, 0, Some(delta));
        assert!(
            (got / expected - 1.0).abs() < 0.01,
            "k = {k}: felt {got}, expected {expected}"
        );
    }
}

/// Pressing (two slow presses, 0.5 and 1.5 N per corner): the braking pulse acts only in the first
/// samples after entry and SEH's extrapolation vanishes at rest, so both feel as their spring 2k
/// (MODELS §5.5, §5.7). The hysteretic wall (MODELS §5.8, per corner k0 = 500, (250 N/m, 0.25 N),
/// (250 N/m, 0.5 N)) loads at 1000 N/m up to 1 mm (1 N), where block 1 slips, then at 750 N/m: 0.5 N
/// sits at 0.5 mm, 1.5 N at 1 mm + 0.5/750 = 1.6667 mm; the secant is 1/1.1667 mm = 857.1 N/m per
/// corner.
#[test]
fn pressing_feels_the_pulse_and_seh_walls_as_their_spring_and_the_hysteretic_wall_softer() {
    let (study, _) = load("wall-laws-press.toml");
    for (c, expected) in [
        ("pulse-vs-spring", 2000.0),
        ("seh-vs-spring", 2000.0),
        ("hysteretic-vs-spring", 2.0 * 1.0 / 1.1666667e-3),
    ] {
        let i = study.condition_index(c).unwrap();
        let got = felt(&study, i, None);
        eprintln!("{c}: felt {got:.2} N/m, derived {expected:.2}");
        assert!(
            (got / expected - 1.0).abs() < 0.01,
            "{c}: felt {got}, derived {expected}"
        );
    }
}

/// Stroking: a stuck reset integrator is the spring (1 + a)·Kr per corner, a = μs/μk − 1 (MODELS
/// §1); Nahvi's pad is k_p0 (§3); Hayward–Armstrong's elastic zone is k below k·z_stick =
/// r_stick·μk·F_n = 0.225 N per corner (§2; the push peaks at 0.175 N per corner). With the same
/// grip in series, equal stick springs feel equal: Nahvi = reset at kr = 2000/1.111 = 1800,
/// Hayward–Armstrong = reset at kr = 2500/1.111 = 2250. Plain Dahl has no elastic zone: loaded once
/// it follows F = k·z_max·(1 − exp(−x/z_max)), whose secant between 0.05 and 0.15 N per corner is
/// 1930 N/m (= reset at kr = 1737) — and its drift under the tremor makes it feel softer still.
/// Classical friction's stick does not move at all: rigid.
#[test]
fn stroking_feels_each_friction_models_stick_spring_and_dahls_drift() {
    let (study, _) = load("friction-models.toml");
    let a = 0.5 / 0.45 - 1.0;
    let idx = |n: &str| study.condition_index(n).unwrap();
    let nahvi = felt(&study, idx("nahvi-vs-reset"), None);
    let reset_1800 = felt(
        &study,
        idx("nahvi-vs-reset"),
        Some(2000.0 / (1.0 + a) - 2000.0),
    );
    assert!(
        (nahvi / reset_1800 - 1.0).abs() < 1e-3,
        "{nahvi} vs {reset_1800}"
    );
    let ha = felt(&study, idx("hayward-armstrong-vs-reset"), None);
    let reset_2250 = felt(
        &study,
        idx("hayward-armstrong-vs-reset"),
        Some(2500.0 / (1.0 + a) - 2000.0),
    );
    assert!((ha / reset_2250 - 1.0).abs() < 1e-3, "{ha} vs {reset_2250}");
    let z_max = 0.45 / 2500.0;
    let x = |f: f64| -z_max * (1.0 - f / 0.45).ln();
    let secant = 0.1 / (x(0.15) - x(0.05));
    assert!((secant - 1930.0).abs() < 5.0, "{secant}");
    let dahl = felt(&study, idx("dahl-vs-reset"), None);
    let reset_secant = felt(
        &study,
        idx("dahl-vs-reset"),
        Some(secant / (1.0 + a) - 2000.0),
    );
    eprintln!("Dahl felt {dahl:.0} N/m, a drift-free Dahl would feel {reset_secant:.0}");
    assert!(dahl < 0.5 * reset_secant, "{dahl} vs {reset_secant}");
    assert_eq!(felt(&study, idx("classical-vs-reset"), None), f64::INFINITY);
}

/// (a) by tapping, the shipped study end to end: the hysteretic wall's PSE is its loading stiffness
/// 1000 (the tap's 0.9 mm stays below the 1 mm slip deflection), SEH's and the pulse's are their
/// physical PSEs; the pulse feels more than three times as stiff as its spring, SEH slightly stiffer
/// (its extrapolation adds about half a sample's travel: at most 5/4.5 × 1000).
#[test]
#[ignore = "about 15 s per study in debug (six simulated participants); run: cargo test -p haptic2d-lab --test it study_pse:: -- --ignored"]
fn wall_laws_tap_study_recovers_each_laws_pse() {
    let (study, text) = load("wall-laws-tap.toml");
    let each = run_each(&study, &text);
    let idx = |n: &str| study.condition_index(n).unwrap();
    let hyst = physical_pse(&study, idx("hysteretic-vs-spring"), -400.0, 400.0);
    assert!((hyst - 1000.0).abs() < 0.01, "{hyst}");
    assert_pse_recovered(&each, "hysteretic-vs-spring", 1000.0);
    let seh = physical_pse(&study, idx("seh-vs-spring"), -300.0, 500.0);
    assert!(seh > 1000.0 && seh < 1000.0 * 5.0 / 4.5 + 1.0, "{seh}");
    assert_pse_recovered(&each, "seh-vs-spring", seh);
    let pulse = physical_pse(&study, idx("pulse-vs-spring"), 2000.0, 9000.0);
    assert!(pulse > 3000.0, "{pulse}");
    assert_pse_recovered(&each, "pulse-vs-spring", pulse);
}

/// (a) by pressing: the pulse and SEH walls' PSEs are their spring, 1000 N/m per corner; the
/// hysteretic wall's is its secant, 857 N/m (derived above; the felt value is within 1 % of it).
#[test]
#[ignore = "about 15 s per study in debug (six simulated participants); run: cargo test -p haptic2d-lab --test it study_pse:: -- --ignored"]
fn wall_laws_press_study_finds_pulse_and_seh_equal_to_their_spring_and_hysteretic_softer() {
    let (study, text) = load("wall-laws-press.toml");
    let each = run_each(&study, &text);
    assert_pse_recovered(&each, "pulse-vs-spring", 1000.0);
    assert_pse_recovered(&each, "seh-vs-spring", 1000.0);
    assert_pse_recovered(&each, "hysteretic-vs-spring", 1.0 / 1.1666667e-3);
}

/// (b) The friction study end to end: Nahvi's and Hayward–Armstrong's PSEs are kr = k/(1 + a) (1800
/// and 2250), Dahl's lies below its drift-free 1737, and classical friction's rigid stick lies above
/// every tested reset integrator.
#[test]
#[ignore = "about 15 s per study in debug (six simulated participants); run: cargo test -p haptic2d-lab --test it study_pse:: -- --ignored"]
fn friction_study_recovers_the_stick_springs_and_shows_dahls_drift_and_classicals_rigid_stick() {
    let (study, text) = load("friction-models.toml");
    let each = run_each(&study, &text);
    let a = 0.5 / 0.45 - 1.0;
    assert_pse_recovered(&each, "nahvi-vs-reset", 2000.0 / (1.0 + a));
    assert_pse_recovered(&each, "hayward-armstrong-vs-reset", 2500.0 / (1.0 + a));
    for res in &each {
        let dahl = pse_of(res, "dahl-vs-reset");
        assert!(dahl.outside.is_none() && dahl.ci.1 < 1737.0, "{dahl:?}");
        let cl = pse_of(res, "classical-vs-reset");
        assert_eq!(cl.outside, Some("above"), "{cl:?}");
    }
}

/// The three shipped studies end to end for one simulated participant each (the fast check; the
/// six-participant interval checks above are ignored for time): every PSE lands within 10 % of its
/// derived or physical value, the pulse feels stiffer than three springs of its K when tapped, and
/// classical friction's rigid stick lies above the tested range.
#[test]
fn each_study_runs_end_to_end_for_one_participant_and_finds_its_pses_within_10_percent() {
    let near = |res: &[ConditionResult], name: &str, expected: f64| {
        let p = pse_of(res, name);
        eprintln!(
            "{name}: PSE {:.1} [{:.1}, {:.1}], expected {expected:.1}",
            p.value, p.ci.0, p.ci.1
        );
        assert!(
            p.outside.is_none() && (p.value / expected - 1.0).abs() < 0.1,
            "{name}: {p:?}, expected {expected}"
        );
    };
    let a = 0.5 / 0.45 - 1.0;
    let (study, text) = load("friction-models.toml");
    let res = &run_for(&study, &text, &["p1"], 50)[0];
    near(res, "nahvi-vs-reset", 2000.0 / (1.0 + a));
    near(res, "hayward-armstrong-vs-reset", 2500.0 / (1.0 + a));
    assert_eq!(pse_of(res, "classical-vs-reset").outside, Some("above"));
    let (study, text) = load("wall-laws-press.toml");
    let res = &run_for(&study, &text, &["p1"], 50)[0];
    near(res, "pulse-vs-spring", 1000.0);
    near(res, "seh-vs-spring", 1000.0);
    near(res, "hysteretic-vs-spring", 1.0 / 1.1666667e-3);
    let (study, text) = load("wall-laws-tap.toml");
    let res = &run_for(&study, &text, &["p1"], 50)[0];
    near(res, "hysteretic-vs-spring", 1000.0);
    assert!(pse_of(res, "pulse-vs-spring").value > 3000.0);
}
