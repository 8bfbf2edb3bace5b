//! The tick's own safety latch (DESIGN §7): a device fault (failed kinematics, closure monitor), a
//! non-finite value, or the handle too close to a singularity sets the torques to zero **in the same
//! tick** and keeps them at zero, with the reason, until [`Safety::reset`].
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

/// The latch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Safety {
    /// Trip when the singularity margin is below this (dimensionless). Default: the device's
    /// `min_singularity_margin` (0.1).
    pub min_margin: f64,
    latched: Option<SafetyTrip>,
}

impl Safety {
    /// A latch tripping below singularity margin `min_margin`.
    pub fn new(min_margin: f64) -> Self {
        Self {
            min_margin,
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

    /// Final gate on the torques: trips on a non-finite torque, then zeroes `tau` if latched.
    /// Returns true when the torques were zeroed.
    #[inline]
    pub fn gate(&mut self, tick: u64, t: f64, tau: &mut [f64; 4]) -> bool {
        if let Some((index, &value)) = tau.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            self.trip(tick, t, SafetyReason::NonFiniteTorque { index, value });
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
