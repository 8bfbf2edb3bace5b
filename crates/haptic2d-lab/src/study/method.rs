//! The psychophysical method of a study: the method of constant stimuli or transformed up/down
//! staircases (Levitt 1971), validated from `[method]`.

use super::file::MethodSection;
use haptic2d::scene::SceneError;

/// A transformed up/down staircase's parameters.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StaircaseSpec {
    /// Consecutive correct answers for one step down (2 → 70.7 %, 3 → 79.4 % correct).
    pub down: u32,
    /// Starting delta of each interleaved staircase of a condition.
    pub starts: Vec<f64>,
    /// Multiplicative step factor (> 1).
    pub step_factor: f64,
    /// Step factor until the second reversal.
    pub initial_step_factor: f64,
    /// Stop after this many trials.
    pub max_trials: u32,
    /// Stop after this many reversals.
    pub max_reversals: u32,
    /// Smallest delta.
    pub min_delta: f64,
    /// Largest delta.
    pub max_delta: f64,
}

impl StaircaseSpec {
    /// The proportion correct the rule converges to, `0.5^(1/down)` (Levitt 1971).
    pub fn target(&self) -> f64 {
        0.5f64.powf(1.0 / f64::from(self.down))
    }
}

/// The method.
#[derive(Clone, Debug, PartialEq)]
pub enum Method {
    /// Method of constant stimuli: every delta `repeats` times per condition, in random order.
    Constant {
        /// Deltas (unit of the varied parameter), each > 0.
        deltas: Vec<f64>,
        /// Presentations per delta and condition.
        repeats: u32,
    },
    /// Interleaved transformed up/down staircases.
    Staircase(StaircaseSpec),
}

/// Largest number of trials a study may schedule per condition.
pub const MAX_TRIALS_PER_CONDITION: u32 = 100_000;

impl Method {
    /// The largest delta the method can present (the easiest; practice uses it).
    pub fn largest_delta(&self) -> f64 {
        match self {
            Method::Constant { deltas, .. } => deltas.iter().copied().fold(0.0, f64::max),
            Method::Staircase(s) => s.max_delta,
        }
    }

    /// The smallest delta the method can present.
    pub fn smallest_delta(&self) -> f64 {
        match self {
            Method::Constant { deltas, .. } => deltas.iter().copied().fold(f64::INFINITY, f64::min),
            Method::Staircase(s) => s.min_delta,
        }
    }

    /// The delta of practice trials: the largest constant delta, or the largest staircase start.
    pub fn practice_delta(&self) -> f64 {
        match self {
            Method::Constant { .. } => self.largest_delta(),
            Method::Staircase(s) => s.starts.iter().copied().fold(0.0, f64::max),
        }
    }

    /// Validates `[method]`; problems go to `errs` with the field and the fix.
    /// `own_deltas`: every condition gives its own `deltas`, so `[method]` need not.
    pub fn from_section(
        m: &MethodSection,
        own_deltas: bool,
        errs: &mut Vec<SceneError>,
    ) -> Option<Method> {
        let mut e = |field: &str, msg: String, fix: &str| {
            errs.push(SceneError::new(format!("method.{field}"), msg, fix))
        };
        let positive = |x: f64| x.is_finite() && x > 0.0;
        match m.kind.as_str() {
            "constant" => {
                let deltas = m.deltas.clone().unwrap_or_default();
                if deltas.is_empty() && !own_deltas {
                    e("deltas", "the method of constant stimuli needs its deltas".into(), "e.g. deltas = [50.0, 100.0, 200.0] (comparison − reference, unit of `vary`)");
                }
                // The sign is checked per condition (file.rs): > 0 for a discrimination, any for
                // a PSE condition.
                if let Some(d) = deltas.iter().find(|d| !d.is_finite()) {
                    e(
                        "deltas",
                        format!("{d} is not a number"),
                        "give finite deltas",
                    );
                }
                let repeats = m.repeats.unwrap_or(0);
                if repeats == 0 || repeats > MAX_TRIALS_PER_CONDITION {
                    e(
                        "repeats",
                        format!("{repeats} repeats"),
                        "give 1 to 100000 presentations per delta, e.g. repeats = 20",
                    );
                }
                for k in [
                    "rule",
                    "starts",
                    "step_factor",
                    "initial_step_factor",
                    "max_trials",
                    "max_reversals",
                    "min_delta",
                    "max_delta",
                ] {
                    let given = match k {
                        "rule" => m.rule.is_some(),
                        "starts" => m.starts.is_some(),
                        "step_factor" => m.step_factor.is_some(),
                        "initial_step_factor" => m.initial_step_factor.is_some(),
                        "max_trials" => m.max_trials.is_some(),
                        "max_reversals" => m.max_reversals.is_some(),
                        "min_delta" => m.min_delta.is_some(),
                        _ => m.max_delta.is_some(),
                    };
                    if given {
                        e(
                            k,
                            "is a staircase setting".into(),
                            "remove it, or set kind = \"staircase\"",
                        );
                    }
                }
                Some(Method::Constant { deltas, repeats })
            }
            "staircase" => {
                let down = match m.rule.as_deref() {
                    Some("1-up-2-down") => 2,
                    Some("1-up-3-down") => 3,
                    other => {
                        e("rule", format!("unknown rule {other:?}"), "rule = \"1-up-2-down\" (70.7 % correct) or \"1-up-3-down\" (79.4 %); weighted up/down is not built yet");
                        2
                    }
                };
                let starts = m.starts.clone().unwrap_or_default();
                if starts.is_empty() || starts.len() > 8 || starts.iter().any(|s| !positive(*s)) {
                    e("starts", format!("{starts:?}"), "give 1 to 8 positive starting deltas, one per interleaved staircase, e.g. starts = [400.0, 50.0]");
                }
                let step = m.step_factor.unwrap_or(0.0);
                if !(step.is_finite() && step > 1.0 && step <= 10.0) {
                    e(
                        "step_factor",
                        format!("{step}"),
                        "give a factor in (1, 10], e.g. step_factor = 1.25",
                    );
                }
                let initial = m.initial_step_factor.unwrap_or(step);
                if !(initial.is_finite() && initial > 1.0 && initial <= 10.0) {
                    e(
                        "initial_step_factor",
                        format!("{initial}"),
                        "give a factor in (1, 10], e.g. 2.0, or remove it",
                    );
                }
                let max_trials = m.max_trials.unwrap_or(0);
                let max_reversals = m.max_reversals.unwrap_or(u32::MAX);
                if max_trials == 0 || max_trials > MAX_TRIALS_PER_CONDITION {
                    e("max_trials", format!("{max_trials}"), "give the stopping rule: 1 to 100000 trials per staircase, e.g. max_trials = 60");
                }
                if max_reversals == 0 {
                    e(
                        "max_reversals",
                        "0".into(),
                        "give at least 1, or remove it (stop on trials alone)",
                    );
                }
                let lo = starts.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = starts.iter().copied().fold(0.0, f64::max);
                let min_delta = m.min_delta.unwrap_or(lo / 64.0);
                let max_delta = m.max_delta.unwrap_or(4.0 * hi);
                if !(positive(min_delta) && min_delta <= lo) {
                    e(
                        "min_delta",
                        format!("{min_delta}"),
                        "give a positive delta no larger than the smallest start",
                    );
                }
                if !(max_delta.is_finite() && max_delta >= hi) {
                    e(
                        "max_delta",
                        format!("{max_delta}"),
                        "give a delta at least the largest start",
                    );
                }
                if m.deltas.is_some() || m.repeats.is_some() {
                    e(
                        "deltas",
                        "deltas/repeats are constant-stimuli settings".into(),
                        "remove them, or set kind = \"constant\"",
                    );
                }
                Some(Method::Staircase(StaircaseSpec {
                    down,
                    starts,
                    step_factor: step,
                    initial_step_factor: initial,
                    max_trials,
                    max_reversals,
                    min_delta,
                    max_delta,
                }))
            }
            other => {
                e(
                    "kind",
                    format!("unknown method `{other}`"),
                    "kind = \"constant\" or \"staircase\" (QUEST/QUEST+ is not built yet)",
                );
                None
            }
        }
    }
}
