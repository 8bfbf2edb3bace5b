//! Live timing of the haptic loop for the display: lateness and compute-time quantiles over a
//! rolling window, plus totals since the start. Recorded by the loop itself (the runner's own
//! [`TimingStats`](haptic2d_rt::TimingStats) is only read at the end of a run).
//!
//! Recording is an index computation and a few increments; once per window (1 s by default) the
//! quantiles are read and the histograms cleared, which costs a pass over their counters (tens of
//! microseconds): a cost the loop pays once a second, never an allocation.

use crate::frame::LoopTiming;
use haptic2d_rt::histogram::LogHistogram;
use haptic2d_rt::TickInfo;

/// Rolling-window timing statistics of a fixed-rate loop.
#[derive(Debug, Clone)]
pub struct LiveTiming {
    rate_hz: f64,
    period_ns: u64,
    window_ns: u64,
    lateness: LogHistogram,
    compute: LogHistogram,
    window_start_wake_ns: Option<u64>,
    window_ticks: u64,
    ticks: u64,
    overruns: u64,
    skipped: u64,
    last: LoopTiming,
}

impl LiveTiming {
    /// Statistics for a loop at `rate_hz` (Hz), summarised every `window_s` seconds (> 0; e.g. 1).
    /// Allocates its histograms here, once.
    pub fn new(rate_hz: f64, window_s: f64) -> Result<Self, String> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(format!(
                "rate_hz = {rate_hz}: must be a positive rate in Hz"
            ));
        }
        if !(window_s.is_finite() && window_s > 0.0) {
            return Err(format!("window_s = {window_s}: must be > 0 s"));
        }
        Ok(Self {
            rate_hz,
            period_ns: (1e9 / rate_hz).round() as u64,
            window_ns: (window_s * 1e9) as u64,
            lateness: LogHistogram::new(),
            compute: LogHistogram::new(),
            window_start_wake_ns: None,
            window_ticks: 0,
            ticks: 0,
            overruns: 0,
            skipped: 0,
            last: LoopTiming {
                rate_hz,
                ..LoopTiming::default()
            },
        })
    }

    /// Records one tick from the runner's [`TickInfo`] and the tick's end time `end_ns`
    /// (`haptic2d_rt::clock::now_ns()` at the end of the tick's work). No allocation.
    #[inline]
    pub fn record_tick(&mut self, info: &TickInfo, end_ns: u64) {
        let woke = info.deadline_ns + info.lateness_ns;
        self.record(
            woke,
            info.lateness_ns,
            end_ns.saturating_sub(woke),
            info.skipped,
        );
    }

    /// Records one tick that woke at `woke_ns` (monotonic ns), `lateness_ns` after its deadline,
    /// computed for `compute_ns`, after skipping `skipped` deadlines. No allocation.
    pub fn record(&mut self, woke_ns: u64, lateness_ns: u64, compute_ns: u64, skipped: u64) {
        self.ticks += 1;
        self.skipped += skipped;
        if lateness_ns + compute_ns > self.period_ns {
            self.overruns += 1;
        }
        self.lateness.record(lateness_ns);
        self.compute.record(compute_ns);
        self.window_ticks += 1;
        let start = *self.window_start_wake_ns.get_or_insert(woke_ns);
        let span = woke_ns.saturating_sub(start);
        if span >= self.window_ns && self.window_ticks >= 2 {
            let us = |v: Option<u64>| v.map_or(0.0, |ns| ns as f64 * 1e-3);
            self.last = LoopTiming {
                rate_hz: self.rate_hz,
                achieved_hz: (self.window_ticks - 1) as f64 / (span as f64 * 1e-9),
                lateness_p50_us: us(self.lateness.quantile(0.5)),
                lateness_p99_us: us(self.lateness.quantile(0.99)),
                lateness_max_us: us(self.lateness.max()),
                compute_p50_us: us(self.compute.quantile(0.5)),
                compute_p99_us: us(self.compute.quantile(0.99)),
                overruns: self.overruns,
                skipped: self.skipped,
                ticks: self.ticks,
            };
            self.lateness.clear();
            self.compute.clear();
            // The window's last tick opens the next one, so no interval is lost.
            self.window_start_wake_ns = Some(woke_ns);
            self.lateness.record(lateness_ns);
            self.compute.record(compute_ns);
            self.window_ticks = 1;
        }
    }

    /// The summary of the last complete window, with the totals (ticks, overruns, skipped) up to
    /// date.
    pub fn snapshot(&self) -> LoopTiming {
        LoopTiming {
            overruns: self.overruns,
            skipped: self.skipped,
            ticks: self.ticks,
            ..self.last
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_summary_reports_rate_and_quantiles() {
        let mut t = LiveTiming::new(1000.0, 1.0).unwrap();
        // 2001 ticks, 1 ms apart, lateness 10 µs except one of 500 µs, compute 5 µs; one overrun.
        for k in 0..2001u64 {
            let late = if k == 700 { 500_000 } else { 10_000 };
            let compute = if k == 900 { 995_000 } else { 5_000 };
            t.record(k * 1_000_000 + late, late, compute, 0);
        }
        let s = t.snapshot();
        assert_eq!(s.ticks, 2001);
        assert_eq!(s.overruns, 1);
        assert!((s.achieved_hz - 1000.0).abs() < 1.0, "{s:?}");
        assert!((s.lateness_p50_us - 10.0).abs() < 0.1, "{s:?}");
        assert!((s.compute_p50_us - 5.0).abs() < 0.1, "{s:?}");
        assert!(
            s.lateness_max_us <= 11.0,
            "second window has no spike: {s:?}"
        );
        assert!(LiveTiming::new(0.0, 1.0).unwrap_err().contains("rate_hz"));
        assert!(LiveTiming::new(1.0, 0.0).unwrap_err().contains("window_s"));
    }
}
