//! The 1-D wall harness (§5.1, §13.1): a mass pushed by a constant force into a wall at `x = 0`.
//!
//! Free space is `x > 0`. At each sample `k` the harness reads the gap `d_k = x_k` and the velocity
//! `v_k`, optionally applies the paper method's entry impulse, evaluates the wall law (called at every
//! sample, with the signed-gap history), optionally passes the force through the passivity controller
//! of §12 or a user hook, holds the result over the sample and advances the mass in one of three
//! integration modes. It records the time series and computes the body-level metrics of §13.1.

use haptic2d::control::passivity::PassivityController;
use haptic2d::laws::normal::{NormalInput, NormalLaw, NormalModel};

/// Speed below which the body counts as settled (m/s), §13.1.
pub const SETTLE_SPEED: f64 = 1e-3;

/// How the harness advances the mass between samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WallIntegration {
    /// Exact motion under the held force (§5.1), including plant damping `b`. Lossless for the mass.
    #[default]
    ExactZoh,
    /// VE mode: semi-implicit (symplectic) Euler of §6.2, `v⁺ = v + T·F/m; x⁺ = x + T·v⁺`. Plant
    /// damping, if any, is applied implicitly: `v⁺ = (v + T·F/m)/(1 + b·T/m)`.
    SemiImplicit,
    /// Explicit Euler, `x⁺ = x + T·v; v⁺ = v + T·(F − b·v)/m` (active; for comparison, W9).
    ExplicitEuler,
}

/// The paper method's collision step (§5.9, §7.4 in 1-D): on the first sample with `d ≤ 0` after being
/// outside, if the approach speed exceeds `v_c`, the velocity jumps to `−e·v` before the law runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EntryImpulse {
    /// Poisson/Newton restitution `e` (dimensionless, 0..=1).
    pub e: f64,
    /// Collision velocity threshold `v_c` (m/s).
    pub v_c: f64,
}

impl EntryImpulse {
    /// The paper's defaults: `e = 0.5`, `v_c = 0.02 m/s`.
    pub fn paper() -> Self {
        Self { e: 0.5, v_c: 0.02 }
    }
}

/// Parameters of one harness run (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallConfig {
    /// Object mass `m` (kg).
    pub mass: f64,
    /// Plant (physical) viscous damping `b` (N·s/m), e.g. Colgate's device damping; 0 = undamped.
    pub damping: f64,
    /// Constant push toward the wall (N), applied along `−x`.
    pub push: f64,
    /// Initial gap `x_0` (m); positive = outside.
    pub gap0: f64,
    /// Initial velocity `v_0` (m/s).
    pub v0: f64,
    /// Sample period `T` (s).
    pub dt: f64,
    /// Simulated duration (s); the run has `round(duration/T)` samples.
    pub duration: f64,
    /// Integration mode.
    pub integration: WallIntegration,
    /// Entry impulse of the paper method (`None` for every other wall).
    pub impulse: Option<EntryImpulse>,
    /// Passivity observer/controller on the wall port (`None` = off). The port carries the wall force
    /// only; the push is an external input (§12).
    pub passivity: Option<PassivityController>,
}

impl WallConfig {
    /// The normative Fig. 4 harness (§5.10, §13.1): `m = 0.5 kg`, `b = 0`, push 2 N, at rest 0.02 m
    /// from the wall, `T = 2 ms`, 10 s, exact-ZOH mode, no impulse, no passivity controller.
    pub fn fig4() -> Self {
        Self {
            mass: 0.5,
            damping: 0.0,
            push: 2.0,
            gap0: 0.02,
            v0: 0.0,
            dt: 0.002,
            duration: 10.0,
            integration: WallIntegration::ExactZoh,
            impulse: None,
            passivity: None,
        }
    }
    /// Checks the parameters; the error names the bad one.
    pub fn validate(&self) -> Result<(), String> {
        let pos = |key: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "wall harness: `{key}` must be finite and > 0, got {v}"
                ))
            }
        };
        let nonneg = |key: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "wall harness: `{key}` must be finite and ≥ 0, got {v}"
                ))
            }
        };
        let finite = |key: &str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(format!("wall harness: `{key}` must be finite, got {v}"))
            }
        };
        pos("mass", self.mass)?;
        nonneg("damping", self.damping)?;
        finite("push", self.push)?;
        finite("gap0", self.gap0)?;
        finite("v0", self.v0)?;
        pos("dt", self.dt)?;
        nonneg("duration", self.duration)?;
        if let Some(imp) = self.impulse {
            if !(0.0..=1.0).contains(&imp.e) {
                return Err(format!(
                    "wall harness: impulse `e` must be in [0, 1], got {}",
                    imp.e
                ));
            }
            nonneg("impulse v_c", imp.v_c)?;
        }
        if let Some(pc) = &self.passivity {
            pc.validate()?;
        }
        Ok(())
    }
}

/// One recorded sample (state at `t = kT`, force held over `[kT, (k+1)T)`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallSample {
    /// Time `t_k` (s).
    pub t: f64,
    /// Position `x_k` (m); the gap, negative inside the wall.
    pub x: f64,
    /// Velocity `v_k` (m/s), before any entry impulse of this sample.
    pub v: f64,
    /// Wall force actually held over the sample (N, along `+x`), after the PC or hook.
    pub f: f64,
    /// Wall force from the law alone (N).
    pub f_env: f64,
    /// Passivity-controller damping `α_k` (N·s/m); 0 without a PC.
    pub alpha: f64,
    /// Observed port energy `E_obs,k` (J); 0 without a PC.
    pub e_obs: f64,
    /// Energy stored in the wall law after this sample (J).
    pub stored: f64,
}

/// What a per-sample hook sees (after the law and the passivity controller).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallHookInput {
    /// Sample index `k`.
    pub k: usize,
    /// Time `t_k` (s).
    pub t: f64,
    /// Position `x_k` (m).
    pub x: f64,
    /// Velocity `v_k` (m/s), after any entry impulse.
    pub v: f64,
    /// Backward-difference velocity `(x_k − x_{k−1})/T` (m/s), as a device would measure it.
    pub v_hat: f64,
    /// The force about to be held (N).
    pub f: f64,
    /// Sample period `T` (s).
    pub dt: f64,
}

/// One wall contact: entry and (if it ends) separation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallContact {
    /// Index of the first sample with gap `< 0`.
    pub entry_index: usize,
    /// Entry speed `−v` at that sample (m/s).
    pub entry_speed: f64,
    /// Index of the separation sample (gap back to `≥ 0`), if any.
    pub exit_index: Option<usize>,
    /// Exit speed `v` at the separation sample (m/s), if any.
    pub exit_speed: Option<f64>,
}

impl WallContact {
    /// Contact ratio exit speed / entry speed, if the contact ended.
    pub fn ratio(&self) -> Option<f64> {
        self.exit_speed.map(|v| v / self.entry_speed)
    }
}

/// Body-level metrics of §13.1 for one run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WallMetrics {
    /// Every contact, in order.
    pub contacts: Vec<WallContact>,
    /// Number of separations (gap from `< 0` to `≥ 0`).
    pub separations: usize,
    /// Earliest time after which `|v| < 1e-3 m/s` for all remaining samples (s); `None` if never.
    pub settle_time: Option<f64>,
    /// Penetration `max(0, −x)` at the last sample (m).
    pub final_penetration: f64,
    /// Largest penetration over the run (m).
    pub max_penetration: f64,
    /// Smallest observed port energy (J); 0 without a PC.
    pub min_e_obs: f64,
    /// Largest PC damping applied (N·s/m); 0 without a PC.
    pub max_alpha: f64,
}

impl WallMetrics {
    /// Computes the metrics from a recorded series (samples evenly spaced).
    pub fn from_samples(samples: &[WallSample]) -> Self {
        let mut m = WallMetrics::default();
        let mut prev_gap: Option<f64> = None;
        for (k, s) in samples.iter().enumerate() {
            let outside_before = prev_gap.is_none_or(|g| g >= 0.0);
            if s.x < 0.0 && outside_before {
                m.contacts.push(WallContact {
                    entry_index: k,
                    entry_speed: -s.v,
                    exit_index: None,
                    exit_speed: None,
                });
            } else if s.x >= 0.0 && prev_gap.is_some_and(|g| g < 0.0) {
                m.separations += 1;
                if let Some(c) = m.contacts.last_mut() {
                    c.exit_index = Some(k);
                    c.exit_speed = Some(s.v);
                }
            }
            prev_gap = Some(s.x);
            m.max_penetration = m.max_penetration.max(-s.x);
            m.min_e_obs = m.min_e_obs.min(s.e_obs);
            m.max_alpha = m.max_alpha.max(s.alpha);
        }
        if let Some(last) = samples.last() {
            m.final_penetration = (-last.x).max(0.0);
            m.settle_time = match samples.iter().rposition(|s| s.v.abs() >= SETTLE_SPEED) {
                None => Some(samples[0].t),
                Some(j) if j + 1 < samples.len() => Some(samples[j + 1].t),
                Some(_) => None,
            };
        }
        m
    }
    /// Contact ratios (exit/entry) of the contacts that ended, in order.
    pub fn ratios(&self) -> Vec<f64> {
        self.contacts.iter().filter_map(|c| c.ratio()).collect()
    }
    /// Entry speeds of every contact, in order (m/s).
    pub fn entry_speeds(&self) -> Vec<f64> {
        self.contacts.iter().map(|c| c.entry_speed).collect()
    }
}

/// The result of one harness run.
#[derive(Clone, Debug, PartialEq)]
pub struct WallRun {
    /// The configuration that produced it.
    pub config: WallConfig,
    /// The wall law's name ([`NormalModel::name`]).
    pub law: &'static str,
    /// The recorded time series, one entry per sample.
    pub samples: Vec<WallSample>,
    /// Metrics of §13.1.
    pub metrics: WallMetrics,
}

/// Runs the harness with `law` (given fresh; its state is reset first).
pub fn run_wall(config: &WallConfig, law: NormalModel) -> Result<WallRun, String> {
    simulate(config, law, None)
}

/// Runs the harness with a per-sample hook: it sees the state and the force about to be held and
/// returns the force to hold instead (N). It runs after the passivity controller, if any.
pub fn run_wall_with_hook(
    config: &WallConfig,
    law: NormalModel,
    hook: &mut dyn FnMut(&WallHookInput) -> f64,
) -> Result<WallRun, String> {
    simulate(config, law, Some(hook))
}

/// The harness loop.
fn simulate(
    config: &WallConfig,
    mut law: NormalModel,
    mut hook: Option<&mut dyn FnMut(&WallHookInput) -> f64>,
) -> Result<WallRun, String> {
    config.validate()?;
    law.validate()?;
    law.reset();
    let mut pc = config.passivity;
    if let Some(pc) = &mut pc {
        pc.reset();
    }
    let (m, b, dt) = (config.mass, config.damping, config.dt);
    let n = (config.duration / dt).round() as usize;
    let mut samples = Vec::with_capacity(n);

    let (mut x, mut v) = (config.gap0, config.v0);
    let mut d = [x; 3];
    let mut hist: u8 = 0;
    let mut x_prev = x;
    let mut inside_prev = false;
    for k in 0..n {
        let t = k as f64 * dt;
        let v_state = v;
        // 1. Gap history (signed, §5.5).
        d = [x, d[0], d[1]];
        hist = (hist + 1).min(3);
        // 2. Paper method: a new contact (d ≤ 0) approaching faster than v_c collides (§8.2, §7.4).
        let inside = x <= 0.0;
        if let Some(imp) = config.impulse {
            if inside && !inside_prev && -v > imp.v_c {
                v *= -imp.e;
            }
        }
        inside_prev = inside;
        // 3. Wall law.
        let input = NormalInput {
            d,
            hist,
            c0: v,
            dt,
            m_eff: m,
        };
        let f_env = law.force(&input);
        // 4. Passivity controller on the wall port, then the user hook.
        let v_hat = if k == 0 { v } else { (x - x_prev) / dt };
        x_prev = x;
        let (mut f, alpha, e_obs) = match &mut pc {
            Some(pc) => {
                let f = pc.update(x, v_hat, f_env, dt);
                (f, pc.alpha(), pc.e_obs())
            }
            None => (f_env, 0.0, 0.0),
        };
        if let Some(h) = hook.as_mut() {
            f = h(&WallHookInput {
                k,
                t,
                x,
                v,
                v_hat,
                f,
                dt,
            });
        }
        samples.push(WallSample {
            t,
            x,
            v: v_state,
            f,
            f_env,
            alpha,
            e_obs,
            stored: law.stored_energy(),
        });
        // 5. Advance the mass under the held force.
        let f_total = f - config.push;
        match config.integration {
            WallIntegration::ExactZoh => {
                if b > 0.0 {
                    let v_inf = f_total / b;
                    let lambda = (-b * dt / m).exp();
                    x += v_inf * dt + (v - v_inf) * (m / b) * (1.0 - lambda);
                    v = v_inf + (v - v_inf) * lambda;
                } else {
                    x += dt * v + 0.5 * dt * dt * f_total / m;
                    v += dt * f_total / m;
                }
            }
            WallIntegration::SemiImplicit => {
                v = (v + dt * f_total / m) / (1.0 + b * dt / m);
                x += dt * v;
            }
            WallIntegration::ExplicitEuler => {
                let a = (f_total - b * v) / m;
                x += dt * v;
                v += dt * a;
            }
        }
    }
    let metrics = WallMetrics::from_samples(&samples);
    Ok(WallRun {
        config: *config,
        law: law.name(),
        samples,
        metrics,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_flight_entry_speed_and_validation() {
        let cfg = WallConfig::fig4();
        let r = run_wall(&cfg, NormalModel::from_name("zoh", false).expect("known")).expect("run");
        assert_eq!(r.samples.len(), 5000);
        // √(2·F·g0/m) = 0.400 m/s, sampled one step after the crossing at most.
        let v_in = r.metrics.contacts[0].entry_speed;
        assert!((v_in - 0.4).abs() < 0.4 * 0.02, "entry speed {v_in}");
        let bad = WallConfig { mass: 0.0, ..cfg };
        let e = run_wall(&bad, NormalModel::default()).unwrap_err();
        assert!(e.contains("mass"), "{e}");
    }

    #[test]
    fn exact_zoh_with_damping_matches_the_closed_form() {
        // No wall in reach: v(t) = v∞ + (v0 − v∞)·e^{−bt/m} with v∞ = −F/b.
        let cfg = WallConfig {
            damping: 2.0,
            gap0: 10.0,
            duration: 1.0,
            ..WallConfig::fig4()
        };
        let r = run_wall(&cfg, NormalModel::from_name("zoh", false).expect("known")).expect("run");
        let last = r.samples.last().expect("samples");
        let (v_inf, rate) = (-2.0 / 2.0, 2.0 / 0.5);
        let v_exact = v_inf * (1.0 - (-rate * last.t).exp());
        assert!((last.v - v_exact).abs() < 1e-12, "{} vs {v_exact}", last.v);
    }
}
