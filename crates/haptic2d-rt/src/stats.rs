//! Timing statistics of a fixed-rate loop, recorded without allocation.
//!
//! Per tick the loop records two durations:
//!
//! - **lateness** `= wake − deadline` (≥ 0): how late the tick started;
//! - **compute time** `= end − wake`: how long the tick's work took.
//!
//! Definitions used in the summary:
//!
//! - a tick is **on time** when its lateness is at most 10 % of the period
//!   ([`ON_TIME_FRACTION_OF_PERIOD`]); a skipped deadline is never on time,
//!   so the on-time fraction is `on_time / (ticks + skipped)`. The target of
//!   the haptic loop is ≥ 99.9 % on time at 1 kHz.
//! - an **overrun** is a tick that ended after the next deadline,
//!   `lateness + compute > period`. It includes every tick with
//!   `compute > period` or `lateness > period`.
//! - a **skipped** deadline is one the loop did not run because it had
//!   already passed when the previous tick ended (no bursting).
//! - the **achieved rate** is `(ticks − 1) / (last wake − first wake)`.

use crate::histogram::LogHistogram;
use crate::rt::RtReport;
use std::fmt;

/// A tick is on time when its lateness is at most this fraction of the period.
pub const ON_TIME_FRACTION_OF_PERIOD: f64 = 0.1;

/// Accumulates lateness and compute time of every tick. Storage is allocated
/// by [`TimingStats::new`]; [`record_tick`](TimingStats::record_tick) and
/// [`record_skipped`](TimingStats::record_skipped) never allocate.
#[derive(Debug, Clone)]
pub struct TimingStats {
    rate_hz: f64,
    period_ns: u64,
    on_time_limit_ns: u64,
    lateness: LogHistogram,
    compute: LogHistogram,
    ticks: u64,
    skipped: u64,
    overruns: u64,
    on_time: u64,
    first_deadline_ns: u64,
    first_wake_ns: u64,
    last_wake_ns: u64,
    last_end_ns: u64,
    worst_compute_ns: u64,
    worst_tick: u64,
    worst_wake_ns: u64,
}

impl TimingStats {
    /// Empty statistics for a loop at `rate_hz` (hertz) with period
    /// `period_ns` (nanoseconds).
    pub fn new(rate_hz: f64, period_ns: u64) -> Self {
        Self {
            rate_hz,
            period_ns,
            on_time_limit_ns: (period_ns as f64 * ON_TIME_FRACTION_OF_PERIOD) as u64,
            lateness: LogHistogram::new(),
            compute: LogHistogram::new(),
            ticks: 0,
            skipped: 0,
            overruns: 0,
            on_time: 0,
            first_deadline_ns: 0,
            first_wake_ns: 0,
            last_wake_ns: 0,
            last_end_ns: 0,
            worst_compute_ns: 0,
            worst_tick: 0,
            worst_wake_ns: 0,
        }
    }

    /// Records one executed tick: its deadline, wake-up and end times
    /// (`CLOCK_MONOTONIC` nanoseconds).
    #[inline]
    pub fn record_tick(&mut self, deadline_ns: u64, woke_ns: u64, end_ns: u64) {
        let lateness = woke_ns.saturating_sub(deadline_ns);
        let compute = end_ns.saturating_sub(woke_ns);
        if self.ticks == 0 {
            self.first_deadline_ns = deadline_ns;
            self.first_wake_ns = woke_ns;
        }
        self.ticks += 1;
        if compute > self.worst_compute_ns || self.ticks == 1 {
            self.worst_compute_ns = compute;
            self.worst_tick = self.ticks;
            self.worst_wake_ns = woke_ns;
        }
        self.last_wake_ns = woke_ns;
        self.last_end_ns = end_ns;
        self.lateness.record(lateness);
        self.compute.record(compute);
        if lateness <= self.on_time_limit_ns {
            self.on_time += 1;
        }
        if lateness + compute > self.period_ns {
            self.overruns += 1;
        }
    }

    /// Records `n` deadlines skipped because they had passed.
    #[inline]
    pub fn record_skipped(&mut self, n: u64) {
        self.skipped += n;
    }

    /// Number of executed ticks so far.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// The lateness histogram (nanoseconds).
    pub fn lateness(&self) -> &LogHistogram {
        &self.lateness
    }

    /// The compute-time histogram (nanoseconds).
    pub fn compute(&self) -> &LogHistogram {
        &self.compute
    }

    /// The summary of everything recorded so far, with `rt` (the real-time
    /// setup report, if any) attached for display.
    pub fn summary(&self, rt: Option<RtReport>) -> TimingSummary {
        let achieved_rate_hz = if self.ticks >= 2 && self.last_wake_ns > self.first_wake_ns {
            (self.ticks - 1) as f64 / ((self.last_wake_ns - self.first_wake_ns) as f64 * 1e-9)
        } else {
            0.0
        };
        let deadlines = self.ticks + self.skipped;
        TimingSummary {
            rate_hz: self.rate_hz,
            period_us: self.period_ns as f64 * 1e-3,
            ticks: self.ticks,
            deadlines,
            skipped: self.skipped,
            overruns: self.overruns,
            on_time: self.on_time,
            on_time_fraction: if deadlines > 0 {
                self.on_time as f64 / deadlines as f64
            } else {
                0.0
            },
            on_time_limit_us: self.on_time_limit_ns as f64 * 1e-3,
            elapsed_s: if self.ticks > 0 {
                (self.last_end_ns - self.first_deadline_ns) as f64 * 1e-9
            } else {
                0.0
            },
            achieved_rate_hz,
            lateness_us: Percentiles::of(&self.lateness),
            compute_us: Percentiles::of(&self.compute),
            worst_compute_tick: self.worst_tick,
            worst_compute_at_s: if self.ticks > 0 {
                self.worst_wake_ns.saturating_sub(self.first_deadline_ns) as f64 * 1e-9
            } else {
                0.0
            },
            rt,
        }
    }
}

/// Quantiles of one timing quantity, in microseconds (all 0 when there were
/// no ticks).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Percentiles {
    /// Median, µs.
    pub p50: f64,
    /// 99th percentile, µs.
    pub p99: f64,
    /// 99.9th percentile, µs.
    pub p999: f64,
    /// Maximum (exact), µs.
    pub max: f64,
    /// Mean (exact), µs.
    pub mean: f64,
}

impl Percentiles {
    /// Reads the quantiles of a nanosecond histogram, in microseconds.
    pub fn of(h: &LogHistogram) -> Self {
        let us = |v: Option<u64>| v.map_or(0.0, |ns| ns as f64 * 1e-3);
        Self {
            p50: us(h.quantile(0.5)),
            p99: us(h.quantile(0.99)),
            p999: us(h.quantile(0.999)),
            max: us(h.max()),
            mean: h.mean().map_or(0.0, |ns| ns * 1e-3),
        }
    }
}

/// The timing report of a loop run (see the module docs for definitions).
#[derive(Debug, Clone, PartialEq)]
pub struct TimingSummary {
    /// Target rate, Hz.
    pub rate_hz: f64,
    /// Target period, µs.
    pub period_us: f64,
    /// Ticks executed.
    pub ticks: u64,
    /// Deadlines that came due: `ticks + skipped`.
    pub deadlines: u64,
    /// Deadlines skipped because they had passed when the previous tick ended.
    pub skipped: u64,
    /// Ticks that ended after the next deadline (`lateness + compute > period`).
    pub overruns: u64,
    /// Ticks with lateness ≤ `on_time_limit_us`.
    pub on_time: u64,
    /// `on_time / deadlines`, in [0, 1].
    pub on_time_fraction: f64,
    /// The on-time lateness limit, 10 % of the period, µs.
    pub on_time_limit_us: f64,
    /// Wall time from the first deadline to the end of the last tick, s.
    pub elapsed_s: f64,
    /// Measured tick rate `(ticks − 1) / (last wake − first wake)`, Hz.
    pub achieved_rate_hz: f64,
    /// Lateness `wake − deadline`, µs.
    pub lateness_us: Percentiles,
    /// Compute time `end − wake`, µs.
    pub compute_us: Percentiles,
    /// The tick (from 1) whose compute time was the largest (the first such tick); 0 without ticks.
    pub worst_compute_tick: u64,
    /// When that tick woke, s after the first deadline.
    pub worst_compute_at_s: f64,
    /// The real-time setup report, when the loop asked for real-time treatment.
    pub rt: Option<RtReport>,
}

impl fmt::Display for TimingSummary {
    /// The human summary (DESIGN §3): achieved rate, lateness
    /// p50/p99/p99.9/max, compute time p50/p99, overruns — three lines, plus
    /// a fourth on the real-time setup when there is one (no trailing newline).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "timing: achieved {:.1} Hz (target {} Hz), {} ticks in {:.3} s; on time {:.3} % (lateness ≤ {:.1} µs); overruns {}; skipped deadlines {}",
            self.achieved_rate_hz,
            self.rate_hz,
            self.ticks,
            self.elapsed_s,
            self.on_time_fraction * 100.0,
            self.on_time_limit_us,
            self.overruns,
            self.skipped,
        )?;
        for (name, p) in [
            ("lateness", &self.lateness_us),
            ("compute ", &self.compute_us),
        ] {
            write!(
                f,
                "\n  {name} µs: p50 {:.2}  p99 {:.2}  p99.9 {:.2}  max {:.2}  (mean {:.2})",
                p.p50, p.p99, p.p999, p.max, p.mean
            )?;
        }
        if self.worst_compute_tick > 0 {
            write!(
                f,
                "\n  worst compute: tick {} at {:.3} s",
                self.worst_compute_tick, self.worst_compute_at_s
            )?;
        }
        if let Some(rt) = &self.rt {
            write!(f, "\n  {rt}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The summary names the tick with the largest compute time and when it woke, so that a run's
    /// worst tick can be found in its log.
    #[test]
    fn the_summary_names_the_tick_of_the_worst_compute_time() {
        let mut s = TimingStats::new(1000.0, 1_000_000);
        let t0 = 5_000_000_000;
        for (k, compute_ns) in [10_000u64, 50_000, 20_000, 50_000].into_iter().enumerate() {
            let deadline = t0 + k as u64 * 1_000_000;
            s.record_tick(deadline, deadline + 1_000, deadline + 1_000 + compute_ns);
        }
        let sum = s.summary(None);
        assert_eq!(
            sum.worst_compute_tick, 2,
            "the first tick of the largest compute"
        );
        assert!(
            (sum.worst_compute_at_s - 1.001e-3).abs() < 1e-12,
            "{}",
            sum.worst_compute_at_s
        );
        assert!(
            sum.to_string().contains("worst compute: tick 2 at 0.001 s"),
            "{sum}"
        );
        let empty = TimingStats::new(1000.0, 1_000_000).summary(None);
        assert_eq!(empty.worst_compute_tick, 0);
        assert!(!empty.to_string().contains("worst compute"));
    }
}
