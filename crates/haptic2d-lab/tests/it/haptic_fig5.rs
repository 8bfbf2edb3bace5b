//! Figs. 5–6 with the device in the loop (see `haptic2d_lab::scenarios::walls_with_device`, whose module docs give the
//! pass criteria and the derivation of the device damping): the paper's claim is that the block keeps
//! bouncing on the marginally passive (SEH) and active (ZOH) walls, settles at the first impact with
//! the pulse wall and soon with the hysteretic wall.
//!
//! Measured with the simulated twin pantograph at 500 Hz, 10 s, push 2 N:
//!
//! - Four-channel on the damped device (`b_x = 2·K·T/2`, the default): SEH 97 separations (21 in the
//!   last 2 s), ZOH 85 (18); the pulse never leaves the wall after the first impact; the hysteretic
//!   wall separates once (ratio 0.61). All four claims hold.
//! - Four-channel on the spec's device (joint `f_v = 1e-4`, 1/70 of the bound): the loop is active
//!   (SEH ratios 1.25, 1.16, …, entries growing 0.40 → 0.50 m/s). SEH and ZOH keep bouncing; the pulse
//!   needs 3 impacts (first ratio 0.49) and the hysteretic wall keeps bouncing (48 separations).
//! - Virtual coupling on the damped device: dissipative, every wall settles.

use haptic2d_lab::scenarios::walls_with_device::{run, Fig5Case, Fig5Params};
use haptic2d_lab::scenarios::ControllerRuns as _;

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

/// Figs. 5 and 6 with the §11.1 table on a device damped at twice Colgate's bound (comparison run):
/// all four walls do what the paper reports.
#[test]
fn fig5_fig6_four_channel_damped_device_reproduces_every_wall() {
    let cases = run(&Fig5Params::calibrated_damping()).expect("runs");
    report("four-channel", &cases);
    for c in &cases {
        assert!(c.metrics.pass, "{}: {:?}", c.name, c.metrics);
    }
    for name in ["seh", "zoh"] {
        assert!(
            case(&cases, name).metrics.bounce.separations() >= 20,
            "{name}"
        );
    }
    // The pulse removes the first impact's energy: at most one (slow) bounce.
    let pulse = &case(&cases, "pulse").metrics;
    assert!(pulse.bounce.separations() <= 1);
    assert!(pulse.first_entry_speed > 0.1);
}

/// `colgate_joint_damping` is what it says: the joint viscous friction it returns, mapped to the
/// handle through the plant's own friction model (`J_aᵀ·τ_f(J_a·ẋ)` with `f_c = 0`), damps x at
/// `margin·K·T/2`.
#[test]
fn fig5_colgate_joint_damping_gives_the_handle_margin_k_t_over_2() {
    use haptic2d::device::dynamics::LumpedDynamics;
    use haptic2d::device::linalg::{j_mul_v, jt_mul_v};
    use haptic2d_lab::scenarios::walls_with_device::{colgate_joint_damping, WALL_STIFFNESS};
    let p = Fig5Params::default();
    for margin in [0.5, 2.0] {
        let mut h = p.haptic.clone();
        h.device.f_v = colgate_joint_damping(&h, p.rate, margin).expect("damping");
        h.device.f_c = 0.0;
        let dev = haptic2d::device::TwinPantograph::new(h.device, 1.0 / p.rate, h.observer)
            .expect("device");
        let x0 = [
            h.device.workspace_center_x,
            h.device.workspace_center_y,
            0.0,
        ];
        let j = dev.jacobian(&x0).expect("jacobian");
        let v = 0.1; // m/s along x
        let tau_f = LumpedDynamics::new(&h.device).joint_friction(&j_mul_v(&j, &[v, 0.0, 0.0]));
        let b_x = jt_mul_v(&j, &tau_f)[0] / v;
        let want = margin * WALL_STIFFNESS / (2.0 * p.rate);
        assert!((b_x - want).abs() < 1e-9 * want, "b_x {b_x} vs {want}");
    }
    // The default margin 2 at 500 Hz: about 1.44e-2 N·m·s/rad, against the spec's 1e-4.
    let f_v = colgate_joint_damping(&p.haptic, p.rate, 2.0).expect("damping");
    assert!((f_v - 1.44e-2).abs() < 0.01e-2, "{f_v}");
    assert!(colgate_joint_damping(&p.haptic, p.rate, -1.0).is_err());
}

/// Fig. 5 with the four-channel loop on the spec's undamped device: SEH and ZOH keep bouncing and the
/// loop is active (ratios above 1); the pulse and hysteretic walls damp the bouncing but miss W7/W6.
#[test]
fn fig5_four_channel_spec_device_is_active() {
    let cases = run(&Fig5Params::spec_device()).expect("runs");
    report("four-channel, spec device", &cases);
    for name in ["seh", "zoh"] {
        let m = &case(&cases, name).metrics;
        assert!(m.pass, "{name} keeps bouncing");
        assert!(m.bounce.separations() >= 20, "{name}");
        assert!(m.bounce.contact_ratios[0] > 1.0, "{name}: active loop");
    }
    assert!(!case(&cases, "pulse").metrics.pass);
    assert!(!case(&cases, "hysteretic").metrics.pass);
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

/// The virtual coupling on the damped device is dissipative: the hysteretic wall settles (Fig. 6),
/// but so do SEH and ZOH, so Fig. 5 fails there. The pulse wall settles too, but since the safety
/// layer (start-up alignment and 0.5 s torque ramp, final clamp, workspace wall) it does so after one
/// separation (first ratio 0.86, settled at 9.6 s), which W7 ("settles at the first impact") does
/// not count as a pass; this comparison run is reported, not a claim. Cause (traced in
/// `fig5_coupling_pulse.rs`): the alignment anchors θ at a quantised reading 0.8 mrad off, the box
/// lands tilted and its two corners enter the wall in different samples, so the first corner's
/// pulse is sized for the whole box.
#[test]
fn fig6_coupling_settles_every_wall() {
    let cases = run(&Fig5Params::coupling()).expect("runs");
    report("coupling", &cases);
    let pulse = &case(&cases, "pulse").metrics;
    assert!(pulse.bounce.separations() <= 1, "{pulse:?}");
    assert!(case(&cases, "hysteretic").metrics.pass);
    for name in ["seh", "zoh"] {
        let m = &case(&cases, name).metrics;
        assert!(!m.pass, "{name}");
        assert!(m.bounce.separations() <= 3, "{name}");
        assert!(m.bounce.settle_time.is_some(), "{name}");
    }
}

/// The default controller on the spec's device (issue 36: `C6 = −1`, `C5 = 2`, `D_m = 1`). No safety
/// stop (`run` errors on one); the hysteretic wall passes (Fig. 6); the pulse wall does not settle at
/// the first impact (its claim is carried by the former default, see `fig5_former_default_settles_the_
/// pulse_wall`); SEH and ZOH do not keep bouncing (Fig. 5 fails): without force reflection (C2 = 0)
/// the handle does not stop with the box at an impact and its momentum is dissipated in the
/// coupling's dampers, so the box bounces at most twice (see the module docs of `experiments::fig5`).
#[test]
fn fig5_fig6_default_four_channel_on_the_spec_device() {
    let p = Fig5Params::default();
    assert_eq!(p.colgate_margin, None);
    let cases = run(&p).expect("runs without a safety stop");
    report("four-channel default", &cases);
    assert!(case(&cases, "hysteretic").metrics.pass);
    assert!(!case(&cases, "pulse").metrics.pass);
    for name in ["seh", "zoh"] {
        let m = &case(&cases, name).metrics;
        assert!(!m.pass, "{name}");
        assert!(
            m.bounce.separations() <= 2,
            "{name}: {}",
            m.bounce.separations()
        );
    }
}

/// The former default (`C6 = −1`, `C5 = 0`, `D_m = 2`), which carries the pulse claim in `reproduce`:
/// the box settles at the first impact (W7).
#[test]
fn fig5_former_default_settles_the_pulse_wall() {
    use haptic2d::control::four_channel::FourChannelGains;
    use haptic2d::haptic::{ControllerKind, HapticConfig};
    let p = Fig5Params {
        haptic: HapticConfig {
            controller: ControllerKind::FourChannel(FourChannelGains::master_force_feedback()),
            ..HapticConfig::default()
        },
        ..Fig5Params::default()
    };
    let c = haptic2d_lab::scenarios::walls_with_device::run_case(
        &p,
        "pulse",
        "pulse",
        haptic2d_lab::scenarios::walls_with_device::Fig5Expectation::SettlesAtFirstImpact,
    )
    .expect("runs");
    report("former default", std::slice::from_ref(&c));
    assert!(c.metrics.pass, "{:?}", c.metrics);
}
