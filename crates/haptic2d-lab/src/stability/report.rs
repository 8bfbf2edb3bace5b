//! The stability report of a configured loop (what `haptic2d stability` prints) and the gate
//! [`check_released_stability`] that `haptic2d run` applies before driving a real device.

use std::fmt::Write as _;

use haptic2d::haptic::HapticConfig;
use haptic2d::world::World;

use super::eig::Complex;
use super::loop_model::{AxisReport, LoopModel, Verdict, MIN_DECAY_RATE};

/// The analysis of one configured loop.
#[derive(Clone, Debug, PartialEq)]
pub struct StabilityReport {
    /// Controller name (for the text).
    pub controller: String,
    /// Loop rate (Hz).
    pub rate: f64,
    /// The model analysed.
    pub model: LoopModel,
    /// Per axis x, y, θ.
    pub axes: [AxisReport; 3],
}

/// Builds and analyses the loop of `config` around `world` at `rate` (Hz) with `delay` extra output
/// samples; `controller` names the configuration in the text.
pub fn analyse_config(
    config: &HapticConfig,
    world: &World,
    rate: f64,
    delay: usize,
    controller: &str,
) -> Result<StabilityReport, String> {
    let model = LoopModel::new(config, world, rate, delay)?;
    let axes = model.analyse()?;
    Ok(StabilityReport {
        controller: controller.to_string(),
        rate,
        model,
        axes,
    })
}

fn pole(p: Complex) -> String {
    if p.1.abs() < 1e-9 {
        format!("{:+.1}", p.0)
    } else {
        format!("{:+.1} ± {:.1}j", p.0, p.1.abs())
    }
}

/// The right-most continuous poles, one per conjugate pair, at most `n`.
fn rightmost_poles(poles: &[Complex], n: usize) -> String {
    poles
        .iter()
        .filter(|p| p.1 >= 0.0)
        .take(n)
        .map(|p| pole(*p))
        .collect::<Vec<_>>()
        .join(", ")
}

impl StabilityReport {
    /// True when no axis is unstable with the hand released.
    pub fn released_stable(&self) -> bool {
        self.axes
            .iter()
            .all(|a| a.verdict() != Verdict::UnstableReleased)
    }

    /// The report as text: environment, then per axis the right-most continuous poles and the
    /// sampled-data growth rate held and released, and the verdict.
    pub fn text(&self) -> String {
        let m = &self.model;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "controller {} at {} Hz ({} extra output sample{}); contact: {} corners, normal law {:.0} N/m, {:.2} N s/m each, friction stick {:.0} N/m, {:.2} N s/m each, lever {:.4} m",
            self.controller,
            self.rate,
            m.delay,
            if m.delay == 1 { "" } else { "s" },
            m.env.contacts,
            m.env.normal.0,
            m.env.normal.1,
            m.env.friction.0,
            m.env.friction.1,
            m.env.lever
        );
        for r in &self.axes {
            let a = &r.model;
            let _ = writeln!(
                s,
                "axis {}: device m {:.4}, b {:.4}; slave {:.4}; against the {} spring K_e {:.4}, B_e {:.4} (world units)",
                r.axis, a.m, a.b, a.m_s, r.contact, a.k_e, a.b_e
            );
            for (cond, p) in [("held", &r.held), ("released", &r.released)] {
                let _ = writeln!(
                    s,
                    "  {cond:<8} right-most poles {} 1/s; sampled growth {:+.2} 1/s",
                    rightmost_poles(&p.continuous, 2),
                    p.growth
                );
            }
            let _ = writeln!(s, "  verdict: {}", r.verdict().label());
        }
        let _ = writeln!(
            s,
            "(\"stable\" = both conditions decay at >= {MIN_DECAY_RATE} 1/s at this rate)"
        );
        s
    }
}

/// Refuses a configuration whose loop grows with the hand released on some axis, at the world's rate,
/// with one extra output sample (a real device's write may land a tick late). The error names the
/// axis, the growth rate and the fix.
pub fn check_released_stability(config: &HapticConfig, world: &World) -> Result<(), String> {
    let rate = 1.0 / world.params.dt;
    let r = analyse_config(config, world, rate, 1, config.controller.name())?;
    for a in &r.axes {
        if a.verdict() == Verdict::UnstableReleased {
            let p = a.released.rightmost();
            return Err(format!(
                "the {} controller is unstable on axis {} with the hand released (sampled growth {:+.1} 1/s at {} Hz, right-most pole {}): a released handle would oscillate with growing amplitude. Fix: use `--controller four-channel` (the default: local force feedback C6 = -1, C5 = 2, with a small damping injection), check with `haptic2d stability`, or pass --allow-unstable to override",
                config.controller.name(),
                a.axis,
                a.released.growth,
                rate,
                pole(p)
            ));
        }
    }
    Ok(())
}
