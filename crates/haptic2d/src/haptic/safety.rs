//! The tick's own safety latch (DESIGN §7): a device fault (failed kinematics, closure monitor), a
//! non-finite value, the handle too close to a singularity or past the workspace bound, a stall
//! longer than [`SafetyConfig::max_stall_periods`], or a torque request above `τ_max` by more than
//! [`SafetyConfig::torque_trip_margin`] sets the torques to zero **in the same tick** and keeps them
//! at zero, with the reason, until [`Safety::reset`].
//!
//! The final gate ([`Safety::gate`]) is the last thing between the computation and the amplifiers:
//!
//! ```text
//! any τ_i non-finite                      → trip
//! max_i |τ_i| > τ_max·(1 + margin)        → trip                     (a request far above the limit is a bug)
//! max_i |τ_i| > τ_max                     → τ ← τ·τ_max / max_i |τ_i| (clamp, direction kept)
//! latched                                 → τ ← 0
//! ```
//!
//! It lives in the core so that [`HapticSystem::tick`](super::HapticSystem::tick) is safe on its own;
//! the real-time loop adds what only it can see (missed deadlines, a lost device) with its watchdog.

use std::fmt;

use crate::device::DeviceFault;

/// Why the torques were zeroed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SafetyReason {
    /// The device model reported a fault while sensing (§10.3 kinematics, closure monitor, …).
    Device(DeviceFault),
    /// The redundancy resolution failed (singular Jacobian).
    Torques(DeviceFault),
    /// Motor torque `index` (0–3) was non-finite.
    NonFiniteTorque {
        /// Motor index 0–3.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A monitored signal was non-finite.
    NonFiniteSignal {
        /// What it was (e.g. "device command f_cm", "slave pose").
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A motor torque request exceeded `τ_max` by more than the configured margin.
    TorqueLimit {
        /// Motor index 0–3.
        index: usize,
        /// The request (N·m).
        value: f64,
        /// The trip level `τ_max·(1 + margin)` (N·m).
        limit: f64,
    },
    /// The tick came `elapsed` seconds after the previous one, more than the configured stall limit:
    /// the device held the last torques, unsupervised, for that long.
    Stall {
        /// Time since the previous tick (s).
        elapsed: f64,
        /// The limit `max_stall_periods·T` (s).
        limit: f64,
    },
    /// The handle left the workspace square by more than the trip distance.
    Workspace {
        /// 0 = x, 1 = y.
        axis: usize,
        /// Handle coordinate on that axis (m).
        position: f64,
        /// The edge it passed, on that axis (m).
        edge: f64,
        /// Trip distance beyond the edge (m).
        trip: f64,
    },
    /// The singularity margin (§10.4) fell below the limit.
    Singularity {
        /// Margin measured (dimensionless).
        margin: f64,
        /// Limit (dimensionless).
        limit: f64,
    },
}

impl fmt::Display for SafetyReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SafetyReason::Device(e) => write!(f, "device fault: {e}"),
            SafetyReason::Torques(e) => write!(f, "torque computation failed: {e}"),
            SafetyReason::NonFiniteTorque { index, value } => {
                write!(f, "non-finite motor torque tau[{index}] = {value}")
            }
            SafetyReason::NonFiniteSignal { what, value } => {
                write!(f, "non-finite {what} = {value}")
            }
            SafetyReason::TorqueLimit { index, value, limit } => write!(
                f,
                "motor torque request tau[{index}] = {value:.4} N m is above the trip level {limit:.4} N m (tau_max plus the margin)"
            ),
            SafetyReason::Stall { elapsed, limit } => write!(
                f,
                "the loop stalled for {:.2} ms (limit {:.2} ms): the device held its torques unsupervised (machine overloaded or the device blocked)",
                elapsed * 1e3,
                limit * 1e3
            ),
            SafetyReason::Workspace {
                axis,
                position,
                edge,
                trip,
            } => write!(
                f,
                "handle {} = {position:.4} m is {:.1} mm past the workspace edge {edge:.4} m (trip at {:.1} mm; workspace_* fields of the device file)",
                ["x", "y"][(*axis).min(1)],
                (position - edge).abs() * 1e3,
                trip * 1e3
            ),
            SafetyReason::Singularity { margin, limit } => write!(
                f,
                "singularity margin {margin:.3} below {limit:.3} (handle at the workspace boundary)"
            ),
        }
    }
}

/// A latched trip: the reason and the tick it happened at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetyTrip {
    /// Tick index `k` of the trip.
    pub tick: u64,
    /// Time `k·T` of the trip (s).
    pub t: f64,
    /// What happened.
    pub reason: SafetyReason,
}

impl fmt::Display for SafetyTrip {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "safety stop at tick {} (t = {:.4} s), torques set to zero: {}",
            self.tick, self.t, self.reason
        )
    }
}

/// Settings of the tick's safety layer that are not device parameters (those — `τ_max`, the
/// singularity margin, the workspace bound — come from the device file).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetyConfig {
    /// Trip when a motor torque request exceeds `τ_max` by more than this fraction (dimensionless);
    /// requests between `τ_max` and `τ_max·(1 + margin)` are clamped to `τ_max` without a trip.
    /// Default 0.05: the redundancy resolution already saturates to `τ_max` (§10.5), so anything
    /// more than rounding above it is a defect upstream, not a hard push.
    pub torque_trip_margin: f64,
    /// Start-up ramp (s): after the first valid device reading (and after every re-arm) the torques
    /// are scaled by `min(1, n·T / ramp_time)` at the `n`-th tick, so the first tick's torques are
    /// exactly zero. 0 = no ramp. Default 0.5 s.
    pub ramp_time: f64,
    /// Trip when a tick comes more than this many periods after the previous one (dimensionless;
    /// see [`HapticSystem::tick_elapsed`](super::HapticSystem::tick_elapsed)). Default 5.
    pub max_stall_periods: f64,
}

impl Default for SafetyConfig {
    fn default() -> Self {
        Self {
            torque_trip_margin: 0.05,
            ramp_time: 0.5,
            max_stall_periods: 5.0,
        }
    }
}

impl SafetyConfig {
    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("torque_trip_margin", self.torque_trip_margin),
            ("ramp_time", self.ramp_time),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!(
                    "safety.{name} must be a finite number >= 0 (got {v})"
                ));
            }
        }
        if !(self.max_stall_periods.is_finite() && self.max_stall_periods >= 1.0) {
            return Err(format!(
                "safety.max_stall_periods must be a finite number >= 1 (got {}; default 5)",
                self.max_stall_periods
            ));
        }
        Ok(())
    }
}

/// The latch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Safety {
    /// Trip when the singularity margin is below this (dimensionless). Default: the device's
    /// `min_singularity_margin` (0.1).
    pub min_margin: f64,
    /// Joint torque limit `τ_max` (N·m) enforced by the final gate.
    pub tau_max: f64,
    /// Trip margin above `τ_max` (fraction, see [`SafetyConfig::torque_trip_margin`]).
    pub torque_trip_margin: f64,
    latched: Option<SafetyTrip>,
}

impl Safety {
    /// A latch tripping below singularity margin `min_margin`, with a final gate that clamps to
    /// `tau_max` (N·m) and trips above `tau_max·(1 + torque_trip_margin)`.
    pub fn new(min_margin: f64, tau_max: f64, torque_trip_margin: f64) -> Self {
        Self {
            min_margin,
            tau_max,
            torque_trip_margin,
            latched: None,
        }
    }

    /// Latches `reason` (the first reason wins) at tick `tick`, time `t` (s).
    #[inline]
    pub fn trip(&mut self, tick: u64, t: f64, reason: SafetyReason) {
        if self.latched.is_none() {
            self.latched = Some(SafetyTrip { tick, t, reason });
        }
    }

    /// Checks that every component of `v` is finite; trips with `what` otherwise.
    #[inline]
    pub fn check_finite(&mut self, tick: u64, t: f64, what: &'static str, v: &[f64]) {
        if let Some(&value) = v.iter().find(|x| !x.is_finite()) {
            self.trip(tick, t, SafetyReason::NonFiniteSignal { what, value });
        }
    }

    /// Final gate on the torques (see the module doc): trips on a non-finite torque or on a request
    /// above `τ_max·(1 + margin)`, clamps a request between the two to `τ_max` keeping the torque
    /// direction, then zeroes `tau` if latched. Returns true when the torques were zeroed.
    #[inline]
    pub fn gate(&mut self, tick: u64, t: f64, tau: &mut [f64; 4]) -> bool {
        if let Some((index, &value)) = tau.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            self.trip(tick, t, SafetyReason::NonFiniteTorque { index, value });
        } else {
            let (mut index, mut peak) = (0, 0.0f64);
            for (i, v) in tau.iter().enumerate() {
                if v.abs() > peak {
                    (index, peak) = (i, v.abs());
                }
            }
            let limit = self.tau_max * (1.0 + self.torque_trip_margin);
            if peak > limit {
                let value = tau[index];
                self.trip(
                    tick,
                    t,
                    SafetyReason::TorqueLimit {
                        index,
                        value,
                        limit,
                    },
                );
            } else if peak > self.tau_max {
                let s = self.tau_max / peak;
                tau.iter_mut().for_each(|v| *v *= s);
            }
        }
        if self.latched.is_some() {
            *tau = [0.0; 4];
            true
        } else {
            false
        }
    }

    /// The latched trip, if any.
    pub fn trip_info(&self) -> Option<SafetyTrip> {
        self.latched
    }

    /// True once tripped.
    pub fn is_latched(&self) -> bool {
        self.latched.is_some()
    }

    /// Re-arms the latch (an explicit user action).
    pub fn reset(&mut self) {
        self.latched = None;
    }
}
