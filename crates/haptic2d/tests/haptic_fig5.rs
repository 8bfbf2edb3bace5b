//! Figs. 5–6 with the device in the loop (see `haptic2d::haptic::fig5`, whose module docs give the
//! pass criteria): the paper's claim is that the block keeps bouncing on the marginally passive (SEH)
//! and active (ZOH) walls, settles at the first impact with the pulse wall and soon with the hysteretic
//! wall.
//!
//! Measured with the simulated twin pantograph at 500 Hz, 10 s, push 2 N:
//!
//! - Four-channel controller (the paper's): SEH and ZOH keep bouncing to the end and the bounces grow
//!   (entry speeds 0.40 → 0.50 m/s for SEH, 0.40 → 0.57 m/s for ZOH; contact ratios 1.25, 1.16, … where
//!   the world alone gives 0.87 for SEH): the loop is active. Fig. 5 holds. The pulse wall stops the
//!   bouncing after 2 separations (entries 0.40, 0.19, 0.08 m/s) but its first contact ratio is 0.49 >
//!   0.4 and the third entry 0.08 > 0.15·v1: not "at the first impact". The hysteretic wall's bounces
//!   decay (0.40, 0.34, 0.26, 0.19, 0.14, 0.09 m/s) with ratios ≈ 1.0 at first, then chatter on (48
//!   separations): Fig. 6 is not reproduced with this loop.
//! - Virtual coupling: the pulse (first ratio 0.20, later entries ≤ 0.026 m/s) and the hysteretic wall
//!   (1 separation, ratio 0.28) settle, as in Fig. 6, but the coupling's damper and the device's joint
//!   friction also settle SEH and ZOH after 1–2 separations: Fig. 5 is not reproduced with this loop.

use haptic2d::haptic::fig5::{run, Fig5Case, Fig5Params};

fn case<'a>(cases: &'a [Fig5Case], name: &str) -> &'a Fig5Case {
    cases.iter().find(|c| c.name == name).expect("case")
}

fn report(label: &str, cases: &[Fig5Case]) {
    for c in cases {
        let m = &c.metrics;
        let f = |v: &[f64]| {
            v.iter()
                .take(6)
                .map(|r| format!("{r:.3}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        println!(
            "{label} {:<10} separations {:>3} (last 2 s: {:>2}), entries [{}] m/s, ratios [{}], settle {:?}, pass {}",
            c.name,
            m.bounce.separations(),
            m.late_separations,
            f(&m.bounce.entry_speeds),
            f(&m.bounce.contact_ratios),
            m.bounce.settle_time,
            m.pass
        );
    }
}

/// Fig. 5 with the four-channel loop: SEH and ZOH keep bouncing; the pulse and hysteretic walls damp
/// the bouncing in that order but miss the W7/W6 thresholds (see the module docs).
#[test]
fn fig5_four_channel_seh_zoh_keep_bouncing() {
    let cases = run(&Fig5Params::default()).expect("runs");
    report("four-channel", &cases);
    for name in ["seh", "zoh"] {
        let m = &case(&cases, name).metrics;
        assert!(m.pass, "{name} keeps bouncing");
        assert!(m.bounce.separations() >= 20, "{name}");
    }
    // The pulse wall stops the bouncing within 3 impacts and the block stays at the wall.
    let pulse = &case(&cases, "pulse").metrics;
    assert!(pulse.bounce.separations() <= 3);
    assert_eq!(pulse.late_separations, 0);
    assert!(pulse.bounce.entry_speeds[1] < 0.6 * pulse.bounce.entry_speeds[0]);
    // The hysteretic wall: every one of the first 6 impacts is slower than the one before, and far
    // slower than SEH's.
    let hyst = &case(&cases, "hysteretic").metrics;
    assert!(hyst
        .bounce
        .entry_speeds
        .windows(2)
        .take(5)
        .all(|w| w[1] < w[0]));
    let seh = &case(&cases, "seh").metrics;
    assert!(hyst.bounce.entry_speeds[5] < 0.5 * seh.bounce.entry_speeds[5]);
}

/// Fig. 6 with the virtual coupling: the pulse wall settles at the first impact (W7) and the hysteretic
/// wall soon (W6); SEH and ZOH settle too (the coupling is dissipative), so Fig. 5 fails there.
#[test]
fn fig6_coupling_pulse_and_hysteretic_settle() {
    let cases = run(&Fig5Params::coupling()).expect("runs");
    report("coupling", &cases);
    assert!(case(&cases, "pulse").metrics.pass);
    assert!(case(&cases, "hysteretic").metrics.pass);
    for name in ["seh", "zoh"] {
        let m = &case(&cases, name).metrics;
        assert!(m.bounce.separations() <= 3, "{name}");
        assert!(m.bounce.settle_time.is_some(), "{name}");
    }
}
