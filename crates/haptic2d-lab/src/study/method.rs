//! The psychophysical method of a study: the method of constant stimuli or transformed up/down
//! staircases (Levitt 1971), validated from `[method]`.

use super::file::MethodSection;
use haptic2d::scene::SceneError;

/// A transformed up/down staircase's parameters.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StaircaseSpec {
    /// Consecutive correct answers for one step down (2 → 70.7 %, 3 → 79.4 % correct; 1 for a
    /// weighted staircase).
    pub down: u32,
    /// The up step in units of the down step (in `log Δ`): 1 for Levitt's transformed rules;
    /// `p/(1 − p)` for Kaernbach's weighted up/down targeting `p` (1991).
    pub up_weight: f64,
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
    /// The rule's name for reports: `1-up/2-down`, `1-up/3-down` or `weighted up/down (up = w × down)`.
    pub fn rule_name(&self) -> String {
        if self.down == 1 {
            format!("weighted up/down (up = {:.2} × down)", self.up_weight)
        } else {
            format!("1-up/{}-down", self.down)
        }
    }

    /// The proportion correct the rule converges to: `0.5^(1/down)` for Levitt's transformed
    /// rules (1971); `w/(1 + w)` for Kaernbach's weighted up/down (1991) with up weight `w`, where
    /// the expected step `p·s_down − (1 − p)·w·s_down` vanishes.
    pub fn target(&self) -> f64 {
        if self.down == 1 {
            self.up_weight / (1.0 + self.up_weight)
        } else {
            0.5f64.powf(1.0 / f64::from(self.down))
        }
    }
}

/// QUEST's parameters (Watson & Pelli 1983; `quest.rs`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QuestSpec {
    /// The prior's centre: the expected threshold (delta).
    pub start: f64,
    /// The prior's standard deviation of `log₁₀ T`.
    pub prior_sd: f64,
    /// The assumed Weibull slope `β`.
    pub beta: f64,
    /// The assumed lapse rate `δ`.
    pub lapse: f64,
    /// Stop after this many trials.
    pub max_trials: u32,
    /// The grid's smallest threshold and delta.
    pub min_delta: f64,
    /// The grid's largest threshold and delta.
    pub max_delta: f64,
    /// Place at the posterior mode (Watson & Pelli) instead of its mean.
    pub place_at_mode: bool,
}

/// QUEST+'s parameters (Watson 2017; `quest_plus.rs`): QUEST's, with a grid of slopes instead of
/// one assumed slope.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QuestPlusSpec {
    /// The threshold prior's centre: the expected threshold (delta).
    pub start: f64,
    /// The threshold prior's standard deviation of `log₁₀ T`.
    pub prior_sd: f64,
    /// The Weibull slopes `β` the posterior spans (uniform prior).
    pub slopes: Vec<f64>,
    /// The assumed lapse rate `δ`.
    pub lapse: f64,
    /// Stop after this many trials.
    pub max_trials: u32,
    /// The grid's smallest threshold and delta.
    pub min_delta: f64,
    /// The grid's largest threshold and delta.
    pub max_delta: f64,
}

/// QUEST+'s default slope grid: Weibull slopes from shallow to steep.
pub const DEFAULT_SLOPES: [f64; 7] = [0.75, 1.0, 1.5, 2.0, 3.0, 4.5, 7.0];

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
    /// QUEST: Bayesian adaptive placement, one per condition, interleaved.
    Quest(QuestSpec),
    /// QUEST+: placement by least expected entropy over threshold and slope, one per condition.
    QuestPlus(QuestPlusSpec),
}

/// Largest number of trials a study may schedule per condition.
pub const MAX_TRIALS_PER_CONDITION: u32 = 100_000;

impl Method {
    /// The largest delta the method can present (the easiest; practice uses it).
    pub fn largest_delta(&self) -> f64 {
        match self {
            Method::Constant { deltas, .. } => deltas.iter().copied().fold(0.0, f64::max),
            Method::Staircase(s) => s.max_delta,
            Method::Quest(q) => q.max_delta,
            Method::QuestPlus(q) => q.max_delta,
        }
    }

    /// The smallest delta the method can present.
    pub fn smallest_delta(&self) -> f64 {
        match self {
            Method::Constant { deltas, .. } => deltas.iter().copied().fold(f64::INFINITY, f64::min),
            Method::Staircase(s) => s.min_delta,
            Method::Quest(q) => q.min_delta,
            Method::QuestPlus(q) => q.min_delta,
        }
    }

    /// The delta of practice trials: the largest constant delta, or the largest staircase start.
    pub fn practice_delta(&self) -> f64 {
        match self {
            Method::Constant { .. } => self.largest_delta(),
            Method::Staircase(s) => s.starts.iter().copied().fold(0.0, f64::max),
            Method::Quest(q) => q.max_delta.min(4.0 * q.start),
            Method::QuestPlus(q) => q.max_delta.min(4.0 * q.start),
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
        match m.kind.as_str() {
            "constant" => Some(constant_from(m, own_deltas, &mut e)),
            "staircase" => Some(Method::Staircase(staircase_from(m, &mut e))),
            "quest" => Some(Method::Quest(quest_from(m, &mut e))),
            "quest+" => Some(Method::QuestPlus(quest_plus_from(m, &mut e))),
            other => {
                e(
                    "kind",
                    format!("unknown method `{other}`"),
                    "kind = \"constant\", \"staircase\", \"quest\" or \"quest+\"",
                );
                None
            }
        }
    }
}

/// A problem of `[method]`: `(field, message, fix)`.
type Report<'a> = dyn FnMut(&str, String, &str) + 'a;

fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// A count of trials (per delta, staircase or condition) in 1 to [`MAX_TRIALS_PER_CONDITION`].
fn trial_count(n: u32) -> bool {
    n != 0 && n <= MAX_TRIALS_PER_CONDITION
}

/// Reports `field` (its `value`, and the `fix`) unless `ok`.
fn require(e: &mut Report, ok: bool, field: &str, value: impl std::fmt::Display, fix: &str) {
    if !ok {
        e(field, value.to_string(), fix);
    }
}

/// `[method]` of kind `"constant"`.
fn constant_from(m: &MethodSection, own_deltas: bool, e: &mut Report) -> Method {
    let deltas = m.deltas.clone().unwrap_or_default();
    if deltas.is_empty() && !own_deltas {
        e(
            "deltas",
            "the method of constant stimuli needs its deltas".into(),
            "e.g. deltas = [50.0, 100.0, 200.0] (comparison − reference, unit of `vary`)",
        );
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
    let fix = "give 1 to 100000 presentations per delta, e.g. repeats = 20";
    require(
        e,
        trial_count(repeats),
        "repeats",
        format!("{repeats} repeats"),
        fix,
    );
    let staircase_settings = [
        ("rule", m.rule.is_some()),
        ("starts", m.starts.is_some()),
        ("step_factor", m.step_factor.is_some()),
        ("initial_step_factor", m.initial_step_factor.is_some()),
        ("max_trials", m.max_trials.is_some()),
        ("max_reversals", m.max_reversals.is_some()),
        ("min_delta", m.min_delta.is_some()),
        ("max_delta", m.max_delta.is_some()),
    ];
    for (k, given) in staircase_settings {
        if given {
            e(
                k,
                "is a staircase setting".into(),
                "remove it, or set kind = \"staircase\"",
            );
        }
    }
    Method::Constant { deltas, repeats }
}

/// `[method]` of kind `"staircase"`.
fn staircase_from(m: &MethodSection, e: &mut Report) -> StaircaseSpec {
    let (down, up_weight) = match m.rule.as_deref() {
        Some("1-up-2-down") => (2, 1.0),
        Some("1-up-3-down") => (3, 1.0),
        Some("weighted") => (1, weighted_up_weight(m.target, e)),
        other => {
            e("rule", format!("unknown rule {other:?}"), "rule = \"1-up-2-down\" (70.7 % correct), \"1-up-3-down\" (79.4 %) or \"weighted\" (Kaernbach 1991: any target, e.g. target = 0.75)");
            (2, 1.0)
        }
    };
    if m.target.is_some() && m.rule.as_deref() != Some("weighted") {
        e(
            "target",
            "only a weighted staircase takes a target".into(),
            "remove it, or set rule = \"weighted\"",
        );
    }
    let starts = m.starts.clone().unwrap_or_default();
    if starts.is_empty() || starts.len() > 8 || starts.iter().any(|s| !positive(*s)) {
        e("starts", format!("{starts:?}"), "give 1 to 8 positive starting deltas, one per interleaved staircase, e.g. starts = [400.0, 50.0]");
    }
    let step = m.step_factor.unwrap_or(0.0);
    require(
        e,
        step.is_finite() && step > 1.0 && step <= 10.0,
        "step_factor",
        step,
        "give a factor in (1, 10], e.g. step_factor = 1.25",
    );
    let initial = m.initial_step_factor.unwrap_or(step);
    require(
        e,
        initial.is_finite() && initial > 1.0 && initial <= 10.0,
        "initial_step_factor",
        initial,
        "give a factor in (1, 10], e.g. 2.0, or remove it",
    );
    let max_trials = m.max_trials.unwrap_or(0);
    let max_reversals = m.max_reversals.unwrap_or(u32::MAX);
    require(
        e,
        trial_count(max_trials),
        "max_trials",
        max_trials,
        "give the stopping rule: 1 to 100000 trials per staircase, e.g. max_trials = 60",
    );
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
    require(
        e,
        positive(min_delta) && min_delta <= lo,
        "min_delta",
        min_delta,
        "give a positive delta no larger than the smallest start",
    );
    require(
        e,
        max_delta.is_finite() && max_delta >= hi,
        "max_delta",
        max_delta,
        "give a delta at least the largest start",
    );
    if m.deltas.is_some() || m.repeats.is_some() {
        e(
            "deltas",
            "deltas/repeats are constant-stimuli settings".into(),
            "remove them, or set kind = \"constant\"",
        );
    }
    StaircaseSpec {
        down,
        up_weight,
        starts,
        step_factor: step,
        initial_step_factor: initial,
        max_trials,
        max_reversals,
        min_delta,
        max_delta,
    }
}

/// The up weight `p/(1 − p)` of a weighted staircase targeting `p` (Kaernbach 1991).
fn weighted_up_weight(target: Option<f64>, e: &mut Report) -> f64 {
    let guessless = 0.5;
    match target {
        Some(p) if p.is_finite() && p > guessless && p < 0.99 => p / (1.0 - p),
        other => {
            e(
                "target",
                format!("{other:?}"),
                "give the proportion correct a weighted staircase converges on, in (0.5, 0.99), e.g. target = 0.75",
            );
            3.0
        }
    }
}

/// `[method]` of kind `"quest+"`: QUEST's settings, with `slopes` instead of `beta`/`placement`.
fn quest_plus_from(m: &MethodSection, e: &mut Report) -> QuestPlusSpec {
    if m.beta.is_some() || m.placement.is_some() {
        e(
            "beta",
            "QUEST+ estimates the slope and places by expected entropy: beta/placement are QUEST settings".into(),
            "give the slopes the posterior spans instead, e.g. slopes = [0.75, 1.0, 1.5, 2.0, 3.0, 4.5, 7.0], or set kind = \"quest\"",
        );
    }
    let q = quest_from(m, e);
    let slopes = m.slopes.clone().unwrap_or_else(|| DEFAULT_SLOPES.to_vec());
    if slopes.is_empty()
        || slopes.len() > 16
        || slopes
            .iter()
            .any(|b| !(b.is_finite() && (0.2..=20.0).contains(b)))
    {
        e(
            "slopes",
            format!("{slopes:?}"),
            "give 1 to 16 Weibull slopes in [0.2, 20], e.g. slopes = [0.75, 1.0, 1.5, 2.0, 3.0, 4.5, 7.0]",
        );
    }
    QuestPlusSpec {
        start: q.start,
        prior_sd: q.prior_sd,
        slopes,
        lapse: q.lapse,
        max_trials: q.max_trials,
        min_delta: q.min_delta,
        max_delta: q.max_delta,
    }
}

/// `[method]` of kind `"quest"`.
fn quest_from(m: &MethodSection, e: &mut Report) -> QuestSpec {
    let start = m.start.unwrap_or(0.0);
    if !positive(start) {
        e(
            "start",
            format!("{start}"),
            "give the expected threshold (a positive delta), e.g. start = 150.0",
        );
    }
    let prior_sd = m.prior_sd.unwrap_or(0.5);
    require(
        e,
        prior_sd.is_finite() && prior_sd > 0.0 && prior_sd <= 3.0,
        "prior_sd",
        prior_sd,
        "give the prior's sd of log10(threshold) in (0, 3], e.g. 0.5",
    );
    let beta = m.beta.unwrap_or(3.5);
    require(e, beta.is_finite() && (0.2..=20.0).contains(&beta), "beta", beta, "give the Weibull slope in [0.2, 20], e.g. 3.5 (Watson & Pelli) or the slope a pilot fit gave");
    let lapse = m.lapse.unwrap_or(0.01);
    require(
        e,
        lapse.is_finite() && (0.0..=0.2).contains(&lapse),
        "lapse",
        lapse,
        "give the assumed lapse rate in [0, 0.2], e.g. 0.01",
    );
    let max_trials = m.max_trials.unwrap_or(0);
    require(
        e,
        trial_count(max_trials),
        "max_trials",
        max_trials,
        "give the stopping rule: 1 to 100000 trials per condition, e.g. max_trials = 80",
    );
    let min_delta = m.min_delta.unwrap_or(start / 100.0);
    let max_delta = m.max_delta.unwrap_or(start * 100.0);
    if !(positive(min_delta) && min_delta < start && max_delta.is_finite() && start < max_delta) {
        e(
            "min_delta",
            format!("[{min_delta}, {max_delta}]"),
            "give 0 < min_delta < start < max_delta (the grid of thresholds and deltas)",
        );
    }
    let place_at_mode = match m.placement.as_deref() {
        None | Some("mean") => false,
        Some("mode") => true,
        Some(other) => {
            e(
                "placement",
                format!("unknown placement `{other}`"),
                "placement = \"mean\" (posterior mean, default) or \"mode\"",
            );
            false
        }
    };
    if m.deltas.is_some() || m.repeats.is_some() || m.rule.is_some() || m.starts.is_some() {
        e(
            "kind",
            "deltas/repeats/rule/starts are not QUEST settings".into(),
            "remove them, or change kind",
        );
    }
    QuestSpec {
        start,
        prior_sd,
        beta,
        lapse,
        max_trials,
        min_delta,
        max_delta,
        place_at_mode,
    }
}
