//! Observers answer trials. [`SimulatedObserver`] is a **model** of a participant, for CI, piloting
//! designs and power estimates; its answers are never data about people.
//!
//! The model, per interval:
//! 1. **Exploration** (physics, deterministic): the stimulus's world is built from the study's scene,
//!    the scene's loads are replaced by the simulated hand, which presses the probe toward the wall
//!    with a constant force `F1` for `press_time`, then `F2` for `press_time`; the world is stepped
//!    with its real contact laws at its rate. The probe's mean position along `toward` over the last
//!    40 % of each press gives `x1`, `x2`, and the felt stiffness is `K = (F2 − F1)/(x2 − x1)` (N/m):
//!    the force increment over the displacement increment, which needs no knowledge of where the
//!    surface is. A press that does not come to rest against the wall is an error, not an answer.
//! 2. **Perception** (noise): the perceived log stiffness is `ln K + σ·ε`, `ε ~ N(0, 1)`, with
//!    `σ = ln(1 + W)/(√2·z₀.₇₅)`: two intervals whose stiffnesses differ by the Weber fraction `W`
//!    are then ordered correctly 75 % of the time (the JND at 75 % correct is `W·K`).
//! 3. **Decision**: with probability `λ` (lapse rate) the model answers at random; otherwise it
//!    names the interval of larger perceived stiffness.
//! 4. **Response time**: `2·2·press_time` of exploration plus a log-normal decision time of median
//!    `decision_time` (log-sd 0.3): a placeholder, not a model of decision dynamics.
//!
//! The felt stiffness of a stimulus is computed once and cached (the world is deterministic); the
//! noise, lapses and RTs come from a generator seeded by the session seed and the trial number, so a
//! resumed session answers exactly as an uninterrupted one.

use super::file::{ObserverSection, Study};
use super::numeric::Z75;
use super::rng::{mix, Rng};
use super::schedule::TrialSpec;
use super::stimulus;
use haptic2d::geom::Vec2;
use haptic2d::load::{Load, Profile};
use haptic2d::scene::SceneError;
use haptic2d::world::World;
use std::collections::HashMap;

/// The simulated observer's parameters (`[observer]` of the study file, or the CLI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObserverParams {
    /// Weber fraction `W` (dimensionless).
    pub weber_fraction: f64,
    /// Lapse rate `λ` (probability).
    pub lapse_rate: f64,
    /// Press forces `F1 < F2` (N).
    pub press_forces: [f64; 2],
    /// Duration of each press (s).
    pub press_time: f64,
    /// Median decision time (s).
    pub decision_time: f64,
}

impl Default for ObserverParams {
    fn default() -> Self {
        Self {
            weber_fraction: 0.15,
            lapse_rate: 0.02,
            press_forces: [1.0, 2.0],
            press_time: 1.0,
            decision_time: 0.6,
        }
    }
}

/// Largest press force of the simulated hand (N).
pub const MAX_PRESS_N: f64 = 50.0;

impl ObserverParams {
    /// Validates `[observer]` (defaults for what is absent).
    pub fn from_section(s: &ObserverSection, errs: &mut Vec<SceneError>) -> Option<Self> {
        let d = Self::default();
        let p = Self {
            weber_fraction: s.weber_fraction.unwrap_or(d.weber_fraction),
            lapse_rate: s.lapse_rate.unwrap_or(d.lapse_rate),
            press_forces: s.press_forces.unwrap_or(d.press_forces),
            press_time: s.press_time.unwrap_or(d.press_time),
            decision_time: s.decision_time.unwrap_or(d.decision_time),
        };
        let n = errs.len();
        p.check(&mut |field, msg, fix| {
            errs.push(SceneError::new(format!("observer.{field}"), msg, fix))
        });
        (errs.len() == n).then_some(p)
    }

    /// Checks the ranges; each problem is reported as `(field, message, fix)`.
    pub fn check(&self, report: &mut dyn FnMut(&str, String, &str)) {
        let w = self.weber_fraction;
        if !(w.is_finite() && w > 0.0 && w <= 5.0) {
            report(
                "weber_fraction",
                format!("{w}"),
                "give a Weber fraction in (0, 5], e.g. 0.15",
            );
        }
        let l = self.lapse_rate;
        if !(l.is_finite() && (0.0..=0.5).contains(&l)) {
            report(
                "lapse_rate",
                format!("{l}"),
                "give a probability in [0, 0.5], e.g. 0.02",
            );
        }
        let [f1, f2] = self.press_forces;
        if !(f1.is_finite() && f2.is_finite() && 0.0 < f1 && f1 < f2 && f2 <= MAX_PRESS_N) {
            report(
                "press_forces",
                format!("[{f1}, {f2}]"),
                "give 0 < F1 < F2 ≤ 50 N, e.g. [1.0, 2.0]",
            );
        }
        let t = self.press_time;
        if !(t.is_finite() && t > 0.0 && t <= 30.0) {
            report(
                "press_time",
                format!("{t}"),
                "give a press time in (0, 30] s, e.g. 1.0",
            );
        }
        let r = self.decision_time;
        if !(r.is_finite() && (0.0..=60.0).contains(&r)) {
            report(
                "decision_time",
                format!("{r}"),
                "give a time in [0, 60] s, e.g. 0.6",
            );
        }
    }

    /// The perceptual noise `σ` of the log stiffness that gives Weber fraction `W` at 75 % correct.
    pub fn sigma(&self) -> f64 {
        (1.0 + self.weber_fraction).ln() / (std::f64::consts::SQRT_2 * Z75)
    }
}

/// An answer to one trial.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Answer {
    /// The interval (1 or 2) named as stiffer.
    pub response: u8,
    /// Response time (s), measured from the start of the first interval.
    pub rt: f64,
}

/// Anything that answers trials: the simulated observer now; a browser page or device buttons later.
pub trait Observer {
    /// Presents `spec` and returns the answer.
    fn answer(&mut self, study: &Study, spec: &TrialSpec) -> Result<Answer, String>;
    /// A short description for the session record (`simulated W=0.15 λ=0.02`).
    fn describe(&self) -> String;
}

/// What one exploration measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Felt {
    /// Mean probe positions along `toward` at the end of the two presses (m).
    pub x: [f64; 2],
    /// Felt stiffness `(F2 − F1)/(x2 − x1)` (N/m).
    pub stiffness: f64,
}

/// Presses the probe of `world` toward the wall as the model's step 1 says.
pub fn explore(
    mut world: World,
    probe: usize,
    toward: [f64; 2],
    p: &ObserverParams,
) -> Result<Felt, String> {
    let dir = Vec2::new(toward[0], toward[1]);
    world.loads.clear();
    world.loads.push(Load {
        body: probe,
        force: dir * p.press_forces[0],
        torque: 0.0,
        per_mass: false,
        profile: Profile::Constant,
    });
    let dt = world.params.dt;
    let n = (p.press_time / dt).round().max(10.0) as usize;
    let tail = (n as f64 * 0.4).ceil() as usize;
    let mut x = [0.0; 2];
    for (phase, &f) in p.press_forces.iter().enumerate() {
        world.loads[0].force = dir * f;
        let mut sum = 0.0;
        for k in 0..n {
            if let Some(d) = world.step() {
                return Err(format!(
                    "the simulated observer's world diverged at t = {:.4} s: {d}",
                    world.time()
                ));
            }
            if k >= n - tail {
                let b = &world.bodies[probe];
                sum += b.pose.pos.x * dir.x + b.pose.pos.y * dir.y;
            }
        }
        x[phase] = sum / tail as f64;
        let b = &world.bodies[probe];
        let v = b.vel.x * dir.x + b.vel.y * dir.y;
        if !v.is_finite() || v.abs() > 0.01 {
            return Err(format!(
                "the probe is still moving at {v:.3} m/s along `toward` after {:.2} s at {f} N: it did not come to rest against a wall (check `toward`, `probe` and the wall's damping, or lengthen observer.press_time)",
                p.press_time
            ));
        }
    }
    let dx = x[1] - x[0];
    if !(dx.is_finite() && dx > 0.0) {
        return Err(format!(
            "the probe did not move further toward the wall under the larger force (Δx = {dx:e} m): no stiffness to feel"
        ));
    }
    Ok(Felt {
        x,
        stiffness: (p.press_forces[1] - p.press_forces[0]) / dx,
    })
}

/// The simulated observer (a model; see the module documentation).
#[derive(Clone, Debug)]
pub struct SimulatedObserver {
    /// Its parameters.
    pub params: ObserverParams,
    seed: u64,
    cache: HashMap<(usize, bool, u64), f64>,
}

impl SimulatedObserver {
    /// A simulated observer with `params`, its noise seeded by the session seed `seed`.
    pub fn new(params: ObserverParams, seed: u64) -> Self {
        Self {
            params,
            seed,
            cache: HashMap::new(),
        }
    }

    /// The felt stiffness (N/m) of condition `c`'s reference (`comparison = false`) or of its
    /// comparison at `delta`.
    pub fn felt(
        &mut self,
        study: &Study,
        c: usize,
        comparison: bool,
        delta: f64,
    ) -> Result<f64, String> {
        let key = (c, comparison, if comparison { delta.to_bits() } else { 0 });
        if let Some(k) = self.cache.get(&key) {
            return Ok(*k);
        }
        let cond = &study.conditions[c];
        let (name, vary) = if comparison {
            (&cond.comparison, Some((&cond.vary, delta)))
        } else {
            (&cond.reference, None)
        };
        let world = stimulus::world(study, name, vary).map_err(|e| {
            e.iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join("; ")
        })?;
        let probe = world
            .body_index(&study.probe)
            .ok_or_else(|| format!("the scene has no body called `{}`", study.probe))?;
        let felt = explore(world, probe, study.toward, &self.params).map_err(|e| {
            format!(
                "condition `{}`, {}: {e}",
                cond.name,
                if comparison {
                    format!("comparison at delta {delta}")
                } else {
                    "reference".into()
                }
            )
        })?;
        self.cache.insert(key, felt.stiffness);
        Ok(felt.stiffness)
    }
}

impl Observer for SimulatedObserver {
    fn answer(&mut self, study: &Study, spec: &TrialSpec) -> Result<Answer, String> {
        let k_ref = self.felt(study, spec.condition, false, 0.0)?;
        let k_cmp = self.felt(study, spec.condition, true, spec.delta)?;
        let mut rng = Rng::new(mix(self.seed, u64::from(spec.trial)));
        let sigma = self.params.sigma();
        let p_ref = k_ref.ln() + sigma * rng.normal();
        let p_cmp = k_cmp.ln() + sigma * rng.normal();
        let lapse = rng.uniform() < self.params.lapse_rate;
        let coin = 1 + rng.below(2) as u8;
        let response = if lapse {
            coin
        } else if p_cmp > p_ref {
            spec.comparison_interval
        } else {
            3 - spec.comparison_interval
        };
        let rt =
            4.0 * self.params.press_time + self.params.decision_time * (0.3 * rng.normal()).exp();
        Ok(Answer { response, rt })
    }

    fn describe(&self) -> String {
        format!(
            "simulated observer (a model, not data): weber_fraction={} lapse_rate={} press_forces={:?} N press_time={} s",
            self.params.weber_fraction, self.params.lapse_rate, self.params.press_forces, self.params.press_time
        )
    }
}
