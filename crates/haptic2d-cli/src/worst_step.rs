//! Which stage set a run's slowest tick (issue 42, item 2).
//!
//! The loop's timing summary names its worst-compute tick; this names what that tick spent its
//! time on: the world step's stages, from [`World::stage_times`] (the wall time of each stage,
//! read at every stage boundary when `haptic2d` is built with its `stage-timing` feature, which
//! this crate's default `stage-timing` feature turns on), and the rest of the tick (the device
//! exchange, the controller, the watchdog, telemetry). Observing a tick copies ten integers: no
//! allocation, no lock, no I/O.

use haptic2d::stage_time::{Stage, StageTimes, ENABLED};
use haptic2d::world::World;
use std::fmt;
use std::time::Duration;

/// The slowest tick seen so far, its world step's stages and when it ran.
#[derive(Clone, Copy, Debug, Default)]
pub struct WorstStep {
    /// The whole tick's wall time (ns), as the loop thread measured it around the tick.
    tick_ns: u64,
    /// Its world step's stage times (ns).
    times: StageTimes,
    /// Its tick, counted from 1 as the loop's timing summary counts them.
    tick: u64,
    /// Its deadline since the first deadline (s).
    at_s: f64,
}

impl WorstStep {
    /// Takes a tick that took `took` into account: kept, with the world's last step's stage
    /// times, when it took longer than the slowest so far.
    #[inline]
    pub fn observe(&mut self, world: &World, took: Duration, tick_index: u64, t_s: f64) {
        let ns = took.as_nanos() as u64;
        if ns > self.tick_ns {
            self.tick_ns = ns;
            self.times = *world.stage_times();
            self.tick = tick_index + 1;
            self.at_s = t_s;
        }
    }

    /// The summary line, or `None` when the build does not time stages or no tick ran.
    pub fn line(&self) -> Option<String> {
        (ENABLED && self.tick_ns > 0).then(|| self.to_string())
    }
}

impl fmt::Display for WorstStep {
    /// `slowest tick: tick N at T s, X µs: world step Y µs (damper 41 %, forces 22 %), rest Z µs`
    /// (the stages over 5 % of the world step, largest first).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let step = self.times.total();
        write!(
            f,
            "slowest tick: tick {} at {:.3} s, {:.1} µs: world step {:.1} µs",
            self.tick,
            self.at_s,
            self.tick_ns as f64 * 1e-3,
            step as f64 * 1e-3
        )?;
        let mut stages = Stage::ALL;
        stages.sort_by_key(|s| std::cmp::Reverse(self.times.get(*s)));
        let mut sep = " (";
        for s in stages {
            let share = self.times.get(s) as f64 / step.max(1) as f64;
            if share < 0.05 {
                break;
            }
            write!(f, "{sep}{} {:.0} %", s.name(), share * 100.0)?;
            sep = ", ";
        }
        if sep == ", " {
            write!(f, ")")?;
        }
        write!(
            f,
            ", rest of the tick {:.1} µs",
            self.tick_ns.saturating_sub(step) as f64 * 1e-3
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn times(pairs: &[(Stage, u64)]) -> StageTimes {
        let mut t = StageTimes::default();
        for (s, ns) in pairs {
            t.ns[*s as usize] = *ns;
        }
        t
    }

    #[test]
    fn the_line_names_the_largest_stages_first_and_omits_the_small_ones() {
        let w = WorstStep {
            tick_ns: 1_200_000,
            times: times(&[
                (Stage::ContactForces, 200_000),
                (Stage::ChainDamper, 500_000),
                (Stage::Poses, 10_000),
                (Stage::ContactSync, 290_000),
            ]),
            tick: 412,
            at_s: 0.411,
        };
        assert_eq!(
            w.to_string(),
            "slowest tick: tick 412 at 0.411 s, 1200.0 µs: world step 1000.0 µs \
             (damper 50 %, sync 29 %, forces 20 %), rest of the tick 200.0 µs"
        );
    }

    #[test]
    fn a_run_without_ticks_has_no_line() {
        assert_eq!(WorstStep::default().line(), None);
    }
}
