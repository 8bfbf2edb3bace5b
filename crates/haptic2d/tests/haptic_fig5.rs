//! Figs. 5–6 with the device in the loop (see `haptic2d::haptic::fig5`): the paper's claim is that the
//! block keeps bouncing on the marginally passive (SEH) and active (ZOH) walls, settles at the first
//! impact with the pulse wall and soon with the hysteretic wall.
//!
//! Measured with the simulated twin pantograph and the four-channel controller (momentum-observer hand
//! force), 500 Hz, 10 s:
//!
//! - SEH and ZOH: the block keeps bouncing to the end, and the bounces *grow* (entry speeds 0.40 →
//!   0.50 m/s for SEH, 0.40 → 0.57 m/s for ZOH) until torque saturation bounds them: the four-channel
//!   loop with an estimated hand force adds energy at each impact on top of the wall's own activity.
//!   Fig. 5's claim holds.
//! - Pulse: 2 separations in 10 s (entries 0.40, 0.19, 0.08 m/s), then the block stays in contact —
//!   stable after the third impact rather than the first. The pulse is sized for the box alone
//!   (`m_eff` = box mass); sizing it for box + device makes the contact chatter (see
//!   `Fig5Params::pulse_device_mass`).
//! - Hysteretic: the bounces decay steadily (entries 0.40, 0.34, 0.26, 0.19, 0.14, 0.09 m/s) but the
//!   block does not come to rest within 10 s: the element friction removes a fixed energy per cycle
//!   while the loop keeps feeding a little.
//!
//! So the ordering of Figs. 5–6 holds (SEH/ZOH bounce for ever; the pulse wall stops the bouncing
//! almost at once; the hysteretic wall damps it), but the strict "settles" criteria of the metrics'
//! `pass` are not met by the pulse and hysteretic walls in this loop; the test asserts the ordering
//! and reports `pass` as measured.

use haptic2d::haptic::fig5::{run, Fig5Case, Fig5Params};

fn case<'a>(cases: &'a [Fig5Case], name: &str) -> &'a Fig5Case {
    cases.iter().find(|c| c.name == name).expect("case")
}

#[test]
fn fig5_fig6_walls_with_the_device_in_the_loop() {
    let cases = run(&Fig5Params::default()).expect("runs");
    for c in &cases {
        let m = &c.metrics;
        let entries: Vec<String> = m
            .bounce
            .entry_speeds
            .iter()
            .take(6)
            .map(|r| format!("{r:.3}"))
            .collect();
        println!(
            "{:<10} separations {:>3} (last 2 s: {:>2}), entries [{}] m/s, settle {:?}, max pen {:.2} mm, late max |v| {:.2e} m/s, pass {}",
            c.name,
            m.bounce.separations(),
            m.late_separations,
            entries.join(", "),
            m.bounce.settle_time,
            m.bounce.max_penetration * 1e3,
            m.late_max_speed,
            m.pass
        );
    }
    // Fig. 5: marginally passive and active walls keep the block bouncing.
    for name in ["seh", "zoh"] {
        let m = &case(&cases, name).metrics;
        assert!(m.pass, "{name} keeps bouncing");
        assert!(m.bounce.separations() >= 20, "{name}");
    }
    // Fig. 6, pulse: the bouncing stops within a few impacts and the block stays in contact.
    let pulse = &case(&cases, "pulse").metrics;
    assert!(
        pulse.bounce.separations() <= 3,
        "pulse separations {}",
        pulse.bounce.separations()
    );
    assert_eq!(pulse.late_separations, 0);
    assert!(pulse.bounce.entry_speeds[1] < 0.6 * pulse.bounce.entry_speeds[0]);
    // Fig. 6, hysteretic: every one of the first 6 impacts is slower than the one before.
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
