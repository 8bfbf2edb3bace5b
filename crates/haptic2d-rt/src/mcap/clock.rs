//! The clock of MCAP `log_time`s (issue 39 item 8): Unix-epoch nanoseconds, so that a recording
//! lines up with other robot logs (ROS 2 bags, other MCAP files, a camera's recording).
//!
//! The loop schedules its ticks on `CLOCK_MONOTONIC` (it never jumps), and the tick's
//! `deadline_ns` column keeps that clock. The log's `log_time` is the deadline moved to the Unix
//! epoch by one offset `CLOCK_REALTIME − CLOCK_MONOTONIC`, read once when the log starts
//! ([`monotonic_to_unix_offset_ns`]): the ticks keep their exact monotonic spacing, and a
//! wall-clock step (NTP) during the run does not reorder them. The offset is stored in the log
//! (metadata record `haptic2d.clock`, [`clock_metadata`]), so `deadline_ns` and `log_time` convert
//! into each other exactly.

use ::mcap::records::Metadata;
use std::collections::BTreeMap;

/// What a log's `log_time`s count, stated in its `haptic2d.clock` metadata record.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LogClock {
    /// Unix-epoch ns: a tick's `CLOCK_MONOTONIC` deadline + the offset (`haptic2d run`).
    UnixFromMonotonic {
        /// `CLOCK_REALTIME − CLOCK_MONOTONIC` when the log started (ns).
        offset_ns: u64,
    },
    /// Unix-epoch ns: the Unix time when the simulation started + the simulated time
    /// (`haptic2d simulate`, whose world time runs faster or slower than the wall clock).
    UnixFromSimTime {
        /// Unix time of `t = 0` (ns).
        start_ns: u64,
    },
    /// Not Unix time: the recorded `CLOCK_MONOTONIC` deadline, else the simulated time `t` (a CSV
    /// tick log converted by `log convert`, which has no record of the offset). The default.
    #[default]
    Converted,
}

fn realtime_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// `CLOCK_REALTIME − CLOCK_MONOTONIC` now (ns): the real-time clock read between two monotonic
/// reads, the closest bracket of 5 tries (its error is at most half that bracket, well under a µs).
pub fn monotonic_to_unix_offset_ns() -> u64 {
    let mut best = (u64::MAX, 0u64);
    for _ in 0..5 {
        let a = crate::clock::now_ns();
        let r = realtime_ns();
        let b = crate::clock::now_ns();
        let width = b.saturating_sub(a);
        if width < best.0 {
            best = (width, r.saturating_sub(a + width / 2));
        }
    }
    best.1
}

/// The Unix time now (ns), for [`LogClock::UnixFromSimTime`].
pub fn unix_now_ns() -> u64 {
    realtime_ns()
}

/// The metadata record `haptic2d.clock` of a log: `log_time` (`unix_epoch_ns` or
/// `converted`), `source` (`monotonic_deadline`, `sim_time`, or how a converted log's times were
/// made), and the offset or start (ns).
pub fn clock_metadata(clock: LogClock) -> Metadata {
    let mut m = BTreeMap::new();
    match clock {
        LogClock::UnixFromMonotonic { offset_ns } => {
            m.insert("log_time".into(), "unix_epoch_ns".into());
            m.insert("source".into(), "monotonic_deadline".into());
            m.insert("monotonic_to_unix_offset_ns".into(), offset_ns.to_string());
        }
        LogClock::UnixFromSimTime { start_ns } => {
            m.insert("log_time".into(), "unix_epoch_ns".into());
            m.insert("source".into(), "sim_time".into());
            m.insert("sim_start_unix_ns".into(), start_ns.to_string());
        }
        LogClock::Converted => {
            m.insert("log_time".into(), "converted".into());
            m.insert(
                "source".into(),
                "deadline_ns (CLOCK_MONOTONIC) if recorded, else round(t * 1e9)".into(),
            );
        }
    }
    Metadata {
        name: "haptic2d.clock".into(),
        metadata: m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_offset_moves_a_monotonic_time_to_the_unix_time_now() {
        let off = monotonic_to_unix_offset_ns();
        let unix = crate::clock::now_ns() + off;
        let real = realtime_ns();
        // Within 50 ms (two clock reads apart on a loaded machine), and after 2020.
        assert!(unix.abs_diff(real) < 50_000_000, "{unix} vs {real}");
        assert!(unix > 1_577_836_800_000_000_000);
    }
}
