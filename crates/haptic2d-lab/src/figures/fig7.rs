//! Fig. 7: a peg pushed into a tight hole by a unidirectional sinusoid (§13.2), the five friction
//! models in the 1-D peg harness and through the full 2-D world pipeline, at `F_pk = 2.1 N` (main) and
//! 1.8 N (sub-stiction).
//!
//! 2-D set-up: the `peg-in-hole` scene (VE mode, `T = 2 ms`, 5.2 s) with the case's friction model at
//! its per-contact parameters (half the 1-D values, §1–§4 tables) and the push peak set to `F_pk`. The
//! normal law is the scene's: the paper law with `Bc = 0`, i.e. a pure SEH stiffness `Kc = 1000 N/m`
//! per corner. With the peg held symmetric in the channel the penetration is constant (1 mm), so the
//! SEH estimate equals the penetration and every pure-stiffness variant (ZOH, SEH, SEH with
//! predictor–corrector) gives the same `F_n = 1 N` per corner; the choice does not affect the figure.
//! Body metrics are taken from the peg's `x`.
//!
//! Pass criteria: 1-D, F7-1…F7-5 as they apply to the model and the push; 2-D (F7-2D), F7-1…F7-4 with
//! the same thresholds, every metric within ±10 % of the 1-D harness's value, and `|θ|, |y| < 1e-6`
//! throughout. The 2-D energy balance `ΔE − W_push` (from the world's ledger) is reported and checked
//! against the same F7-5 bound.

use crate::csv::write_columns;
use crate::figures::{par_jobs, Figure, FigureContext, FigureReport};
use crate::harness::peg::{PegHarness, PegPush, PegResult};
use crate::plot::{write_panels, Panel, Series, Stroke};
use crate::schema::{CaseMetrics, Check, Dimension, Fig7Measured, FigureMetrics, Measured};
use crate::world2d::{body, load_builtin, rebuild};
use haptic2d::geom::Vec2;
use haptic2d::laws::friction::FrictionModel;
use std::fmt::Write as _;

/// The five models of Fig. 7: `(case name, friction model name, label)`.
pub const MODELS: [(&str, &str, &str); 5] = [
    ("classical", "classical", "Classical (Karnopp, v_th = 0.01)"),
    ("salcudean_vlaar", "salcudean-vlaar", "Salcudean–Vlaar"),
    ("reset_integrator", "reset-integrator", "Reset integrator"),
    (
        "hayward_armstrong",
        "hayward-armstrong",
        "Hayward–Armstrong",
    ),
    ("nahvi", "nahvi", "Nahvi finger pad"),
];
/// The two push peaks (N): main and sub-stiction.
pub const PEAKS: [f64; 2] = [2.1, 1.8];
/// Duration of every run (s).
pub const DURATION: f64 = 5.2;

/// §13.2 reference values at 2.1 N: `(creep_k, advance_k)` as printed in the table.
pub fn reference(case: &str) -> (&'static str, &'static str) {
    match case {
        "classical" => (
            "2.2e-3, 0.9e-3, 1.6e-3, 2.1e-3 (irregular)",
            "0.042, 0.035, 0.039",
        ),
        "salcudean_vlaar" => ("7.9e-5 (every cycle)", "0.0125"),
        "reset_integrator" => ("5.4e-5", "0.0407"),
        "hayward_armstrong" => ("5.0e-5", "0.0560"),
        "nahvi" => ("6.2e-5", "0.0414"),
        _ => ("", ""),
    }
}

/// §13.2 reference at 1.8 N (F7-4), as printed.
pub fn reference_sub(case: &str) -> &'static str {
    match case {
        "classical" => "x ≡ 0",
        "salcudean_vlaar" => "max|x| 3.0e-4",
        "reset_integrator" => "max|x| 2.0e-4",
        "hayward_armstrong" => "advance 0.8e-3",
        "nahvi" => "max|x| 2.25e-4",
        _ => "",
    }
}

fn model_name(case: &str) -> Result<&'static str, String> {
    MODELS
        .iter()
        .find(|m| m.0 == case)
        .map(|m| m.1)
        .ok_or_else(|| format!("unknown Fig. 7 model `{case}`"))
}

/// Runs the 1-D peg harness for `case` at peak `f_pk` (N).
pub fn run_1d(case: &str, f_pk: f64) -> Result<PegResult, String> {
    let model = FrictionModel::from_name(model_name(case)?, false)?;
    let h = PegHarness {
        duration: DURATION,
        ..PegHarness::fig7(model)
    };
    h.run(&PegPush::fig7(f_pk))
}

/// A 2-D run: the peg's `x` series as a [`PegResult`] (metrics computed with the same definitions),
/// plus the symmetry bounds and the guard count.
#[derive(Clone, Debug)]
pub struct Run2d {
    /// Series and metrics; `u_f` holds the world's stored contact energy plus any kinetic energy
    /// not in `½m·v_x²` (rotation, `y` motion), so `energy(j)` is the ledger's total.
    pub result: PegResult,
    /// `max|θ|` (rad).
    pub max_abs_theta: f64,
    /// `max|y|` (m).
    pub max_abs_y: f64,
    /// Passivity-guard triggers (0 with the guard off).
    pub guard_triggers: u64,
}

/// Runs the 2-D `peg-in-hole` world for `case` at peak `f_pk` (N), with an optional passivity guard
/// tolerance `guard` (J).
pub fn run_2d(case: &str, f_pk: f64, guard: Option<f64>) -> Result<Run2d, String> {
    let friction = FrictionModel::from_name(model_name(case)?, true)?;
    friction.validate()?;
    let mut w = load_builtin("peg-in-hole")?;
    let peg = body(&w, "peg")?;
    let mut loads = 0;
    for l in w.loads.iter_mut().filter(|l| l.body == peg) {
        l.force = Vec2::new(f_pk, 0.0);
        loads += 1;
    }
    if loads != 1 {
        return Err(format!(
            "peg-in-hole: expected one load on the peg, found {loads}"
        ));
    }
    let mut params = w.params;
    params.guard = guard;
    let normal = w.normal;
    let mut w = rebuild(w, normal, friction, params);
    let dt = w.params.dt;
    let n = (DURATION / dt).round() as usize;
    let mass = w.bodies[peg].mass;
    let push = PegPush::fig7(f_pk);
    let mut r = PegResult {
        mass,
        dt,
        period: 1.0,
        model: friction.name(),
        ..PegResult::default()
    };
    let (mut max_th, mut max_y) = (0.0f64, 0.0f64);
    for k in 0..=n {
        let b = &w.bodies[peg];
        let t = w.time();
        debug_assert!((t - k as f64 * dt).abs() < 1e-9);
        let ke: f64 = w.bodies.iter().map(|b| b.kinetic_energy()).sum();
        let (x, vx) = (b.pose.pos.x, b.vel.x);
        max_th = max_th.max(b.pose.angle.abs());
        max_y = max_y.max(b.pose.pos.y.abs());
        r.t.push(t);
        r.x.push(x);
        r.v.push(vx);
        r.f_push.push(push.at(t));
        // Stored energy after this sample's update, as in the 1-D harness.
        if let Some(d) = w.step() {
            return Err(format!(
                "fig7 {case}: the world diverged at t = {:.4} s: {d}",
                w.time()
            ));
        }
        r.f_friction.push(w.contact_wrench(peg).force.x);
        r.u_f.push(w.ledger().stored + (ke - 0.5 * mass * vx * vx));
    }
    r.creep = (1..=4).map_while(|k| r.creep_of(k)).collect();
    r.advance = (1..=3).map_while(|k| r.advance_of(k)).collect();
    r.energy_balance = (1..=4)
        .map_while(|k| {
            let c = k as f64;
            r.energy_balance_between(c - 0.1, c + 0.9)
        })
        .collect();
    r.max_abs_x = r.x.iter().fold(0.0, |a, x| a.max(x.abs()));
    Ok(Run2d {
        result: r,
        max_abs_theta: max_th,
        max_abs_y: max_y,
        guard_triggers: w.guard_triggers(),
    })
}

fn sci(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.3e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn measured(r: &PegResult, f_pk: f64, theta: f64, y: f64) -> Fig7Measured {
    Fig7Measured {
        peak_force_n: f_pk,
        creep_m: r.creep.clone(),
        advance_m: r.advance.clone(),
        energy_balance_j: r.energy_balance.clone(),
        max_abs_x_m: r.max_abs_x,
        max_abs_theta_rad: theta,
        max_abs_y_m: y,
    }
}

/// F7-1…F7-4 for `case` on metrics `m` (same thresholds in 1-D and 2-D); `x_all_zero` is whether the
/// whole `x` series is exactly 0 (classical at 1.8 N).
pub fn checks_f7_1_to_4(case: &str, m: &Fig7Measured, x_all_zero: bool) -> Vec<Check> {
    let mut c = Vec::new();
    let complete = m.creep_m.len() == 4 && m.advance_m.len() == 3;
    if !complete {
        c.push(Check::new(
            "F7",
            false,
            format!(
                "needs 4 creep_k and 3 advance_k, got {} and {}",
                m.creep_m.len(),
                m.advance_m.len()
            ),
        ));
        return c;
    }
    let max = |v: &[f64]| v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let min = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
    let main = m.peak_force_n > 2.0;
    if main {
        if case == "classical" {
            let (lo, spread) = (min(&m.creep_m), max(&m.creep_m) - min(&m.creep_m));
            c.push(Check::new(
                "F7-1",
                lo >= 5e-4 && spread > 1e-4,
                format!("min creep_k {lo:.3e} ≥ 5e-4 m, spread {spread:.3e} > 1e-4 m"),
            ));
        } else {
            let hi = max(&m.creep_m);
            let dc = m
                .creep_m
                .windows(2)
                .map(|w| (w[1] - w[0]).abs())
                .fold(0.0, f64::max);
            let da = m
                .advance_m
                .windows(2)
                .map(|w| (w[1] - w[0]).abs())
                .fold(0.0, f64::max);
            c.push(Check::new(
                "F7-2",
                hi <= 2e-4 && dc < 1e-5 && da < 1e-5,
                format!(
                    "max creep_k {hi:.3e} ≤ 2e-4 m; cycle-to-cycle Δcreep {dc:.2e}, Δadvance {da:.2e} < 1e-5 m"
                ),
            ));
        }
        let lo = min(&m.advance_m);
        c.push(Check::new(
            "F7-3",
            lo > 5e-3,
            format!("min advance_k {lo:.4e} > 5e-3 m"),
        ));
    } else {
        match case {
            "classical" => c.push(Check::new(
                "F7-4",
                x_all_zero,
                format!("x ≡ 0 (max|x| = {:.3e} m)", m.max_abs_x_m),
            )),
            "hayward_armstrong" => c.push(Check::new(
                "F7-4",
                m.advance_m.iter().all(|&a| 0.2e-3 < a && a < 2e-3),
                format!("advance_k [{}] in (0.2e-3, 2e-3) m", sci(&m.advance_m)),
            )),
            _ => c.push(Check::new(
                "F7-4",
                m.advance_m.iter().all(|a| a.abs() < 1e-6) && m.max_abs_x_m < 4e-4,
                format!(
                    "|advance_k| [{}] < 1e-6 m; max|x| {:.3e} < 4e-4 m",
                    sci(&m.advance_m),
                    m.max_abs_x_m
                ),
            )),
        }
    }
    c
}

/// F7-5: `ΔE − W_push ≤ 1e-6 J` in every cycle.
pub fn check_f7_5(m: &Fig7Measured) -> Check {
    let worst = m
        .energy_balance_j
        .iter()
        .cloned()
        .fold(f64::NEG_INFINITY, f64::max);
    Check::new(
        "F7-5",
        m.energy_balance_j.len() == 4 && worst <= 1e-6,
        format!("max per-cycle ΔE − W_push {worst:.3e} J ≤ 1e-6 J"),
    )
}

/// The numbers F7-2D compares with the 1-D reference (±10 %): creep_k and advance_k at 2.1 N;
/// `max|x|` (or advance_k for HA) at 1.8 N. Classical at 1.8 N has none (`x ≡ 0` in both).
fn compared(case: &str, m: &Fig7Measured) -> Vec<(String, f64)> {
    let mut v = Vec::new();
    if m.peak_force_n > 2.0 {
        for (k, x) in m.creep_m.iter().enumerate() {
            v.push((format!("creep_{}", k + 1), *x));
        }
        for (k, x) in m.advance_m.iter().enumerate() {
            v.push((format!("advance_{}", k + 1), *x));
        }
    } else if case == "hayward_armstrong" {
        for (k, x) in m.advance_m.iter().enumerate() {
            v.push((format!("advance_{}", k + 1), *x));
        }
    } else if case != "classical" {
        v.push(("max|x|".into(), m.max_abs_x_m));
    }
    v
}

/// F7-2D: 2-D numbers within ±10 % of the 1-D ones, and the symmetry bounds.
pub fn checks_2d(case: &str, m2: &Fig7Measured, m1: &Fig7Measured) -> Vec<Check> {
    let a = compared(case, m2);
    let b = compared(case, m1);
    let mut worst = (String::new(), 0.0f64);
    let mut ok = a.len() == b.len();
    for ((name, x2), (_, x1)) in a.iter().zip(&b) {
        let rel = ((x2 - x1) / x1).abs();
        // A NaN (e.g. a zero reference) fails the comparison and counts as the worst.
        if rel.is_nan() || rel > 0.10 {
            ok = false;
        }
        if rel.is_nan() || rel > worst.1 {
            worst = (name.clone(), rel);
        }
    }
    let mut c = vec![Check::new(
        "F7-2D",
        ok,
        if a.is_empty() {
            "no numbers to compare (x ≡ 0 in both)".to_string()
        } else {
            format!(
                "{} numbers within ±10 % of 1-D; worst {} at {:.1} %",
                a.len(),
                worst.0,
                worst.1 * 100.0
            )
        },
    )];
    c.push(Check::new(
        "F7-2D",
        m2.max_abs_theta_rad < 1e-6 && m2.max_abs_y_m < 1e-6,
        format!(
            "max|θ| {:.2e} rad, max|y| {:.2e} m < 1e-6",
            m2.max_abs_theta_rad, m2.max_abs_y_m
        ),
    ));
    c
}

/// The Fig. 7 figure.
pub struct Fig7;

struct Done {
    model: usize,
    peak: usize,
    dim: Dimension,
    result: PegResult,
    measured: Fig7Measured,
}

impl Figure for Fig7 {
    fn name(&self) -> &'static str {
        "fig7"
    }
    fn title(&self) -> &'static str {
        "Fig. 7: a peg pushed into a tight hole by a unidirectional sinusoid (§13.2)"
    }
    fn jobs(&self) -> u64 {
        (MODELS.len() * PEAKS.len() * 2) as u64
    }
    fn run(&self, ctx: &FigureContext) -> Result<FigureReport, String> {
        let mut jobs = Vec::new();
        for i in 0..MODELS.len() {
            for p in 0..PEAKS.len() {
                for d in [Dimension::OneD, Dimension::TwoD] {
                    jobs.push((i, p, d));
                }
            }
        }
        let done: Vec<Done> = par_jobs(ctx.progress, &jobs, |&(i, p, dim)| {
            let (case, f_pk) = (MODELS[i].0, PEAKS[p]);
            let r = match dim {
                Dimension::OneD => run_1d(case, f_pk).map(|r| {
                    let m = measured(&r, f_pk, 0.0, 0.0);
                    (r, m)
                }),
                Dimension::TwoD => run_2d(case, f_pk, None).map(|r| {
                    let m = measured(&r.result, f_pk, r.max_abs_theta, r.max_abs_y);
                    (r.result, m)
                }),
            };
            r.map(|(result, measured)| Done {
                model: i,
                peak: p,
                dim,
                result,
                measured,
            })
            .map_err(|e| format!("fig7 {case} {f_pk} N {}: {e}", dim.as_str()))
        })?;
        let get = |i: usize, p: usize, d: Dimension| {
            done.iter()
                .find(|x| x.model == i && x.peak == p && x.dim == d)
                .expect("every job ran")
        };
        let mut cases = Vec::new();
        let mut files = Vec::new();
        for (i, (case, _, _)) in MODELS.iter().enumerate() {
            for (p, f_pk) in PEAKS.iter().enumerate() {
                let one = get(i, p, Dimension::OneD);
                let two = get(i, p, Dimension::TwoD);
                let zero = |d: &Done| d.result.x.iter().all(|&x| x == 0.0);
                let mut c1 = checks_f7_1_to_4(case, &one.measured, zero(one));
                c1.push(check_f7_5(&one.measured));
                let mut c2 = checks_f7_1_to_4(case, &two.measured, zero(two));
                c2.extend(checks_2d(case, &two.measured, &one.measured));
                c2.push(check_f7_5(&two.measured));
                cases.push(CaseMetrics::new(
                    case,
                    Dimension::OneD,
                    Measured::Fig7(one.measured.clone()),
                    c1,
                ));
                cases.push(CaseMetrics::new(
                    case,
                    Dimension::TwoD,
                    Measured::Fig7(two.measured.clone()),
                    c2,
                ));
                for d in [one, two] {
                    let path = ctx
                        .dir
                        .join(format!("{case}_{}N_{}.csv", f_pk, d.dim.as_str()));
                    let r = &d.result;
                    write_columns(
                        &path,
                        &["t_s", "x_m", "v_m_s", "f_push_n", "f_friction_n", "u_f_j"],
                        &[&r.t, &r.x, &r.v, &r.f_push, &r.f_friction, &r.u_f],
                    )?;
                    files.push(path);
                }
            }
        }
        // Positions: one panel per model, x (mm) against time for both peaks and both pipelines.
        let panels: Vec<Panel> = MODELS
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let pts = |d: &Done| {
                    d.result
                        .t
                        .iter()
                        .zip(&d.result.x)
                        .map(|(&t, &x)| (t, x * 1e3))
                        .collect::<Vec<_>>()
                };
                Panel {
                    title: m.2.to_string(),
                    x_label: "time (s)".into(),
                    y_label: "peg position x (mm)".into(),
                    series: vec![
                        Series::new(
                            "1-D, F_pk 2.1 N",
                            pts(get(i, 0, Dimension::OneD)),
                            0,
                            Stroke::Solid,
                        ),
                        Series::new(
                            "2-D, F_pk 2.1 N",
                            pts(get(i, 0, Dimension::TwoD)),
                            1,
                            Stroke::Dashed,
                        ),
                        Series::new(
                            "1-D, F_pk 1.8 N",
                            pts(get(i, 1, Dimension::OneD)),
                            2,
                            Stroke::Solid,
                        ),
                        Series::new(
                            "2-D, F_pk 1.8 N",
                            pts(get(i, 1, Dimension::TwoD)),
                            3,
                            Stroke::Dashed,
                        ),
                    ],
                    ..Panel::default()
                }
            })
            .collect();
        files.extend(write_panels(
            &ctx.dir.join("positions"),
            "Fig. 7: peg position under F(t) = F_pk (1 − cos 2πt)/2",
            &panels,
            2,
            (620, 320),
        )?);
        // Creep and advance per cycle at 2.1 N.
        let per_cycle = |f: fn(&Fig7Measured) -> &Vec<f64>| {
            let mut s = Vec::new();
            for (i, m) in MODELS.iter().enumerate() {
                for (d, stroke, label) in [
                    (
                        Dimension::OneD,
                        Stroke::LineMarkers,
                        format!("{} (1-D)", m.0),
                    ),
                    (Dimension::TwoD, Stroke::Markers, String::new()),
                ] {
                    let v = f(&get(i, 0, d).measured);
                    let pts = v
                        .iter()
                        .enumerate()
                        .map(|(k, &x)| ((k + 1) as f64, x))
                        .collect();
                    s.push(Series::new(label, pts, i, stroke));
                }
            }
            s
        };
        files.extend(write_panels(
            &ctx.dir.join("creep_advance"),
            "Fig. 7 at F_pk = 2.1 N: creep while stuck and advance per cycle (lines 1-D, dots 2-D)",
            &[
                Panel {
                    title: "creep_k = x(k + 0.2) − x(k − 0.1)".into(),
                    x_label: "cycle k".into(),
                    y_label: "creep (m)".into(),
                    series: per_cycle(|m| &m.creep_m),
                    log_y: true,
                    h_lines: vec![2e-4, 5e-4],
                    ..Panel::default()
                },
                Panel {
                    title: "advance_k = x(k + 0.9) − x(k − 0.1)".into(),
                    x_label: "cycle k".into(),
                    y_label: "advance (m)".into(),
                    series: per_cycle(|m| &m.advance_m),
                    h_lines: vec![5e-3],
                    ..Panel::default()
                },
            ],
            2,
            (640, 460),
        )?);
        Ok(FigureReport::new("fig7", cases, files, report))
    }
}

/// The figure's section of `REPORT.md`.
fn report(m: &FigureMetrics) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## fig7\n\nFig. 7 (§13.2): a 0.2 kg peg pressed by 2 × 2 N normal force (μs = 0.5, μk = 0.45), \
         pushed by `F_pk (1 − cos 2πt)/2`, semi-implicit Euler at `T = 2 ms`, 5.2 s. 1-D: the peg \
         harness; 2-D: the `peg-in-hole` scene (4 corner contacts, per-contact parameters) through the \
         full world pipeline. Pass: F7-1…F7-5 in 1-D; in 2-D F7-1…F7-4 with the same thresholds, the \
         numbers within ±10 % of the 1-D run, `|θ|, |y| < 1e-6`, and F7-5 on the world's energy ledger.\n\n\
         ![positions](fig7/positions.png)\n\n![creep and advance](fig7/creep_advance.png)\n\n\
         | model | dim | F_pk (N) | creep_k (m) | advance_k (m) | max ΔE − W_push (J) | reference (§13.2) | pass |\n\
         |---|---|---|---|---|---|---|---|"
    );
    for c in &m.cases {
        let Measured::Fig7(x) = &c.measured else {
            continue;
        };
        let reference = if x.peak_force_n > 2.0 {
            let (cr, ad) = reference(&c.model);
            format!("creep {cr}; advance {ad}")
        } else {
            format!(
                "{}; max|x| here {:.3e} m",
                reference_sub(&c.model),
                x.max_abs_x_m
            )
        };
        let worst = x
            .energy_balance_j
            .iter()
            .cloned()
            .fold(f64::NEG_INFINITY, f64::max);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {:.2e} | {reference} | {} |",
            c.model,
            c.dimension.as_str(),
            x.peak_force_n,
            sci(&x.creep_m),
            sci(&x.advance_m),
            worst,
            if c.pass { "yes" } else { "**NO**" }
        );
    }
    let failing: Vec<&CaseMetrics> = m.cases.iter().filter(|c| !c.pass).collect();
    if !failing.is_empty() {
        let _ = writeln!(s, "\nFailing checks:\n");
        for c in failing {
            let Measured::Fig7(x) = &c.measured else {
                continue;
            };
            for k in c.checks.iter().filter(|k| !k.pass) {
                let _ = writeln!(
                    s,
                    "- {} {} {} N: {} — {}",
                    c.model,
                    c.dimension.as_str(),
                    x.peak_force_n,
                    k.id,
                    k.detail
                );
            }
        }
    }
    s
}
