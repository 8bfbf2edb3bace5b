//! Which scenes the loop can run at its rate: the page may only switch to a scene whose world step
//! fits the control period.
//!
//! A switch to a scene the loop cannot run (e.g. the 1000-box `pile` at 1 kHz: a step with the
//! global proximity stage costs about 1.5 ms, docs/PERFORMANCE.md) would overrun every tick while a
//! device is in the loop. So before the server starts, off the real-time thread, every built-in
//! scene is built at the loop's rate and a few of its steps are timed; the server refuses a switch
//! to a scene whose estimate does not fit, with the reason, and the page greys it out.
//!
//! **The estimate.** The step cost is periodic in the proximity interval `N_g` (the global stage
//! runs on every `N_g`-th step), so steps are timed in whole cycles of `N_g`: after one warm-up
//! step (it sizes the buffers), cycle `c` times steps `c·N_g + k` for `k = 0 … N_g−1`. Preemption
//! by other processes only ever adds time, so for each phase `k` the minimum over the cycles is
//! kept, and the estimate is the maximum over the phases:
//!
//! ```text
//! t̂ = max_k min_c t(c, k)          (s)
//! ```
//!
//! — the cost of the most expensive step of a cycle, with the noise filtered out. It is measured on
//! the scene's initial state, before the bodies settle into contact, so it is a *lower* bound of the
//! running cost: a scene refused by it certainly cannot run; one accepted can still grow heavier
//! (the loop's own overrun statistics and watchdog cover that).
//!
//! **The budget.** The world step must fit in `fraction · T` with `T = 1/rate` the period
//! ([`DEFAULT_STEP_FRACTION`] = 0.5): the rest of the tick is the device read/write, kinematics,
//! controller and the loop's wake-up jitter.

use haptic2d::scene::{builtin, BUILTIN};
use haptic2d::world::World;
use serde::Serialize;
use std::time::{Duration, Instant};

/// Fraction of the period the world step may take (the rest is the device, the controller and
/// wake-up jitter).
pub const DEFAULT_STEP_FRACTION: f64 = 0.5;
/// Proximity cycles timed per scene (the minimum over them filters preemption).
pub const CYCLES: usize = 3;
/// Wall-clock time spent timing one scene at most (s): a scene so heavy that one cycle takes
/// longer is judged on the cycles done (at least one).
pub const MAX_TIMING_S: f64 = 0.5;

/// Whether one built-in scene fits the loop's period (`{"name", "step_us", "budget_us",
/// "runnable", "reason"}` in the page's `welcome`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneCost {
    /// Built-in scene name.
    pub name: &'static str,
    /// Estimated cost of the scene's most expensive step (µs), see the module docs.
    pub step_us: f64,
    /// The step budget at the loop's rate: `fraction / rate` (µs).
    pub budget_us: f64,
    /// True when `step_us ≤ budget_us`.
    pub runnable: bool,
    /// Why the scene cannot run, when it cannot (shown on the page and sent with a refusal).
    pub reason: Option<String>,
}

/// Estimates the most expensive step of `world` (s) by timing steps of a clone (see the module
/// docs). Allocates and takes up to about [`MAX_TIMING_S`]; call it off the real-time thread.
pub fn estimate_step_s(world: &World) -> f64 {
    let mut w = world.clone();
    let n_g = w.params.proximity_every.max(1) as usize;
    w.step();
    let mut best = vec![f64::INFINITY; n_g];
    let start = Instant::now();
    for _ in 0..CYCLES {
        for b in best.iter_mut() {
            let t0 = Instant::now();
            w.step();
            *b = b.min(t0.elapsed().as_secs_f64());
        }
        if start.elapsed() > Duration::from_secs_f64(MAX_TIMING_S) {
            break;
        }
    }
    best.into_iter().fold(0.0, f64::max)
}

/// The verdict for a scene named `name` whose step is estimated at `step_s` (s), at `rate_hz` (Hz)
/// with the step allowed `fraction` of the period.
pub fn verdict(name: &'static str, step_s: f64, rate_hz: f64, fraction: f64) -> SceneCost {
    let budget_s = fraction / rate_hz;
    let runnable = step_s <= budget_s;
    SceneCost {
        name,
        step_us: step_s * 1e6,
        budget_us: budget_s * 1e6,
        runnable,
        reason: (!runnable).then(|| {
            format!(
                "scene `{name}` is too heavy for the loop at {rate_hz} Hz: its world step takes about {:.0} µs, more than the {:.0} µs ({:.0} % of the {:.0} µs period) it may use; run it with a lower --rate (at most about {:.0} Hz) or `haptic2d simulate {name}`",
                step_s * 1e6,
                budget_s * 1e6,
                fraction * 100.0,
                1e6 / rate_hz,
                fraction / step_s,
            )
        }),
    }
}

/// Builds every built-in scene at `rate_hz` (Hz) and judges whether its step fits `fraction` of
/// the period. A scene that does not build at that rate is not runnable, with the scene's error as
/// the reason. Takes up to a few tenths of a second per heavy scene; call it off the real-time
/// thread, before the loop starts.
pub fn assess_builtin_scenes(rate_hz: f64, fraction: f64) -> Vec<SceneCost> {
    BUILTIN
        .iter()
        .map(|&(name, _, _)| match builtin(name, Some(rate_hz)) {
            Some(Ok(scene)) => verdict(name, estimate_step_s(&scene.world), rate_hz, fraction),
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
        assert!(why.contains("at most about 333 Hz"), "{why}");
    }
}
