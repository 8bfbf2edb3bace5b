//! The run-time limit-cycle trip (DESIGN §7, issue 34 finding 6), shared by every system.
//!
//! The stability gate (§11.4) checks the loop with the hand released on a *model* of the device,
//! whose inertia comes from a datasheet or an estimate. A device lighter than the model (finding 6:
//! a 2DIY 4–5× lighter than the gate's 0.033–0.035 kg) can pass the gate and oscillate: the loop
//! gain grows as `1/m`, the oscillation grows until the motors saturate, and it then settles into a
//! limit cycle at `±τ_max` (both controllers spent about 2/3 of ~2 990 ticks there and the run exited
//! 0). This monitor sees that limit cycle from the torques alone.
//!
//! Over consecutive windows of `N = round(W/T)` ticks it counts the ticks with a motor at its torque
//! limit (after the saturation of §10.5, before the start-up ramp) and, per motor, the reversals of
//! the sign of its saturated torque. At the end of a window it trips when
//!
//! ```text
//! saturated ticks ≥ s_min·N   and   max_i reversals_i ≥ R_min
//! ```
//!
//! Thresholds (defaults `W` = 0.2 s, `s_min` = 0.5, `R_min` = 8):
//! - A limit cycle at frequency `f` with the motor saturated a fraction `s` of the time reverses
//!   `2·f·W` times a window; finding 6's cycle has `s ≈ 2/3` (and its frequency is measured in the
//!   test `a_device_lighter_than_the_gate_assumes_trips_on_its_limit_cycle`). `R_min` = 8 means a
//!   cycle of at least 20 Hz.
//! - A hand cannot do that: voluntary motion has a bandwidth of about 5–10 Hz (Brooks 1990, "The
//!   Human Factor of Haptic Interfaces"), so a push that saturates the motors reverses at most
//!   about 4 times in 0.2 s, and a push held against a stiff wall saturates without reversing.
//! - `s_min` = 0.5 rejects the short saturated spikes of a contact impact (a few ticks each).
//!
//! The trip comes at the end of the first window that holds the cycle: within `2·W` (0.4 s) of the
//! cycle's start. Never allocates.

use super::safety::{SafetyConfig, SafetyReason};

/// Relative tolerance for "at the limit": the saturation scales the peak motor to `τ_max` up to
/// rounding.
const AT_LIMIT: f64 = 1.0 - 1e-6;

/// The windowed counters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitCycleMonitor {
    window_ticks: u32,
    window: f64,
    min_saturated: u32,
    min_reversals: u32,
    ticks: u32,
    saturated: u32,
    last_sign: [i8; 4],
    reversals: [u32; 4],
}

impl LimitCycleMonitor {
    /// The monitor of `config` (`limit_cycle_*`) at period `dt` (s); off when the window is 0.
    pub fn new(config: &SafetyConfig, dt: f64) -> Self {
        let n = (config.limit_cycle_window / dt).round().max(0.0) as u32;
        Self {
            window_ticks: n,
            window: n as f64 * dt,
            min_saturated: (config.limit_cycle_saturation * n as f64).ceil() as u32,
            min_reversals: config.limit_cycle_reversals,
            ticks: 0,
            saturated: 0,
            last_sign: [0; 4],
            reversals: [0; 4],
        }
    }

    /// One tick's motor torques `tau` (N·m, after the saturation, before the ramp) against the
    /// limits `tau_max` (N·m; 0 = an unused motor). Returns the trip reason at the end of a window
    /// that holds a limit cycle.
    #[inline]
    pub fn observe(&mut self, tau: &[f64; 4], tau_max: &[f64; 4]) -> Option<SafetyReason> {
        if self.window_ticks == 0 {
            return None;
        }
        let mut any = false;
        for i in 0..4 {
            if tau_max[i] > 0.0 && tau[i].abs() >= AT_LIMIT * tau_max[i] {
                any = true;
                let sign = if tau[i] > 0.0 { 1 } else { -1 };
                if self.last_sign[i] != 0 && self.last_sign[i] != sign {
                    self.reversals[i] += 1;
                }
                self.last_sign[i] = sign;
            }
        }
        self.saturated += any as u32;
        self.ticks += 1;
        if self.ticks < self.window_ticks {
            return None;
        }
        let (motor, reversals) = self
            .reversals
            .iter()
            .copied()
            .enumerate()
            .fold((0, 0), |m, (i, r)| if r > m.1 { (i, r) } else { m });
        let out =
            (self.saturated >= self.min_saturated && reversals >= self.min_reversals).then(|| {
                SafetyReason::LimitCycle {
                    saturated: self.saturated as f64 / self.window_ticks as f64,
                    reversals,
                    motor,
                    window: self.window,
                }
            });
        self.ticks = 0;
        self.saturated = 0;
        self.reversals = [0; 4];
        out
    }

    /// Starts a fresh window and forgets the last signs (after a pause or a re-arm).
    pub fn reset(&mut self) {
        self.ticks = 0;
        self.saturated = 0;
        self.reversals = [0; 4];
        self.last_sign = [0; 4];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: f64 = 1e-3;
    const TAU_MAX: [f64; 4] = [0.123, 0.123, 0.0, 0.0];

    /// Runs `n` ticks of motor 0 at `τ(k)`; the tick of the first trip, if any.
    fn run(n: usize, tau: impl Fn(usize) -> f64) -> Option<(usize, SafetyReason)> {
        let mut m = LimitCycleMonitor::new(&SafetyConfig::default(), T);
        (0..n).find_map(|k| {
            m.observe(&[tau(k), 0.0, 0.0, 0.0], &TAU_MAX)
                .map(|r| (k, r))
        })
    }

    /// A square wave at `f` Hz between ±τ_max, saturated a fraction `duty` of each half period.
    fn cycle(f: f64, duty: f64) -> impl Fn(usize) -> f64 {
        move |k| {
            let phase = (k as f64 * T * f).fract();
            let half = if phase < 0.5 { 1.0 } else { -1.0 };
            let within = (phase * 2.0).fract();
            if within < duty {
                half * 0.123
            } else {
                half * 0.05
            }
        }
    }

    #[test]
    fn a_saturated_oscillation_trips_at_the_end_of_the_first_window() {
        let (k, r) = run(1000, cycle(40.0, 0.7)).expect("trips");
        assert_eq!(k, 199);
        match r {
            SafetyReason::LimitCycle {
                saturated,
                reversals,
                motor,
                window,
            } => {
                assert!((saturated - 0.7).abs() < 0.03, "{saturated}");
                assert!((15..=16).contains(&reversals), "{reversals}");
                assert_eq!(motor, 0);
                assert!((window - 0.2).abs() < 1e-12);
            }
            r => panic!("{r:?}"),
        }
        assert!(r.to_string().contains("device identify"), "{r}");
    }

    #[test]
    fn a_held_push_at_the_limit_never_trips() {
        assert!(run(5000, |_| -0.123).is_none());
    }

    #[test]
    fn a_hand_reversing_a_saturated_push_at_5_hz_never_trips() {
        assert!(run(5000, cycle(5.0, 1.0)).is_none());
    }

    #[test]
    fn an_oscillation_below_the_limit_or_seldom_saturated_never_trips() {
        // Fast, but never at the limit.
        assert!(run(5000, |k| if k % 20 < 10 { 0.12 } else { -0.12 }).is_none());
        // Fast and reversing, saturated only 30 % of the time (contact impacts, spikes).
        assert!(run(5000, cycle(40.0, 0.3)).is_none());
    }

    #[test]
    fn a_zero_window_turns_it_off() {
        let cfg = SafetyConfig {
            limit_cycle_window: 0.0,
            ..SafetyConfig::default()
        };
        let mut m = LimitCycleMonitor::new(&cfg, T);
        let f = cycle(40.0, 1.0);
        assert!((0..5000).all(|k| m.observe(&[f(k), 0.0, 0.0, 0.0], &TAU_MAX).is_none()));
    }
}
