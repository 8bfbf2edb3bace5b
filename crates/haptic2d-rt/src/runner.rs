//! The fixed-rate loop runner: calls a tick function at every deadline and
//! measures it.
//!
//! ```text
//! setup (real-time if asked, timer slack 1 ns, statistics preallocated)
//! loop:
//!     stop flag set, or duration over?          → stop
//!     sleep + spin to the next deadline          (clock)
//!     tick(info)                                 (the caller's work)
//!     record lateness and compute time           (stats, no allocation)
//!     tick asked to stop?                        → stop
//!     advance to the next deadline still ahead, counting skipped ones
//! ```
//!
//! The runner knows nothing of devices or worlds: the haptic tick (device
//! read → kinematics → observer → controller → world step → torques →
//! watchdog → device write → telemetry) is the closure the caller passes.

use crate::clock::{now_ns, period_ns_from_rate, set_timer_slack_ns, FixedRateClock};
use crate::rt::{setup_realtime, RtRequest};
use crate::stats::{TimingStats, TimingSummary};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// Settings of [`run_loop`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopConfig {
    /// Tick rate, Hz. Default 1000.
    pub rate_hz: f64,
    /// Run for this long (wall time from the first deadline), or until
    /// stopped if `None`. Default `None`.
    pub duration: Option<Duration>,
    /// Busy-wait margin before each deadline, µs: the loop sleeps until
    /// `deadline − spin_us`, then spins. Default 30 µs; must be below the
    /// period.
    pub spin_us: f64,
    /// Ask for real-time treatment of the loop thread ([`RtRequest`]);
    /// refusal is reported in the summary, not an error. Default false.
    pub rt: bool,
    /// What "real-time" means when `rt` is true. Default [`RtRequest::default`].
    pub rt_request: RtRequest,
}

impl Default for LoopConfig {
    fn default() -> Self {
        Self {
            rate_hz: 1000.0,
            duration: None,
            spin_us: 30.0,
            rt: false,
            rt_request: RtRequest::default(),
        }
    }
}

impl LoopConfig {
    /// Checks the settings; errors name the parameter.
    pub fn validate(&self) -> Result<(), String> {
        let period_ns = period_ns_from_rate(self.rate_hz)?;
        if !self.spin_us.is_finite() || self.spin_us < 0.0 {
            return Err(format!(
                "spin_us = {}: the spin margin must be ≥ 0 µs (default 30)",
                self.spin_us
            ));
        }
        if self.spin_us * 1e3 > period_ns as f64 {
            return Err(format!(
                "spin_us = {}: the spin margin must not exceed the period ({} µs at {} Hz)",
                self.spin_us,
                period_ns as f64 * 1e-3,
                self.rate_hz
            ));
        }
        Ok(())
    }
}

/// What the tick function is told about its tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickInfo {
    /// Index of this tick among executed ticks (0, 1, 2, …).
    pub index: u64,
    /// Index of this tick's deadline, counting skipped deadlines (≥ `index`).
    pub deadline_index: u64,
    /// Time of this deadline since deadline 0, `deadline_index · period`, s.
    pub t_s: f64,
    /// The period, s.
    pub period_s: f64,
    /// The period, ns.
    pub period_ns: u64,
    /// How late this tick started, `wake − deadline`, ns.
    pub lateness_ns: u64,
    /// Deadlines skipped just before this tick because they had passed.
    pub skipped: u64,
    /// The deadline, `CLOCK_MONOTONIC` ns.
    pub deadline_ns: u64,
}

impl TickInfo {
    /// True when this tick missed its deadline: deadlines were skipped just
    /// before it, or it started more than one period late. Feed this to the
    /// watchdog's `deadline_missed`.
    #[inline]
    pub fn missed_deadline(&self) -> bool {
        self.skipped > 0 || self.lateness_ns > self.period_ns
    }
}

/// Measures the time between consecutive ticks (wake to wake), for the stall check of the watchdog
/// and for a tick that must differentiate over the real interval. No allocation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TickInterval {
    prev_wake_ns: Option<u64>,
}

impl TickInterval {
    /// A meter that has seen no tick yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Time since the previous tick's wake-up (ns), from this tick's `info`; one period for the
    /// first tick. A wake-up is `deadline + lateness`.
    #[inline]
    pub fn update(&mut self, info: &TickInfo) -> u64 {
        let wake = info.deadline_ns.saturating_add(info.lateness_ns);
        let elapsed = match self.prev_wake_ns {
            Some(p) => wake.saturating_sub(p),
            None => info.period_ns,
        };
        self.prev_wake_ns = Some(wake);
        elapsed
    }

    /// Forgets the previous tick (e.g. after a pause): the next update returns one period.
    pub fn reset(&mut self) {
        self.prev_wake_ns = None;
    }
}

/// What the tick function wants next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TickControl {
    /// Keep going.
    Continue,
    /// Stop after this tick (e.g. the watchdog tripped or the replay ended).
    Stop,
}

/// Runs `tick` at every deadline of `config.rate_hz` until `config.duration`
/// has elapsed, `stop` becomes true (e.g. set by a Ctrl-C handler), or the
/// tick returns [`TickControl::Stop`]. Runs on the calling thread (spawn a
/// thread for it if the caller has other work). Deadlines that passed while a
/// tick overran are skipped and counted, never run back to back.
///
/// Returns the timing summary; errors only for an invalid `config`, before
/// the first tick.
pub fn run_loop(
    config: &LoopConfig,
    stop: &AtomicBool,
    mut tick: impl FnMut(TickInfo) -> TickControl,
) -> Result<TimingSummary, String> {
    config.validate()?;
    let spin = Duration::from_nanos((config.spin_us * 1e3).round() as u64);
    let mut clock = FixedRateClock::new(config.rate_hz, spin)?;
    let period_ns = clock.period_ns();
    let period_s = period_ns as f64 * 1e-9;
    // Deadlines within the duration: round(duration / period).
    let max_deadlines = config.duration.map(|d| {
        let d_ns = u64::try_from(d.as_nanos()).unwrap_or(u64::MAX);
        d_ns.saturating_add(period_ns / 2) / period_ns
    });

    // Setup, before the first deadline: everything that may allocate or fault.
    let rt_report = config.rt.then(|| setup_realtime(&config.rt_request));
    set_timer_slack_ns(1);
    let mut stats = TimingStats::new(config.rate_hz, period_ns);

    clock.start();
    let mut index = 0u64;
    let mut skipped = 0u64;
    loop {
        if stop.load(Ordering::Relaxed) {
            break;
        }
        if max_deadlines.is_some_and(|n| clock.next_index() >= n) {
            break;
        }
        let wake = clock.wait();
        let info = TickInfo {
            index,
            deadline_index: wake.deadline_index,
            t_s: wake.deadline_index as f64 * period_s,
            period_s,
            period_ns,
            lateness_ns: wake.lateness_ns(),
            skipped,
            deadline_ns: wake.deadline_ns,
        };
        let control = tick(info);
        let end_ns = now_ns();
        stats.record_tick(wake.deadline_ns, wake.woke_ns, end_ns);
        index += 1;
        if control == TickControl::Stop {
            break;
        }
        skipped = clock.advance(end_ns);
        // Deadlines past the end of the run were never due.
        if let Some(n) = max_deadlines {
            skipped -= clock.next_index().saturating_sub(n).min(skipped);
        }
        stats.record_skipped(skipped);
    }
    Ok(stats.summary(rt_report))
}

/// Runs [`run_loop`] on a new thread named `haptic2d-rt` (the real-time
/// setup, if asked for, then applies to that thread) and returns its handle.
/// Join it to get the summary. Errors if the thread cannot be started.
pub fn spawn_loop<F>(
    config: LoopConfig,
    stop: Arc<AtomicBool>,
    tick: F,
) -> Result<JoinHandle<Result<TimingSummary, String>>, String>
where
    F: FnMut(TickInfo) -> TickControl + Send + 'static,
{
    std::thread::Builder::new()
        .name("haptic2d-rt".into())
        .spawn(move || run_loop(&config, &stop, tick))
        .map_err(|e| format!("cannot start the real-time loop thread: {e}"))
}
