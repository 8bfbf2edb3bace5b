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
//!    names the interval of largest perceived stiffness (3AFC: each of the two reference intervals
//!    is perceived with its own noise).
//! 4. **Response time**: `2·2·press_time` of exploration plus a log-normal decision time of median
//!    `decision_time` (log-sd 0.3): a placeholder, not a model of decision dynamics.
//!
//! The felt stiffness of a stimulus is computed once and cached (the world is deterministic); the
//! noise, lapses and RTs come from a generator seeded by the session seed and the trial number, so a
//! resumed session answers exactly as an uninterrupted one.

use super::file::{ObserverSection, Study, Task};
use super::numeric::Z75;
use super::rng::{mix, Rng};
use super::schedule::TrialSpec;
use super::stimulus;
use haptic2d::scene::SceneError;
use std::collections::HashMap;

pub use super::explore::{explore, Exploration, Felt};

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
    /// Same–different: the differencing rule's criterion, in units of the percept noise `σ`
    /// ("different" when the two percepts differ by more).
    pub sd_criterion: f64,
    /// Magnitude estimation: the exponent `a` of Stevens' power law on the percepts (the number
    /// is `modulus·(K̂_cmp/K̂_ref)^a`).
    pub magnitude_exponent: f64,
    /// Press and stroke: each change of force is ramped linearly over this time (s); 0 = a step.
    pub press_ramp: f64,
    /// How the hand explores (press, tap or stroke).
    pub exploration: Exploration,
    /// The hand's damping on the probe's velocity during presses and strokes (N·s/m).
    pub hand_damping: f64,
    /// The hand's grip on the probe's orientation during presses and strokes: a torsional spring
    /// to the starting angle (N·m/rad; 0 = the hand only pushes, the probe may turn).
    pub grip_stiffness: f64,
    /// The grip's torsional damping (N·m·s/rad).
    pub grip_damping: f64,
    /// Tap: the speed of the probe toward the wall (m/s).
    pub tap_speed: f64,
    /// Tap: the window after contact in which the wall force is felt (s).
    pub tap_window: f64,
    /// Stroke: the normal force pressing the probe on the wall (N).
    pub stroke_normal: f64,
    /// Stroke: the two tangential pushes `F_t1 < F_t2` (N).
    pub stroke_forces: [f64; 2],
    /// Stroke: the tremor's amplitude on the tangential push (N).
    pub tremor_amplitude: f64,
    /// Stroke: the tremor's frequency (Hz).
    pub tremor_hz: f64,
}

impl Default for ObserverParams {
    fn default() -> Self {
        Self {
            weber_fraction: 0.15,
            lapse_rate: 0.02,
            press_forces: [1.0, 2.0],
            press_time: 1.0,
            decision_time: 0.6,
            sd_criterion: 1.8,
            magnitude_exponent: 0.8,
            press_ramp: 0.0,
            exploration: Exploration::Press,
            hand_damping: 0.0,
            grip_stiffness: 0.0,
            grip_damping: 0.0,
            tap_speed: 0.1,
            tap_window: 0.01,
            stroke_normal: 2.0,
            stroke_forces: [0.1, 0.3],
            tremor_amplitude: 0.05,
            tremor_hz: 10.0,
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
            press_ramp: s.press_ramp.unwrap_or(d.press_ramp),
            sd_criterion: s.sd_criterion.unwrap_or(d.sd_criterion),
            magnitude_exponent: s.magnitude_exponent.unwrap_or(d.magnitude_exponent),
            exploration: d.exploration,
            hand_damping: s.hand_damping.unwrap_or(d.hand_damping),
            grip_stiffness: s.grip_stiffness.unwrap_or(d.grip_stiffness),
            grip_damping: s.grip_damping.unwrap_or(d.grip_damping),
            tap_speed: s.tap_speed.unwrap_or(d.tap_speed),
            tap_window: s.tap_window.unwrap_or(d.tap_window),
            stroke_normal: s.stroke_normal.unwrap_or(d.stroke_normal),
            stroke_forces: s.stroke_forces.unwrap_or(d.stroke_forces),
            tremor_amplitude: s.tremor_amplitude.unwrap_or(d.tremor_amplitude),
            tremor_hz: s.tremor_hz.unwrap_or(d.tremor_hz),
        };
        let mut p = p;
        if let Some(e) = &s.exploration {
            match Exploration::from_name(e) {
                Ok(x) => p.exploration = x,
                Err(m) => errs.push(SceneError::new(
                    "observer.exploration",
                    m,
                    "exploration = \"press\" (static stiffness), \"tap\" (rate-hardness) or \"stroke\" (tangential stick stiffness)",
                )),
            }
        }
        let n = errs.len();
        p.check(&mut |field, msg, fix| {
            errs.push(SceneError::new(format!("observer.{field}"), msg, fix))
        });
        (errs.len() == n).then_some(p)
    }

    /// Checks the ranges; each problem is reported as `(field, message, fix)`.
    pub fn check(&self, report: &mut dyn FnMut(&str, String, &str)) {
        self.check_press(report);
        self.check_tap_stroke(report);
        let r = self.decision_time;
        if !(r.is_finite() && (0.0..=60.0).contains(&r)) {
            report(
                "decision_time",
                format!("{r}"),
                "give a time in [0, 60] s, e.g. 0.6",
            );
        }
    }

    /// [`check`](Self::check) of the perception and the press: Weber fraction to grip damping.
    fn check_press(&self, report: &mut dyn FnMut(&str, String, &str)) {
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
        let c = self.sd_criterion;
        if !(c.is_finite() && c > 0.0 && c <= 10.0) {
            report(
                "sd_criterion",
                format!("{c}"),
                "give the same–different criterion in (0, 10] units of the percept noise, e.g. 1.8",
            );
        }
        let a = self.magnitude_exponent;
        if !(a.is_finite() && a > 0.0 && a <= 5.0) {
            report(
                "magnitude_exponent",
                format!("{a}"),
                "give Stevens' exponent in (0, 5], e.g. 0.8",
            );
        }
        let r = self.press_ramp;
        if !(r.is_finite() && r >= 0.0 && r <= 0.8 * t) {
            report(
                "press_ramp",
                format!("{r}"),
                "give a ramp time in [0, 0.8·press_time] s, e.g. 0.5 with press_time = 1.0",
            );
        }
        let b = self.hand_damping;
        if !(b.is_finite() && (0.0..=200.0).contains(&b)) {
            report(
                "hand_damping",
                format!("{b}"),
                "give a damping in [0, 200] N·s/m, e.g. 10.0",
            );
        }
        let g = self.grip_stiffness;
        if !(g.is_finite() && (0.0..=50.0).contains(&g)) {
            report(
                "grip_stiffness",
                format!("{g}"),
                "give a torsional stiffness in [0, 50] N·m/rad, e.g. 20.0",
            );
        }
        let gd = self.grip_damping;
        if !(gd.is_finite() && (0.0..=1.0).contains(&gd)) {
            report(
                "grip_damping",
                format!("{gd}"),
                "give a torsional damping in [0, 1] N·m·s/rad, e.g. 0.02",
            );
        }
    }

    /// [`check`](Self::check) of the tap and the stroke.
    fn check_tap_stroke(&self, report: &mut dyn FnMut(&str, String, &str)) {
        let v = self.tap_speed;
        if !(v.is_finite() && v > 0.0 && v <= 2.0) {
            report(
                "tap_speed",
                format!("{v}"),
                "give a speed in (0, 2] m/s, e.g. 0.1",
            );
        }
        let w = self.tap_window;
        if !(w.is_finite() && w > 0.0 && w <= 0.5) {
            report(
                "tap_window",
                format!("{w}"),
                "give a window in (0, 0.5] s, e.g. 0.01",
            );
        }
        let fnorm = self.stroke_normal;
        if !(fnorm.is_finite() && fnorm > 0.0 && fnorm <= MAX_PRESS_N) {
            report(
                "stroke_normal",
                format!("{fnorm}"),
                "give 0 < F_n ≤ 50 N, e.g. 2.0",
            );
        }
        let [t1, t2] = self.stroke_forces;
        if !(t1.is_finite() && t2.is_finite() && 0.0 <= t1 && t1 < t2 && t2 <= MAX_PRESS_N) {
            report(
                "stroke_forces",
                format!("[{t1}, {t2}]"),
                "give 0 ≤ F_t1 < F_t2 ≤ 50 N, below the friction's break-away, e.g. [0.1, 0.3]",
            );
        }
        let a = self.tremor_amplitude;
        if !(a.is_finite() && (0.0..=MAX_PRESS_N).contains(&a)) {
            report(
                "tremor_amplitude",
                format!("{a}"),
                "give an amplitude in [0, 50] N, e.g. 0.05",
            );
        }
        let h = self.tremor_hz;
        if !(h.is_finite() && h > 0.0 && h <= 100.0) {
            report(
                "tremor_hz",
                format!("{h}"),
                "give a frequency in (0, 100] Hz, e.g. 10.0",
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
    /// The interval (1 to the task's number) named as stiffer (stiffest); 0 in magnitude
    /// estimation.
    pub response: u8,
    /// Magnitude estimation: the number given to the comparison (the reference being the study's
    /// modulus); `None` in the other tasks.
    pub magnitude: Option<f64>,
    /// Response time (s): the simulated observer's from the start of the first interval (a model);
    /// the browser page's from the answer prompt (measured).
    pub rt: f64,
}

/// Anything that answers trials: the simulated observer, or a participant on the browser page
/// (`haptic2d study run --observer browser`).
pub trait Observer {
    /// Presents `spec` and returns the answer.
    fn answer(&mut self, study: &Study, spec: &TrialSpec) -> Result<Answer, String>;
    /// A short description for the session record (`simulated W=0.15 λ=0.02`).
    fn describe(&self) -> String;
    /// A rest break before `next` (the study's `[breaks]`, `order.rs`). The default (the simulated
    /// observer) does nothing; the browser session shows its break screen before `next`.
    fn rest(&mut self, _study: &Study, _next: &TrialSpec) -> Result<(), String> {
        Ok(())
    }
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
        let world = stimulus::interval_world(study, c, comparison, delta)?;
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
        let n = study.task.intervals();
        // 3AFC: a second reference interval, perceived with its own noise (drawn after the 2AFC
        // draws, so a 2AFC session's answers do not depend on this branch).
        let p_ref2 = if n == 3 {
            k_ref.ln() + sigma * rng.normal()
        } else {
            f64::NEG_INFINITY
        };
        let lapse = rng.uniform() < self.params.lapse_rate;
        let coin = 1 + rng.below(n) as u8;
        let ci = spec.comparison_interval;
        if study.task == Task::SameDifferent {
            // The differencing rule: "different" (1) when the two percepts differ by more than
            // the criterion (in units of the percept noise σ). A "same" trial (ci = 0) presents
            // the reference twice: p_cmp is then replaced by a second reference percept.
            let other = if ci == 0 {
                k_ref.ln() + (p_cmp - k_cmp.ln())
            } else {
                p_cmp
            };
            let different = (other - p_ref).abs() > self.params.sd_criterion * sigma;
            let response = if lapse { coin - 1 } else { u8::from(different) };
            let rt = 4.0 * self.params.press_time
                + self.params.decision_time * (0.3 * rng.normal()).exp();
            return Ok(Answer {
                response,
                rt,
                magnitude: None,
            });
        }
        if study.task == Task::Magnitude {
            // Stevens' power law on the percepts: the comparison's number is the modulus times
            // the ratio of perceived stiffnesses raised to the exponent `a` (no lapses: a number
            // is always given).
            let m = study.modulus * (self.params.magnitude_exponent * (p_cmp - p_ref)).exp();
            let rt = 4.0 * self.params.press_time
                + self.params.decision_time * (0.3 * rng.normal()).exp();
            return Ok(Answer {
                response: 0,
                rt,
                magnitude: Some(m),
            });
        }
        // The reference intervals in order: the ones that are not the comparison's.
        let refs: Vec<u8> = (1..=n as u8).filter(|&i| i != ci).collect();
        let response = if lapse {
            coin
        } else if p_cmp > p_ref && p_cmp > p_ref2 {
            ci
        } else if p_ref >= p_ref2 {
            refs[0]
        } else {
            refs[1]
        };
        let rt =
            4.0 * self.params.press_time + self.params.decision_time * (0.3 * rng.normal()).exp();
        Ok(Answer {
            response,
            rt,
            magnitude: None,
        })
    }

    fn describe(&self) -> String {
        let p = &self.params;
        let how = match p.exploration {
            Exploration::Press => format!("press_forces={:?} N", p.press_forces),
            Exploration::Tap => format!(
                "tap_speed={} m/s tap_window={} s",
                p.tap_speed, p.tap_window
            ),
            Exploration::Stroke => format!(
                "stroke_normal={} N stroke_forces={:?} N tremor={} N at {} Hz",
                p.stroke_normal, p.stroke_forces, p.tremor_amplitude, p.tremor_hz
            ),
        };
        format!(
            "simulated observer (a model, not data): weber_fraction={} lapse_rate={} exploration={} {how} press_time={} s press_ramp={} s hand_damping={} N s/m grip={} N m/rad, {} N m s/rad",
            p.weber_fraction, p.lapse_rate, p.exploration.name(), p.press_time, p.press_ramp, p.hand_damping, p.grip_stiffness, p.grip_damping
        )
    }
}
