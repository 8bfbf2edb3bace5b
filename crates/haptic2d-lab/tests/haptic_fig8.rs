//! Figs. 8–11 with the device in the loop (see `haptic2d_lab::experiments::fig8`): the paper's claim is that
//! classical friction drifts while the other models stick and slip. Thresholds are §13.2's F7-1 (drift:
//! `min creep_k ≥ 5e-4 m`), F7-2 (stick: `max creep_k ≤ 2e-4 m`) and F7-3 (slip: `advance_k > 5e-3 m`).
//!
//! Measured (1 kHz, scale 2, F_pk = 2.1 N, handle free after the release):
//!
//! - Virtual coupling: classical creep 7.1e-4–8.3e-4 m per cycle (drift), the others 3.4e-5–5.3e-5 m
//!   (elastic presliding, as in the 1-D reference's 5e-5 m); advances 7e-3–2.5e-2 m. Every claim holds.
//! - Four-channel: the free handle renders the channel's undamped corner springs through the C2 force
//!   channel at `s²·4000 N/m` with a zero-order hold (Colgate: needs 8 N·s/m of physical damping, the
//!   device has ~0.01); the y/θ oscillation grows until corners unload (`|y|` up to 7 mm against 1 mm of
//!   interference), the first slip runs away and every run ends in a singularity safety stop at the
//!   workspace edge within 0.6–0.9 s of the release.

use haptic2d_lab::experiments::fig8::{run, Fig8Case, Fig8Params};

fn report(label: &str, cases: &[Fig8Case]) {
    for c in cases {
        let m = &c.metrics;
        let f = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:.2e}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        println!(
            "{label} {:<17} creep [{}] m, advance [{}] m, max|y| {:.1e} m, pass {}{}",
            c.name,
            f(&m.creep),
            f(&m.advance),
            m.max_abs_y,
            m.pass,
            c.stopped
                .as_deref()
                .map_or(String::new(), |s| format!(" — {s}"))
        );
    }
}

/// The paper's claim with the virtual coupling: classical drifts, the others stick and slip.
#[test]
fn fig8_fig11_classical_drifts_others_stick_slip() {
    let cases = run(&Fig8Params::default()).expect("runs");
    report("coupling", &cases);
    assert_eq!(cases.len(), 5);
    for c in &cases {
        assert!(c.stopped.is_none(), "{}", c.name);
        assert!(c.metrics.pass, "{}", c.name);
        // The peg stays squeezed: no rattle across the 1 mm interference.
        assert!(c.metrics.max_abs_y < 1e-4, "{}", c.name);
    }
}

/// The four-channel loop with the handle released: the y/θ rattle makes every run stop safely at the
/// workspace edge (deterministic), so the claim cannot be measured there.
#[test]
fn fig8_four_channel_free_handle_rattles_and_stops_safely() {
    let cases = run(&Fig8Params::four_channel()).expect("runs");
    report("four-channel", &cases);
    for c in &cases {
        let s = c.stopped.as_deref().expect("safety stop");
        assert!(s.contains("singularity"), "{}: {s}", c.name);
        assert!(c
            .records
            .last()
            .expect("records")
            .tau
            .iter()
            .all(|t| *t == 0.0));
        assert!(c.metrics.max_abs_y > 1e-3, "{}: corners unload", c.name);
        assert!(!c.metrics.pass);
    }
}
