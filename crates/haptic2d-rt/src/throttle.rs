//! Linux's real-time throttling, as the cause of a loop stall (issue 42, session 30).
//!
//! The kernel lets `SCHED_FIFO` threads run `kernel.sched_rt_runtime_us` out of every
//! `kernel.sched_rt_period_us` (950 000 of 1 000 000 by default): a loop thread whose ticks keep
//! overrunning never sleeps, reaches the limit and is stopped for the rest of the period (50 ms),
//! longer than a 1 kHz loop's stall limit. On the development machine, while the VM ran slow
//! (compute p50 540–700 µs against 350 µs), six of nine `haptic2d run pile:1000` runs stopped
//! 1.9–5.0 s in, with nothing else running; the three stop messages kept name host-side stalls
//! of 41.8–49.0 ms, within the throttle's 50 ms. The throttle fits these stalls; it was not
//! proven to cause them. [`hint`] names it after the loop has stopped (never on the hot path).

use std::path::Path;

/// The kernel's real-time limit: runtime and period (µs); `None` when the files cannot be read
/// (not Linux) or the limit is off (`sched_rt_runtime_us = -1`).
pub fn rt_limit() -> Option<(u64, u64)> {
    let read = |name: &str| -> Option<i64> {
        let p = Path::new("/proc/sys/kernel").join(name);
        std::fs::read_to_string(p).ok()?.trim().parse().ok()
    };
    let (runtime, period) = (read("sched_rt_runtime_us")?, read("sched_rt_period_us")?);
    (runtime >= 0 && period > 0 && runtime < period).then_some((runtime as u64, period as u64))
}

/// A note for a host-side stall of `stall_s` (s) of a `SCHED_FIFO` loop under the real-time limit
/// `limit` (runtime, period in µs): when the stall is no longer than the throttled part of a
/// period (plus 5 ms of sleep overshoot), the throttle can explain it, and the note says how to
/// lift it. `None` otherwise.
pub fn hint(stall_s: f64, limit: Option<(u64, u64)>) -> Option<String> {
    let (runtime, period) = limit?;
    let off_s = (period - runtime) as f64 * 1e-6;
    (stall_s.is_finite() && stall_s > 0.0 && stall_s <= off_s + 5e-3).then(|| {
        format!(
            "note: this kernel stops a real-time thread that has run {:.0} ms of the last {:.0} ms for the rest of that period ({:.0} ms; kernel.sched_rt_runtime_us = {runtime}): a loop whose ticks keep overrunning never sleeps and meets that limit, and the {:.1} ms stall fits it. Lower --rate or the scene's cost, or lift the limit with `sudo sysctl kernel.sched_rt_runtime_us=-1` (a runaway real-time thread can then freeze its core)",
            runtime as f64 * 1e-3,
            period as f64 * 1e-3,
            off_s * 1e3,
            stall_s * 1e3
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stall_the_length_of_the_throttled_part_of_a_period_is_named() {
        let limit = Some((950_000, 1_000_000));
        assert!(hint(0.047, limit).unwrap().contains("47.0 ms stall"));
        assert!(hint(0.041, limit).is_some());
        // Longer than the 50 ms the throttle can take (plus overshoot): something else.
        assert_eq!(hint(0.2, limit), None);
        // No limit (off, or not Linux): no note.
        assert_eq!(hint(0.047, None), None);
        assert_eq!(hint(f64::NAN, limit), None);
    }
}
