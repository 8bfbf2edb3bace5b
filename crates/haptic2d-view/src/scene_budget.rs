//! Which scenes the loop can run at its rate: the page may only switch to a scene whose world step
//! fits the control period.
//!
//! A switch to a scene the loop cannot run (e.g. the 1000-box `pile` at 1 kHz: issue 38 measured
//! its running step at p50 349 µs, p99 1.0 ms against a 500 µs budget) would overrun every tick
//! while a device is in the loop — on a real device, a watchdog trip. So before the server starts,
//! off the real-time thread, every built-in scene is built at the loop's rate and **run for a short
//! timed trial**; the server refuses a switch to a scene whose measured cost does not fit, with the
//! reason, and the page greys it out. The loop only looks the verdict up: no trial ever runs on the
//! haptic thread.
//!
//! **The trial.** The scene is stepped from its initial state for [`TRIAL_S`] of simulated time
//! (0.3 s: `⌈0.3 · rate⌉` steps, at least [`MIN_TRIAL_STEPS`]) — long enough for a dropped pile to
//! land and its bottom rows to press into each other (the pile's boxes start 5 mm above the floor
//! and 6 mm apart: the floor is reached after about 32 ms), so the trial measures the contact phase
//! that made the former initial-state estimate 4–12× too low. Two copies of the world are stepped
//! side by side; the step being deterministic, both pass through the same states, and each step's
//! cost is the smaller of its two timings (preemption by another process only ever adds time, and
//! must now hit the same step twice to count). The measured cost is the **99th percentile**
//! (nearest rank) of those per-step costs: at 1 kHz with the proximity stage every 10 steps, the
//! expensive proximity steps are 10 % of the trial, so the p99 is one of them.
//!
//! **The margin.** The scene is runnable when `MARGIN · p99 ≤ fraction · T` with `T = 1/rate` the
//! period, [`COST_MARGIN`] = 1.5 and [`DEFAULT_STEP_FRACTION`] = 0.5 (the rest of the tick is the
//! device read/write, kinematics, controller and the loop's wake-up jitter): the step's p99 may
//! take a third of the period. The margin covers what the trial cannot see: a scene that keeps
//! growing heavier after [`TRIAL_S`] (a pile whose upper rows are still landing), other processes
//! sharing the cache with the loop, a slower clock. It is not a proof: the loop's own overrun
//! statistics and, on a device, the stall latch remain the last line.
//!
//! **Bounded time.** A trial stops early, refused, as soon as more steps exceeded the budget than
//! the percentile allows (the p99 can then only be above it) — a heavy scene is refused after a
//! few of its steps — and it never takes more than [`MAX_TRIAL_WALL_S`] of wall-clock time; a
//! trial cut by that limit is refused too (its steps average more than the period: see
//! [`trial`]).

use haptic2d::scene::{builtin, BUILTIN};
use haptic2d::world::World;
use serde::Serialize;
use std::time::{Duration, Instant};

/// Fraction of the period the world step may take (the rest is the device, the controller and
/// wake-up jitter).
pub const DEFAULT_STEP_FRACTION: f64 = 0.5;
/// Simulated time a trial steps the scene (s).
pub const TRIAL_S: f64 = 0.3;
/// Fewest steps of a trial (a low rate still times this many).
pub const MIN_TRIAL_STEPS: usize = 100;
/// The percentile of the per-step costs that must fit (nearest rank).
pub const COST_PERCENTILE: f64 = 0.99;
/// Factor applied to the measured percentile before it is compared with the budget.
pub const COST_MARGIN: f64 = 1.5;
/// Wall-clock time one trial may take at most (s). Two copies of the scene are stepped, so a trial
/// cut by this limit averaged more than `MAX_TRIAL_WALL_S / (2 · steps planned)` per step, i.e.
/// more than the period `T` (`steps planned ≥ TRIAL_S / T`, and `MAX_TRIAL_WALL_S = 2 · TRIAL_S`):
/// it is refused.
pub const MAX_TRIAL_WALL_S: f64 = 2.0 * TRIAL_S;

/// Whether one built-in scene fits the loop's period (`{"name", "step_us", "budget_us",
/// "runnable", "reason"}` in the page's `welcome`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneCost {
    /// Built-in scene name.
    pub name: &'static str,
    /// The measured step cost (µs): the trial's p99 (see the module docs), without the margin.
    pub step_us: f64,
    /// The step budget at the loop's rate: `fraction / rate` (µs).
    pub budget_us: f64,
    /// True when `COST_MARGIN · step_us ≤ budget_us`.
    pub runnable: bool,
    /// Why the scene cannot run, when it cannot (shown on the page and sent with a refusal).
    pub reason: Option<String>,
}

/// How a trial ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrialEnd {
    /// Every planned step was timed.
    Complete,
    /// Stopped early: more steps exceeded the budget than the percentile allows.
    OverBudget,
    /// Stopped by [`MAX_TRIAL_WALL_S`].
    OutOfTime,
}

/// The result of a timed trial of a scene ([`trial`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Trial {
    /// The measured cost (s): the [`COST_PERCENTILE`] of the per-step costs of the steps timed
    /// (for [`TrialEnd::OverBudget`], a lower bound of the complete trial's, itself over budget).
    pub p99_s: f64,
    /// The largest per-step cost (s).
    pub max_s: f64,
    /// The median per-step cost (s).
    pub p50_s: f64,
    /// Steps timed.
    pub steps: usize,
    /// Steps planned.
    pub planned: usize,
    /// How the trial ended.
    pub end: TrialEnd,
}

/// Nearest-rank percentile `p` of `sorted` (ascending, non-empty).
fn percentile(sorted: &[f64], p: f64) -> f64 {
    let rank = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1]
}

/// Runs the timed trial of `world` at its own rate (module docs): two clones stepped side by side
/// for [`TRIAL_S`] of simulated time, each step's cost the smaller of its two timings. A step whose
/// cost times `margin` exceeds `budget_s` (s) counts against the budget; once more steps than the
/// [`COST_PERCENTILE`] allows have, the trial stops ([`TrialEnd::OverBudget`]). Allocates (the
/// clones) and takes up to [`MAX_TRIAL_WALL_S`]: call it off the real-time thread.
pub fn trial(world: &World, budget_s: f64, margin: f64) -> Trial {
    trial_within(world, budget_s, margin, MAX_TRIAL_WALL_S)
}

/// [`trial`] with a wall-clock limit of `max_wall_s` (s) instead of [`MAX_TRIAL_WALL_S`] (for
/// measurements that must see the whole trial of a heavy scene).
pub fn trial_within(world: &World, budget_s: f64, margin: f64, max_wall_s: f64) -> Trial {
    let dt = world.params.dt;
    let planned = ((TRIAL_S / dt).ceil() as usize).max(MIN_TRIAL_STEPS);
    // More than `allowed` steps over the budget put the percentile over it.
    let allowed = planned - (COST_PERCENTILE * planned as f64).ceil() as usize;
    let (mut a, mut b) = (world.clone(), world.clone());
    let mut costs = Vec::with_capacity(planned);
    let mut over = 0usize;
    let mut end = TrialEnd::Complete;
    let start = Instant::now();
    let limit = Duration::from_secs_f64(max_wall_s.max(0.0));
    for _ in 0..planned {
        let t0 = Instant::now();
        a.step();
        let ta = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        b.step();
        let tb = t1.elapsed().as_secs_f64();
        let c = ta.min(tb);
        costs.push(c);
        if margin * c > budget_s {
            over += 1;
            if over > allowed {
                end = TrialEnd::OverBudget;
                break;
            }
        }
        if start.elapsed() > limit {
            end = TrialEnd::OutOfTime;
            break;
        }
    }
    let steps = costs.len();
    costs.sort_by(f64::total_cmp);
    let p99_s = match end {
        // The (allowed+1)-th largest cost: over the budget, and at most the complete trial's p99.
        TrialEnd::OverBudget => costs[steps - allowed - 1],
        _ => percentile(&costs, COST_PERCENTILE),
    };
    Trial {
        p99_s,
        max_s: costs[steps - 1],
        p50_s: percentile(&costs, 0.5),
        steps,
        planned,
        end,
    }
}

/// Judges `world` (the built-in scene `name`) at `rate_hz` (Hz) by a [`trial`] with the step allowed
/// `fraction` of the period and [`COST_MARGIN`]. Off the real-time thread only.
pub fn assess(name: &'static str, world: &World, rate_hz: f64, fraction: f64) -> SceneCost {
    let budget_s = fraction / rate_hz;
    let t = trial(world, budget_s, COST_MARGIN);
    let mut cost = verdict_of(
        name,
        t.p99_s,
        rate_hz,
        fraction,
        t.end == TrialEnd::OverBudget,
    );
    if t.end == TrialEnd::OutOfTime && cost.runnable {
        cost.runnable = false;
        cost.reason = Some(format!(
            "scene `{name}` is too heavy for the loop at {rate_hz} Hz: its trial of {} steps did not finish within {MAX_TRIAL_WALL_S} s (more than a period a step); run it with a lower --rate or `haptic2d simulate {name}`",
            t.planned
        ));
    }
    cost
}

/// The verdict for a scene named `name` whose measured step cost is `step_s` (s), at `rate_hz` (Hz)
/// with the step allowed `fraction` of the period: runnable when `COST_MARGIN · step_s` fits.
pub fn verdict(name: &'static str, step_s: f64, rate_hz: f64, fraction: f64) -> SceneCost {
    verdict_of(name, step_s, rate_hz, fraction, false)
}

/// [`verdict`]; `lower_bound`: `step_s` is a lower bound of the cost (a trial stopped early).
fn verdict_of(
    name: &'static str,
    step_s: f64,
    rate_hz: f64,
    fraction: f64,
    lower_bound: bool,
) -> SceneCost {
    let budget_s = fraction / rate_hz;
    let runnable = COST_MARGIN * step_s <= budget_s;
    SceneCost {
        name,
        step_us: step_s * 1e6,
        budget_us: budget_s * 1e6,
        runnable,
        reason: (!runnable).then(|| {
            format!(
                "scene `{name}` is too heavy for the loop at {rate_hz} Hz: its world step takes {} {:.0} µs (p99 of a timed trial{}), which with the {COST_MARGIN}× margin is more than the {:.0} µs ({:.0} % of the {:.0} µs period) it may use; run it with a lower --rate (at most about {:.0} Hz) or `haptic2d simulate {name}`",
                if lower_bound { "at least" } else { "about" },
                step_s * 1e6,
                if lower_bound { ", stopped once over the budget" } else { "" },
                budget_s * 1e6,
                fraction * 100.0,
                1e6 / rate_hz,
                fraction / (COST_MARGIN * step_s),
            )
        }),
    }
}

/// Builds every built-in scene at `rate_hz` (Hz) and judges whether its step fits `fraction` of
/// the period. A scene that does not build at that rate is not runnable, with the scene's error as
/// the reason. Takes up to [`MAX_TRIAL_WALL_S`] per scene (a heavy scene is refused after a few of
/// its steps); call it off the real-time thread, before the loop starts.
pub fn assess_builtin_scenes(rate_hz: f64, fraction: f64) -> Vec<SceneCost> {
    BUILTIN
        .iter()
        .map(|&(name, _, _)| match builtin(name, Some(rate_hz)) {
            Some(Ok(scene)) => assess(name, &scene.world, rate_hz, fraction),
            Some(Err(e)) => SceneCost {
                name,
                step_us: f64::NAN,
                budget_us: fraction / rate_hz * 1e6,
                runnable: false,
                reason: Some(format!("scene `{name}` does not load at {rate_hz} Hz: {e}")),
            },
            None => SceneCost {
                name,
                step_us: f64::NAN,
                budget_us: fraction / rate_hz * 1e6,
                runnable: false,
                reason: Some(format!("no built-in scene `{name}`")),
            },
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdict_compares_the_step_with_the_share_of_the_period() {
        let ok = verdict("box-in-walls", 20e-6, 1000.0, 0.5);
        assert!(ok.runnable && ok.reason.is_none());
        assert!((ok.budget_us - 500.0).abs() < 1e-9);
        let heavy = verdict("pile", 1.5e-3, 10_000.0, 0.5);
        assert!(!heavy.runnable);
        let why = heavy.reason.unwrap();
        assert!(
            why.contains("pile") && why.contains("10000 Hz") && why.contains("1500 µs"),
            "{why}"
        );
        // 0.5 / (1.5 · 1.5 ms) = 222 Hz.
        assert!(why.contains("at most about 222 Hz"), "{why}");
        // The margin: a step of 400 µs fits 500 µs but not with 1.5× (600 µs).
        assert!(!verdict("x", 400e-6, 1000.0, 0.5).runnable);
        assert!(verdict("x", 330e-6, 1000.0, 0.5).runnable);
    }
}
