//! The tick's own safety latch (DESIGN §7): a device fault (failed kinematics, closure monitor), a
//! non-finite value, the handle too close to a singularity or past the workspace bound, a stall
//! longer than [`SafetyConfig::max_stall_periods`], an implausible joint angle or speed
//! ([`SafetyConfig::max_joint_angle`], [`SafetyConfig::max_joint_speed`]), a limit cycle at the torque
//! limit ([`SafetyConfig::limit_cycle_window`]), or a torque request above `τ_max` by more than
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
        /// The limit `max(max_stall_periods·T, min_stall_time)` (s).
        limit: f64,
        /// The part of `elapsed` the loop spent waiting for the device's reply (s); the rest is the
        /// host's own (sleep overshoot, computation). NaN when unknown (a caller that measured only
        /// the interval).
        device_wait: f64,
    },
    /// A joint angle beyond the plausible range (an encoder or driver fault: no linkage turns that
    /// far).
    JointAngle {
        /// Joint index 0–3.
        index: usize,
        /// The reading (rad).
        value: f64,
        /// The bound `max_joint_angle` (rad).
        limit: f64,
    },
    /// A joint moved faster between two readings than any hand can move it (an encoder glitch, a
    /// lost count burst, a re-zeroed encoder).
    JointSpeed {
        /// Joint index 0–3.
        index: usize,
        /// The speed `|Δq|/Δt` (rad/s).
        value: f64,
        /// The bound `max_joint_speed` (rad/s).
        limit: f64,
    },
    /// A limit cycle: over one window the motors sat at the torque limit most of the time and the
    /// saturated torque kept reversing (the loop oscillates at the actuators' limit; see
    /// [`LimitCycleMonitor`](super::limit_cycle::LimitCycleMonitor)).
    LimitCycle {
        /// Fraction of the window's ticks with a motor at its torque limit (dimensionless).
        saturated: f64,
        /// Reversals of the saturated torque on the motor that reversed most.
        reversals: u32,
        /// Its motor index 0–3.
        motor: usize,
        /// The window (s).
        window: f64,
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
            SafetyReason::Stall {
                elapsed,
                limit,
                device_wait,
            } if device_wait.is_finite() => {
                let host = elapsed - device_wait;
                write!(
                    f,
                    "the loop stalled for {:.2} ms (limit {:.2} ms): {:.2} ms on the host (sleep overshoot, computation) and {:.2} ms waiting for the device; the device held its torques unsupervised. {}",
                    elapsed * 1e3,
                    limit * 1e3,
                    host * 1e3,
                    device_wait * 1e3,
                    if host >= *device_wait {
                        "The host was late: the machine is overloaded (give the loop real-time priority, close other programs, lower --rate, or raise max_stall_periods in the device file)"
                    } else {
                        "The device was late: it answered slowly (check the cable or the network; its reply timeout is timeout_periods in the device file)"
                    }
                )
            }
            SafetyReason::Stall { elapsed, limit, .. } => write!(
                f,
                "the loop stalled for {:.2} ms (limit {:.2} ms): the device held its torques unsupervised (machine overloaded or the device blocked)",
                elapsed * 1e3,
                limit * 1e3
            ),
            SafetyReason::JointAngle { index, value, limit } => write!(
                f,
                "joint angle q[{index}] = {value:.4e} rad is beyond the plausible +-{limit:.2} rad (safety max_joint_angle): an encoder or driver fault, not a motion; check the encoder cable and the device file's counts and offsets"
            ),
            SafetyReason::JointSpeed { index, value, limit } => write!(
                f,
                "joint q[{index}] moved at {value:.4e} rad/s between two readings, faster than the plausible {limit:.1} rad/s (safety max_joint_speed): an encoder glitch or a re-zeroed encoder, not a hand; check the encoder cable and restart with the handle at rest"
            ),
            SafetyReason::LimitCycle {
                saturated,
                reversals,
                motor,
                window,
            } => write!(
                f,
                "limit cycle: in the last {:.0} ms a motor sat at its torque limit in {:.0} % of the ticks and motor {motor}'s saturated torque reversed {reversals} times (an oscillation at the actuators' limit, not a push): the stability gate trusted a device inertia nobody measured (the device is likely lighter than its model); measure its effective inertia (`haptic2d device identify --write` on a 2DIY, docs/HARDWARE.md \"Identify your device\"), re-check with `haptic2d stability`, or use gentler controller gains",
                window * 1e3,
                saturated * 100.0
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
    /// see [`HapticSystem::tick_elapsed`](super::HapticSystem::tick_elapsed)), and longer than
    /// [`Self::min_stall_time`]. Default 5.
    pub max_stall_periods: f64,
    /// The shortest interval between two ticks that counts as a stall, whatever the period (s):
    /// the stall limit is `max(max_stall_periods·T, min_stall_time)` ([`Self::stall_limit`]).
    /// Default 0.02 s. Why: a handle left with the last torque `τ_max` moves `½·(F/m)·t²`; for a
    /// 2DIY (`F ≈ τ_max/l1` = 0.123/0.07 = 1.76 N on `m ≈ 0.035` kg) that is 10 mm in 20 ms, the
    /// workspace trip distance, so a 20 ms stall cannot take a free handle further than the bound
    /// allows, while 5 ms at 1 kHz tripped within 1–2 s on a loaded 2-core machine with nothing
    /// wrong (issue 34 finding 10). 0 = the periods alone.
    pub min_stall_time: f64,
    /// Plausibility bound on every joint angle `|q_i|` (rad): a reading beyond it trips
    /// ([`SafetyReason::JointAngle`]). Default 4π (two turns: no linkage joint turns that far from
    /// its assembly pose, whatever the encoder offsets).
    pub max_joint_angle: f64,
    /// Plausibility bound on every joint speed `|q_i,k − q_i,k−1| / Δt` (rad/s) between two
    /// readings: faster trips ([`SafetyReason::JointSpeed`]). Default 1000 rad/s, a jump of more
    /// than 1 rad in one 1 ms tick (70 m/s at the end of a 2DIY's 70 mm link; a fast flick of the
    /// hand is 1 m/s, 14 rad/s): far enough above any hand that the timing of a loaded machine (the
    /// host measures 1 ms while the board's clock advanced several) cannot reach it — 158 rad/s was
    /// seen against the emulator at a load average of 10 — and still a garbage reading or a
    /// re-zeroed encoder.
    pub max_joint_speed: f64,
    /// Window of the limit-cycle check (s; 0 = off). Default 0.2 s. See
    /// [`LimitCycleMonitor`](super::limit_cycle::LimitCycleMonitor) for the derivation.
    pub limit_cycle_window: f64,
    /// Trip when, within one window, a motor is at its torque limit in at least this fraction of
    /// the ticks (dimensionless, in (0, 1]). Default 0.5.
    pub limit_cycle_saturation: f64,
    /// … and one motor's saturated torque reversed at least this many times. Default 8 (20 Hz over
    /// the default window).
    pub limit_cycle_reversals: u32,
}

impl Default for SafetyConfig {
    fn default() -> Self {
        Self {
            torque_trip_margin: 0.05,
            ramp_time: 0.5,
            max_stall_periods: 5.0,
            min_stall_time: 0.02,
            max_joint_angle: 4.0 * std::f64::consts::PI,
            max_joint_speed: 1000.0,
            limit_cycle_window: 0.2,
            limit_cycle_saturation: 0.5,
            limit_cycle_reversals: 8,
        }
    }
}

impl SafetyConfig {
    /// The stall limit at period `dt` (s): `max(max_stall_periods·T, min_stall_time)`.
    pub fn stall_limit(&self, dt: f64) -> f64 {
        (self.max_stall_periods * dt).max(self.min_stall_time)
    }

    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("torque_trip_margin", self.torque_trip_margin),
            ("ramp_time", self.ramp_time),
            ("min_stall_time", self.min_stall_time),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!(
                    "safety.{name} must be a finite number >= 0 (got {v})"
                ));
            }
        }
        for (name, v) in [
            ("max_joint_angle", self.max_joint_angle),
            ("max_joint_speed", self.max_joint_speed),
        ] {
            if v.is_nan() || v <= 0.0 {
                return Err(format!(
                    "safety.{name} must be a number > 0 (got {v}; inf = off)"
                ));
            }
        }
        if !(self.limit_cycle_window.is_finite() && self.limit_cycle_window >= 0.0) {
            return Err(format!(
                "safety.limit_cycle_window must be a finite number >= 0 s (got {}; 0 = off, default 0.2)",
                self.limit_cycle_window
            ));
        }
        if !(self.limit_cycle_saturation > 0.0 && self.limit_cycle_saturation <= 1.0) {
            return Err(format!(
                "safety.limit_cycle_saturation must be in (0, 1] (got {}; default 0.5)",
                self.limit_cycle_saturation
            ));
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

    /// The stall check shared by every system: a tick `elapsed` s after the previous one (of which
    /// `device_wait` s, NaN if unknown, waiting for the device) trips when it exceeds `limit` (s);
    /// a NaN interval counts as a stall (a broken clock must not pass). Only after a first tick
    /// (`started`). Returns true when it tripped.
    #[inline]
    pub fn check_stall(
        &mut self,
        tick: u64,
        t: f64,
        started: bool,
        elapsed: f64,
        device_wait: f64,
        limit: f64,
    ) -> bool {
        let stalled = started && (elapsed.is_nan() || elapsed > limit);
        if stalled {
            self.trip(
                tick,
                t,
                SafetyReason::Stall {
                    elapsed,
                    limit,
                    device_wait,
                },
            );
        }
        stalled
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
