//! Wall time of each stage of a world step, for profiling (docs/PERFORMANCE.md, issue 17).
//!
//! Compiled in only with the crate feature `stage-timing`: without it the stopwatch (`Lap`) is
//! empty, charging a lap does nothing and
//! [`World::stage_times`](crate::world::World::stage_times) stays zero, so the step reads no
//! clock. With it, each stage boundary reads the monotonic clock once (about
//! 20 ns on Linux, through the vDSO): the timed step is that much slower, and the stages show
//! where a step's time goes, warm or right after the caches were emptied
//! (`haptic2d-bench --settle … --cold …`).

/// The stages of a world step, in the order they run (§0.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Body rotations, colliders' world features and the odometers.
    Poses,
    /// The global proximity stage (its share of the spread update).
    Global,
    /// The local stage: closest features and VE candidates.
    Local,
    /// Loads and drives into the bodies' accumulators.
    Loads,
    /// Contact records: merge with the candidates and measure every pair.
    ContactSync,
    /// Contact events: release, hand-over, creation and simultaneous impacts, and the energy
    /// ledger's impact accounting after them.
    ContactEvents,
    /// Continuous-contact forces (the force pass).
    ContactForces,
    /// Past poses and the held wrenches before integration.
    Assemble,
    /// The implicit chain damper.
    ChainDamper,
    /// Integration, the swept test and the energy ledger.
    Integrate,
}

impl Stage {
    /// Number of stages.
    pub const COUNT: usize = 10;
    /// Every stage, in the order a step runs them.
    pub const ALL: [Stage; Stage::COUNT] = [
        Stage::Poses,
        Stage::Global,
        Stage::Local,
        Stage::Loads,
        Stage::ContactSync,
        Stage::ContactEvents,
        Stage::ContactForces,
        Stage::Assemble,
        Stage::ChainDamper,
        Stage::Integrate,
    ];

    /// A short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Poses => "poses",
            Stage::Global => "global",
            Stage::Local => "local",
            Stage::Loads => "loads",
            Stage::ContactSync => "sync",
            Stage::ContactEvents => "events",
            Stage::ContactForces => "forces",
            Stage::Assemble => "assemble",
            Stage::ChainDamper => "damper",
            Stage::Integrate => "integrate",
        }
    }
}

/// Whether this build times the stages (the `stage-timing` feature).
pub const ENABLED: bool = cfg!(feature = "stage-timing");

/// Wall time of each stage of the last step (ns); all zero without the `stage-timing` feature.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageTimes {
    /// Nanoseconds by stage, indexed as [`Stage::ALL`].
    pub ns: [u64; Stage::COUNT],
}

impl StageTimes {
    /// Time of stage `s` (ns).
    pub fn get(&self, s: Stage) -> u64 {
        self.ns[s as usize]
    }

    /// Time of the whole step (ns): the sum of the stages.
    pub fn total(&self) -> u64 {
        self.ns.iter().sum()
    }
}

/// A stopwatch whose laps are charged to stages; empty without the `stage-timing` feature.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lap {
    #[cfg(feature = "stage-timing")]
    t: std::time::Instant,
}

impl Lap {
    /// Starts a lap now.
    #[inline(always)]
    pub(crate) fn start() -> Self {
        Self {
            #[cfg(feature = "stage-timing")]
            t: std::time::Instant::now(),
        }
    }

    /// Charges the time since the lap started to `s` in `times`, and starts the next lap.
    #[inline(always)]
    pub(crate) fn charge(&mut self, _times: &mut StageTimes, _s: Stage) {
        #[cfg(feature = "stage-timing")]
        {
            let now = std::time::Instant::now();
            _times.ns[_s as usize] += now.duration_since(self.t).as_nanos() as u64;
            self.t = now;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stages_are_listed_in_their_index_order() {
        for (i, s) in Stage::ALL.iter().enumerate() {
            assert_eq!(*s as usize, i, "{}", s.name());
        }
    }

    #[cfg(not(feature = "stage-timing"))]
    #[test]
    fn without_the_feature_a_lap_charges_nothing() {
        let mut t = StageTimes::default();
        let mut lap = Lap::start();
        std::hint::black_box((0..10_000u64).sum::<u64>());
        lap.charge(&mut t, Stage::Global);
        assert_eq!(t.total(), 0);
        assert_eq!(std::mem::size_of::<Lap>(), 0);
    }

    #[cfg(feature = "stage-timing")]
    #[test]
    fn with_the_feature_a_lap_charges_its_stage_only() {
        let mut t = StageTimes::default();
        let mut lap = Lap::start();
        std::thread::sleep(std::time::Duration::from_millis(2));
        lap.charge(&mut t, Stage::Global);
        assert!(t.get(Stage::Global) >= 2_000_000, "{t:?}");
        assert_eq!(t.total(), t.get(Stage::Global));
    }
}
