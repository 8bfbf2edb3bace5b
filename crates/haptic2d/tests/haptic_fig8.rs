//! Figs. 8–11 with the device in the loop (see `haptic2d::haptic::fig8`): the paper's claim is that
//! classical friction drifts while the other models stick and slip.
//!
//! Finding (not yet reproduced; the test documenting the claim is `#[ignore]`d): with the simulated
//! twin pantograph and the default four-channel controller, every model's first slip carries the peg
//! 0.1–0.2 m, so the handle reaches the edge of its workspace (singularity margin < 0.1, safety stop)
//! within 0.6–2.5 s of the release, before the creep/advance windows of later cycles. In the recorded
//! runs the squeezed peg rattles in y and θ (contact forces of ±5–8 N across the channel, torques at
//! saturation) once it moves: the coupling's y/θ stiffness (2000 N/m, 4 N·m/rad on the slave) against
//! 1000 N/m corner springs, with the device's inertial x–y–θ coupling, unloads the corners
//! intermittently and friction drops, so slips run long. Tried without success: F_pk 2.1–2.3 N,
//! mapping scale 1 and 2, with and without the push-in phase. Untried: stiffer y/θ grip on the handle,
//! lower slave y/θ gains, 500 Hz with reduced θ gains.

use haptic2d::haptic::fig8::{run, Fig8Params};

fn report() -> Vec<haptic2d::haptic::fig8::Fig8Case> {
    let cases = run(&Fig8Params::default()).expect("runs");
    for c in &cases {
        let m = &c.metrics;
        let f = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:.2e}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        println!(
            "{:<17} creep [{}] m, advance [{}] m, peg x end {:.4} m, pass {}{}",
            c.name,
            f(&m.creep),
            f(&m.advance),
            c.records.last().map_or(f64::NAN, |r| r.x_s[0]),
            m.pass,
            c.stopped
                .as_deref()
                .map_or(String::new(), |s| format!(" — {s}"))
        );
    }
    cases
}

/// What the loop does today: every case ends in a safety stop at the workspace edge (deterministic).
#[test]
fn fig8_runs_and_stops_safely_at_the_workspace_edge() {
    let cases = report();
    assert_eq!(cases.len(), 5);
    for c in &cases {
        let last = c.records.last().expect("records");
        assert!(last.tau.iter().all(|t| *t == 0.0) || c.stopped.is_none());
        if let Some(s) = &c.stopped {
            assert!(s.contains("singularity"), "{}: {s}", c.name);
        }
    }
}

/// The paper's claim (F7-1..F7-3 thresholds): classical drifts, the others stick and slip.
#[test]
#[ignore = "not reproduced with the device in the loop yet; see the module docs"]
fn fig8_fig11_classical_drifts_others_stick_slip() {
    for c in &report() {
        assert!(c.metrics.pass, "{}", c.name);
    }
}
