//! Fixed-rate scheduling with absolute deadlines.
//!
//! Time comes from `CLOCK_MONOTONIC` in integer nanoseconds. Deadline `k` is
//! `t0 + k·T` exactly (no accumulated drift). To wait for a deadline the clock
//! sleeps with `clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME)` until
//! `deadline − spin`, then busy-waits until the deadline itself. The sleep
//! absorbs most of the period at no CPU cost; the spin absorbs the kernel's
//! wake-up latency, so the tick starts within a few hundred nanoseconds of its
//! deadline when the machine is quiet.
//!
//! Missed deadlines are skipped, never replayed in a burst: after a tick, the
//! next deadline is the first one that is still in the future
//! ([`FixedRateClock::advance`]).

use std::time::Duration;

/// Nanoseconds per second.
pub const NS_PER_S: u64 = 1_000_000_000;

/// Reads `CLOCK_MONOTONIC`, in nanoseconds since an arbitrary fixed origin
/// (boot on Linux). Never goes backwards; does not allocate.
#[inline]
pub fn now_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_MONOTONIC always exists on Linux.
    unsafe {
        libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts);
    }
    (ts.tv_sec as u64) * NS_PER_S + ts.tv_nsec as u64
}

/// Sleeps until the absolute `CLOCK_MONOTONIC` time `t_ns` (nanoseconds), with
/// `clock_nanosleep(TIMER_ABSTIME)`. Returns at once if `t_ns` has passed.
/// Retries on `EINTR` (a signal such as Ctrl-C), so it never returns early.
pub fn sleep_until_ns(t_ns: u64) {
    let ts = libc::timespec {
        tv_sec: (t_ns / NS_PER_S) as libc::time_t,
        tv_nsec: (t_ns % NS_PER_S) as libc::c_long,
    };
    loop {
        // SAFETY: `ts` is a valid timespec; the remainder pointer may be null with TIMER_ABSTIME.
        let rc = unsafe {
            libc::clock_nanosleep(
                libc::CLOCK_MONOTONIC,
                libc::TIMER_ABSTIME,
                &ts,
                std::ptr::null_mut(),
            )
        };
        if rc != libc::EINTR {
            return;
        }
    }
}

/// Busy-waits until `CLOCK_MONOTONIC` reaches `t_ns` (nanoseconds) and
/// returns the time it read last, which is ≥ `t_ns`.
#[inline]
pub fn spin_until_ns(t_ns: u64) -> u64 {
    loop {
        let now = now_ns();
        if now >= t_ns {
            return now;
        }
        std::hint::spin_loop();
    }
}

/// Sets the calling thread's timer slack to `slack_ns` nanoseconds
/// (`prctl(PR_SET_TIMERSLACK)`). Linux lets normal threads' sleeps overshoot by
/// up to 50 µs by default to batch wake-ups; a haptic loop wants 1 ns.
/// Needs no privilege. Returns `false` if the kernel refused.
pub fn set_timer_slack_ns(slack_ns: u64) -> bool {
    // SAFETY: PR_SET_TIMERSLACK takes one unsigned long argument and touches only this thread.
    let rc = unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, slack_ns as libc::c_ulong, 0, 0, 0) };
    rc == 0
}

/// What [`FixedRateClock::wait`] observed for one deadline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Wake {
    /// Index of the deadline since [`FixedRateClock::start`] (0 for the first),
    /// counting skipped deadlines too.
    pub deadline_index: u64,
    /// The deadline, `CLOCK_MONOTONIC` nanoseconds.
    pub deadline_ns: u64,
    /// When the wait returned, `CLOCK_MONOTONIC` nanoseconds (≥ `deadline_ns`).
    pub woke_ns: u64,
}

impl Wake {
    /// Lateness of the wake-up, `woke − deadline`, in nanoseconds (≥ 0).
    #[inline]
    pub fn lateness_ns(&self) -> u64 {
        self.woke_ns.saturating_sub(self.deadline_ns)
    }
}

/// A periodic schedule of absolute deadlines `t0 + k·T`.
#[derive(Debug, Clone)]
pub struct FixedRateClock {
    /// Period `T`, nanoseconds.
    period_ns: u64,
    /// Spin margin before each deadline, nanoseconds.
    spin_ns: u64,
    /// `t0`, the time of deadline 0, `CLOCK_MONOTONIC` nanoseconds.
    t0_ns: u64,
    /// Index of the next deadline to wait for.
    next_index: u64,
}

impl FixedRateClock {
    /// A clock ticking at `rate_hz` (hertz) that spins for the last `spin`
    /// before each deadline. Errors name the offending parameter: the rate
    /// must be finite, positive and give a period of at least 1 µs, and the
    /// spin margin may not exceed the period.
    pub fn new(rate_hz: f64, spin: Duration) -> Result<Self, String> {
        let period_ns = period_ns_from_rate(rate_hz)?;
        let spin_ns = u64::try_from(spin.as_nanos()).unwrap_or(u64::MAX);
        if spin_ns > period_ns {
            return Err(format!(
                "spin margin {} µs exceeds the period {} µs (rate {rate_hz} Hz): choose a spin margin below the period",
                spin_ns as f64 / 1e3,
                period_ns as f64 / 1e3
            ));
        }
        Ok(Self {
            period_ns,
            spin_ns,
            t0_ns: 0,
            next_index: 0,
        })
    }

    /// The period `T`, nanoseconds.
    pub fn period_ns(&self) -> u64 {
        self.period_ns
    }

    /// The spin margin, nanoseconds.
    pub fn spin_ns(&self) -> u64 {
        self.spin_ns
    }

    /// `t0`, the time of deadline 0 (`CLOCK_MONOTONIC` nanoseconds); 0 before
    /// [`start`](Self::start).
    pub fn t0_ns(&self) -> u64 {
        self.t0_ns
    }

    /// Index of the next deadline [`wait`](Self::wait) will wait for.
    pub fn next_index(&self) -> u64 {
        self.next_index
    }

    /// The absolute time of deadline `index`, `CLOCK_MONOTONIC` nanoseconds.
    #[inline]
    pub fn deadline_ns(&self, index: u64) -> u64 {
        self.t0_ns + index * self.period_ns
    }

    /// Starts the schedule: deadline 0 is one period from now, so that the
    /// first tick is not born late.
    pub fn start(&mut self) {
        self.t0_ns = now_ns() + self.period_ns;
        self.next_index = 0;
    }

    /// Waits for the next deadline: sleeps until `deadline − spin`, then
    /// spins until the deadline. Returns at once (late) if the deadline has
    /// passed. Does not advance the schedule; call [`advance`](Self::advance)
    /// once the tick's work is done.
    #[inline]
    pub fn wait(&self) -> Wake {
        let deadline_ns = self.deadline_ns(self.next_index);
        let wake_at = deadline_ns.saturating_sub(self.spin_ns);
        if now_ns() < wake_at {
            sleep_until_ns(wake_at);
        }
        let woke_ns = spin_until_ns(deadline_ns);
        Wake {
            deadline_index: self.next_index,
            deadline_ns,
            woke_ns,
        }
    }

    /// Moves to the next deadline that is still in the future at `now_ns`
    /// (`CLOCK_MONOTONIC` nanoseconds, normally the end of the tick), and
    /// returns how many deadlines were skipped on the way (0 when the tick
    /// finished in time). Skipping, rather than running the missed ticks
    /// back to back, keeps a late loop from bursting.
    #[inline]
    pub fn advance(&mut self, now_ns: u64) -> u64 {
        let mut next = self.next_index + 1;
        let next_deadline = self.deadline_ns(next);
        let mut skipped = 0;
        if now_ns >= next_deadline {
            // Deadlines next, next+1, …, up to the last one ≤ now, have passed.
            skipped = (now_ns - next_deadline) / self.period_ns + 1;
            next += skipped;
        }
        self.next_index = next;
        skipped
    }
}

/// The period in nanoseconds of a rate in hertz, rounded to the nearest
/// nanosecond. Errors (naming `rate_hz`) for a non-finite or non-positive
/// rate, or one above 1 MHz.
pub fn period_ns_from_rate(rate_hz: f64) -> Result<u64, String> {
    if !rate_hz.is_finite() || rate_hz <= 0.0 {
        return Err(format!(
            "rate_hz = {rate_hz}: the loop rate must be a positive number of hertz (e.g. 1000)"
        ));
    }
    if rate_hz > 1e6 {
        return Err(format!(
            "rate_hz = {rate_hz}: rates above 1 MHz (periods below 1 µs) are not supported"
        ));
    }
    Ok((1e9 / rate_hz).round() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advance_skips_passed_deadlines() {
        let mut c = FixedRateClock::new(1000.0, Duration::from_micros(20)).unwrap();
        c.t0_ns = 1_000_000_000;
        // Finished tick 0 within its period: no skip.
        assert_eq!(c.advance(1_000_500_000), 0);
        assert_eq!(c.next_index(), 1);
        // Tick 1 ended exactly at deadline 2: deadline 2 has passed, skip it.
        assert_eq!(c.advance(1_002_000_000), 1);
        assert_eq!(c.next_index(), 3);
        // Tick 3 ended 3.5 periods after its deadline: deadlines 4, 5, 6 passed.
        assert_eq!(c.advance(1_006_500_000), 3);
        assert_eq!(c.next_index(), 7);
    }

    #[test]
    fn rejects_bad_rates_and_spin() {
        assert!(FixedRateClock::new(0.0, Duration::ZERO)
            .unwrap_err()
            .contains("rate_hz"));
        assert!(FixedRateClock::new(f64::NAN, Duration::ZERO).is_err());
        assert!(FixedRateClock::new(1000.0, Duration::from_millis(2))
            .unwrap_err()
            .contains("spin"));
    }

    #[test]
    fn wait_never_returns_before_the_deadline() {
        let mut c = FixedRateClock::new(10_000.0, Duration::from_micros(30)).unwrap();
        c.start();
        for _ in 0..20 {
            let w = c.wait();
            assert!(w.woke_ns >= w.deadline_ns);
            c.advance(now_ns());
        }
    }
}
