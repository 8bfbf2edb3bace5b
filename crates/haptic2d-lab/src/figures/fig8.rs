//! Figs. 8–11: the peg in a tight hole with the device in the loop (`crate::scenarios::peg_with_device`): the
//! 0.2 kg peg of `peg-in-hole` (1 mm interference, 1 N per corner), one friction model per case, the
//! simulated twin pantograph at 1 kHz with mapping scale 2; the hand grips the handle for 1 s, then
//! lets go and `F_pk (1 − cos 2πt)/2` with `F_pk = 2.1 N` (world) pushes the handle along x; y and θ
//! are free. The claims are carried by the default controller (`C6 = −1`, `C5 = 2`, damping
//! injection; `carrier` gives the reason the report prints beside `haptic2d stability`'s verdict);
//! comparison runs: the virtual coupling (§11.2), the §11.1 table (unstable with the hand released,
//! §11.4), the default at the paper's setting (500 Hz, mapping scale 1), a named variant, the
//! paper-rate study's soft coupling there, the default on the capstan-friction device without and
//! with friction compensation, and the default with the push injected into the hand-force estimate
//! (issue 36 items 2–4).
//!
//! Pass criteria (§13.2 thresholds on the cycles after the release): the run ends without a safety
//! stop; every `advance_k > 5e-3 m` (F7-3); classical `min creep_k ≥ 5e-4 m` (F7-1, drift), the others
//! `max |creep_k| ≤ 2e-4 m` (F7-2, stick). F7-2's periodicity and F7-5's energy balance are not checked
//! (the device's friction and quantisation make the staircase vary by ~1e-3 m per cycle; the device
//! is an energy port the ledger does not close).

use crate::figures::{
    case_panels, device_case, run_configurations, write_tick_csv, Figure, FigureContext,
    FigureReport,
};
use crate::plot::{write_panels, Series, Stroke};
use crate::scenarios::peg_with_device::{run_case, Fig8Case, Fig8Params, FIG8_CASES};
use crate::scenarios::{with_capstan_friction, ControllerRuns, Protocol};
use crate::schema::{CaseMetrics, Check, Dimension, Fig7Measured, FigureMetrics, Measured};
use std::fmt::Write as _;

/// The controllers compared: `(name, parameters, comparison)`. The four-channel controller with its
/// released-stable default gains carries the claims; the virtual coupling and the §11.1 table are
/// comparison runs.
fn controllers(ctx: Option<&FigureContext>) -> Result<Vec<(String, Fig8Params)>, String> {
    let mut v = vec![
        ("four-channel".to_string(), Fig8Params::default()),
        ("coupling".to_string(), Fig8Params::coupling()),
        (
            "four-channel-spec".to_string(),
            Fig8Params::paper_controller(),
        ),
        // The paper's setting (issue 36 item 2), a named variant: 500 Hz and mapping scale 1, where
        // the device's world-side inertia is four times that at scale 2.
        (
            "four-channel-500hz-scale1".to_string(),
            Fig8Params {
                rate: 500.0,
                scale: 1.0,
                ..Fig8Params::default()
            },
        ),
        // The paper-rate study's best stable design (issue 36 item 2, MODELS.md §11.4): a soft
        // virtual coupling (`controllers/coupling-paper-rate.toml`), at 500 Hz and scale 1.
        (
            "coupling-160-500hz-scale1".to_string(),
            Fig8Params {
                rate: 500.0,
                scale: 1.0,
                ..Fig8Params::with_controller(haptic2d::haptic::ControllerKind::Coupling(
                    PAPER_RATE_COUPLING,
                ))
            },
        ),
    ];
    // Issue 36 item 3, named comparison runs: the carrier on the device of
    // `devices/twin-pantograph-capstan-friction.toml` (realistic joint Coulomb friction), without
    // and with its friction compensation. Item 4: the carrier with the push injected into the
    // hand-force estimate instead of acting on the handle.
    let base = v[0].1.clone();
    for (suffix, compensated) in [
        ("capstan-friction", false),
        ("capstan-friction-compensated", true),
    ] {
        let mut p = base.clone();
        p.haptic.device = with_capstan_friction(&p.haptic.device, compensated)?;
        v.push((format!("four-channel-{suffix}"), p));
    }
    // The same compensation with a deadband of 0.01 rad/s: below the 0.04 rad/s spike one encoder
    // count makes through the velocity filter, so a real device could dither at rest with it (the
    // reason the file keeps 0.05); it compensates the breakaway the stick models need each cycle.
    let mut fine = base.clone();
    fine.haptic.device = with_capstan_friction(&fine.haptic.device, true)?;
    fine.haptic.device.friction_deadband = FINE_DEADBAND;
    v.push((
        "four-channel-capstan-friction-compensated-deadband-0.01".to_string(),
        fine,
    ));
    v.push((
        "four-channel-estimate-injection".to_string(),
        Fig8Params {
            protocol: Protocol::EstimateInjection,
            ..base
        },
    ));
    // `reproduce --controller-file`: that controller carries the claims (and runs the variants).
    if let Some((label, kind)) = ctx.and_then(|c| c.controller.as_ref()) {
        for (name, p) in v.iter_mut() {
            if name.starts_with("four-channel") && !name.starts_with("four-channel-spec") {
                *name = name.replacen("four-channel", label, 1);
                p.haptic.controller = *kind;
            }
        }
    }
    Ok(v)
}

/// The gains of `controllers/coupling-paper-rate.toml`: `K_vc` = 160 N/m, `B_vc` = 7.8125 N·s/m (θ
/// 0.125 N·m/rad, 0.005 N·m·s/rad).
pub const PAPER_RATE_COUPLING: haptic2d::control::coupling::CouplingGains =
    haptic2d::control::coupling::CouplingGains {
        k: [160.0, 160.0, 0.125],
        b: [7.8125, 7.8125, 0.005],
    };

/// The deadband of the fine-deadband friction comparison run (rad/s of joint rate).
pub const FINE_DEADBAND: f64 = 0.01;

/// Why the default carries the Figs. 8–11 claims.
const DEFAULT_REASON: &str = "the default controller, stable held and released with margin on the peg (`haptic2d stability peg-in-hole`): its slave-side local force feedback C5 makes the hand's push reach the peg without reflecting the contact force to a released handle";

/// Which run carries the claims (`i` indexes [`controllers`]) and why; `None` for a comparison run.
fn carrier(i: usize) -> Option<&'static str> {
    (i == 0).then_some(DEFAULT_REASON)
}

fn label(model: &str) -> &'static str {
    match model {
        "classical" => "Classical — Fig. 11",
        "reset-integrator" => "Reset integrator — Fig. 10",
        "dahl" => "Driftless Dahl (Hayward–Armstrong) — Fig. 9",
        "nahvi" => "Nahvi finger pad — Fig. 8",
        _ => "Salcudean–Vlaar",
    }
}

fn sci(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.2e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn measured(p: &Fig8Params, c: &Fig8Case) -> Fig7Measured {
    Fig7Measured {
        peak_force_n: p.peak,
        creep_m: c.metrics.creep.clone(),
        advance_m: c.metrics.advance.clone(),
        energy_balance_j: Vec::new(),
        max_abs_x_m: c.records.iter().map(|r| r.x_s[0].abs()).fold(0.0, f64::max),
        max_abs_theta_rad: c.metrics.max_abs_theta,
        max_abs_y_m: c.metrics.max_abs_y,
    }
}

/// The claim's checks for case `c` (see the module docs).
pub fn checks(c: &Fig8Case) -> Vec<Check> {
    let m = &c.metrics;
    let min = m.creep.iter().copied().fold(f64::INFINITY, f64::min);
    let max = m.creep.iter().map(|c| c.abs()).fold(0.0, f64::max);
    let mut v = vec![Check::new(
        "F8-run",
        c.stopped.is_none(),
        c.stopped
            .clone()
            .unwrap_or_else(|| "no safety stop".to_string()),
    )];
    if m.expect_drift {
        v.push(Check::new(
            "F7-1",
            c.stopped.is_none() && min >= 5e-4,
            format!("min creep_k {min:.3e} ≥ 5e-4 m (drift)"),
        ));
    } else {
        v.push(Check::new(
            "F7-2",
            c.stopped.is_none() && max <= 2e-4,
            format!("max |creep_k| {max:.3e} ≤ 2e-4 m (stick)"),
        ));
    }
    let lo = m.advance.iter().copied().fold(f64::INFINITY, f64::min);
    v.push(Check::new(
        "F7-3",
        c.stopped.is_none() && lo > 5e-3,
        format!("min advance_k {lo:.3e} > 5e-3 m (slip)"),
    ));
    v
}

/// The Figs. 8–11 figure.
pub struct Fig8;

impl Figure for Fig8 {
    fn name(&self) -> &'static str {
        "fig8"
    }
    fn title(&self) -> &'static str {
        "Figs. 8–11: a peg pushed in a tight hole with the device in the loop"
    }
    fn jobs(&self) -> u64 {
        (controllers(None).map_or(0, |c| c.len()) * FIG8_CASES.len()) as u64
    }
    fn run(&self, ctx: &FigureContext) -> Result<FigureReport, String> {
        let ctrl = controllers(Some(ctx))?;
        let done = run_configurations(ctx, "fig8", &ctrl, FIG8_CASES.len(), |p, j| {
            let (name, model, drift) = FIG8_CASES[j];
            run_case(p, name, model, drift)
        })?;
        let mut files = Vec::new();
        let mut cases = Vec::new();
        for (i, j, c) in &done {
            let p = &ctrl[*i].1;
            let model = format!("{}/{}", ctrl[*i].0, c.name);
            let (world, haptic) =
                crate::scenarios::peg_with_device::case_world(p, FIG8_CASES[*j].1)?;
            let case = device_case(
                CaseMetrics::new(
                    &model,
                    Dimension::TwoD,
                    Measured::Fig7(measured(p, c)),
                    checks(c),
                ),
                &ctrl[*i].0,
                carrier(*i),
                crate::design::verdict_line(&haptic, &world, p.rate),
            );
            cases.push(case);
            let path = ctx.dir.join(format!("{}_{}.csv", ctrl[*i].0, c.name));
            write_tick_csv(&path, &c.records, p.scale, "peg", &[(6, "push_n", &c.push)])?;
            files.push(path);
        }
        let titles: Vec<&str> = FIG8_CASES.iter().map(|(name, _, _)| label(name)).collect();
        let mut panels = case_panels(&titles, "peg position x (mm)", &done, |i, c| {
            let pts = c.records.iter().map(|r| (r.t, r.x_s[0] * 1e3)).collect();
            let (stroke, lbl) = match (i, &c.stopped) {
                (0, _) => (Stroke::Solid, ctrl[i].0.clone()),
                (_, Some(_)) => (Stroke::Dashed, format!("{} (safety stop)", ctrl[i].0)),
                _ => (Stroke::Dashed, ctrl[i].0.clone()),
            };
            Series::new(lbl, pts, i, stroke)
        });
        for p in &mut panels {
            p.y_range = Some((-5.0, 120.0));
        }
        files.extend(write_panels(
            &ctx.dir.join("positions"),
            "Figs. 8–11 with the device in the loop: peg position, push 2.1 N (1 − cos 2πt)/2 from t = 1 s",
            &panels,
            2,
            (620, 320),
        )?);
        Ok(FigureReport::new("fig8", cases, files, report))
    }
}

fn report(m: &FigureMetrics) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## fig8\n\nFigs. 8–11 with the device in the loop: the `peg-in-hole` peg (0.2 kg, 1 mm \
         interference, 1 N per corner, SEH stiffness without damping) driven by the simulated twin \
         pantograph at 1 kHz, mapping scale 2; the hand holds the handle for 1 s, then lets go and \
         `2.1 N (1 − cos 2πt)/2` (world) pushes the handle along x, y and θ free. The claims are carried \
         by the default controller (C6 = −1, C5 = 2, D_m = 1 N·s/m); comparison runs: the virtual \
         coupling (§11.2), the paper's §11.1 table, the default at the paper's own setting, \
         500 Hz and mapping scale 1 (`four-channel-500hz-scale1`: the device's world-side inertia \
         four times that at scale 2; the claims do not hold there), the paper-rate study's best stable \
         design there (`coupling-160-500hz-scale1`, `controllers/coupling-paper-rate.toml`: 4 of 5, \
         but walls felt at 7 % of their stiffness), the default on a device with realistic joint \
         Coulomb friction (`four-channel-capstan-friction`, 0.015 N·m per joint from \
         `devices/twin-pantograph-capstan-friction.toml`) and with that file's friction compensation \
         (`four-channel-capstan-friction-compensated`, deadband 0.05 rad/s; and \
         `…-deadband-0.01`, a deadband below one encoder count's velocity spike), and the default \
         with the push injected into \
         the hand-force estimate instead of acting on the handle (`four-channel-estimate-injection`, \
         the second reading of the paper's protocol); MODELS.md §11.4 discusses each. Pass: no safety stop; \
         classical `min creep_k ≥ 5e-4 m` (F7-1, drift), the others `max creep_k ≤ 2e-4 m` (F7-2, \
         stick); every `advance_k > 5e-3 m` (F7-3, slip). `creep_k = x(k + 0.2) − x(k − 0.1)`, \
         `advance_k = x(k + 0.9) − x(k − 0.1)`, k counted in seconds after the release.\n\n\
         ![positions](fig8/positions.png)\n\n\
         ### Which configuration reproduces each claim\n\n{}\n\
         ### Every run\n\n\
         | controller/model | creep_k (m) | advance_k (m) | max abs y (m) | max abs θ (rad) | pass |\n\
         |---|---|---|---|---|---|",
        crate::figures::claims_table(m)
    );
    for c in &m.cases {
        let Measured::Fig7(x) = &c.measured else {
            continue;
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1e} | {:.1e} | {} |",
            c.model,
            sci(&x.creep_m),
            sci(&x.advance_m),
            x.max_abs_y_m,
            x.max_abs_theta_rad,
            c.verdict()
        );
    }
    let failing: Vec<&CaseMetrics> = m.cases.iter().filter(|c| !c.pass).collect();
    if !failing.is_empty() {
        let _ = writeln!(s, "\nFailing checks (comparison runs included):\n");
        for c in failing {
            for k in c.checks.iter().filter(|k| !k.pass) {
                let _ = writeln!(s, "- {}: {} — {}", c.model, k.id, k.detail);
            }
        }
    }
    let _ = writeln!(
        s,
        "\nThe mechanism (issue 11, spec §11.4). After the release nothing holds the handle. With the \
         §11.1 table (force reflection C2 = 1) the loop of handle, peg and the squeezed corner springs \
         is unstable in continuous time: for the y axis at scale 2 (handle inertia divided by 4, peg \
         0.2 kg, 4 × 1000 N/m) the §11.4 polynomial has roots +30 ± 185j — the rattle of the \
         `four-channel-spec` runs, which end in safety stops at every rate; Colgate's `b > K·T/2` is \
         not the mechanism and device damping is not the cure. With local force feedback at the master \
         (C6 = −1, so C2 = 0) every axis is stable with the hand held or released (`haptic2d \
         stability peg-in-hole --scale 2`). With C5 = 0 (the former default) the push reaches the peg \
         through the hand-force estimate (C3 = 1) while the handle follows through the PD, so every \
         slip is braked by the handle's inertia and the coupling's dampers (advances below the 5 mm \
         of F7-3, no classical drift). The default's slave-side local force feedback C5 = 2 drives the \
         peg with 3·f_h − 2·f_e: the push arrives amplified and the contact force is fed back at the \
         slave only, so the peg slips while a released handle still feels no contact force. The \
         virtual coupling (comparison) meets every claim too: it sends no force channel to the \
         device and drives the peg with the spring K_vc alone."
    );
    s
}
