//! The safety watchdog of the haptic loop (DESIGN §7).
//!
//! Called once per tick, after the torques are computed and before they are
//! written. It checks the tick's safety inputs; on the first fault it
//! **latches**, zeroes the torques **in the same tick**, and keeps zeroing
//! them on every later tick until [`Watchdog::reset`] (an explicit user
//! action). The [`Fault`] says what happened, when, and with which value.
//!
//! Faults, checked in this order (the first one found is reported):
//!
//! 1. the device reported itself lost;
//! 2. a non-finite torque, pose component or extra monitored value;
//! 3. a kinematic closure fault (MODELS §10.3: `| |P₂ − P₁| − r_c | ≥ 1e-3 m`);
//! 4. singularity margin below the limit (MODELS §10.4: 0.1);
//! 5. a stall: this tick came more than `max_stall_periods` periods after the previous one (the
//!    device held its last torques, unsupervised, for that long) — one such tick is enough;
//! 6. `N` consecutive ticks that missed their deadline.
//!
//! [`TickInterval`](crate::runner::TickInterval) measures the time between ticks for item 5.

use std::fmt;

/// Watchdog thresholds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WatchdogConfig {
    /// Fault when the singularity margin (dimensionless `|sin|`, MODELS
    /// §10.4) falls below this. Default 0.1. Set 0 to disable.
    pub min_singularity_margin: f64,
    /// Fault after this many consecutive ticks that missed their deadline;
    /// `None` disables the check. Default `Some(10)` (10 ms at 1 kHz).
    pub max_missed_run: Option<u32>,
    /// Fault on a single tick that comes more than this many periods after the previous one
    /// ([`SafetyInput::elapsed_periods`]); `None` disables the check. Default `Some(5.0)` (5 ms at
    /// 1 kHz): a few periods, so that ordinary scheduling jitter passes and a stall does not.
    pub max_stall_periods: Option<f64>,
}

impl Default for WatchdogConfig {
    fn default() -> Self {
        Self {
            min_singularity_margin: 0.1,
            max_missed_run: Some(10),
            max_stall_periods: Some(5.0),
        }
    }
}

impl WatchdogConfig {
    /// Checks the thresholds; errors name the parameter.
    pub fn validate(&self) -> Result<(), String> {
        if !self.min_singularity_margin.is_finite() || self.min_singularity_margin < 0.0 {
            return Err(format!(
                "min_singularity_margin = {}: must be a number ≥ 0 (default 0.1)",
                self.min_singularity_margin
            ));
        }
        if let Some(p) = self.max_stall_periods {
            if !(p.is_finite() && p >= 1.0) {
                return Err(format!(
                    "max_stall_periods = {p}: must be a number ≥ 1 (periods; default 5), or none to disable the check"
                ));
            }
        }
        if self.max_missed_run == Some(0) {
            return Err("max_missed_run = 0: must be ≥ 1, or none to disable the check".into());
        }
        Ok(())
    }
}

/// What the watchdog looks at in one tick (besides the torques).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SafetyInput<'a> {
    /// Tick index, for the fault report.
    pub tick: u64,
    /// Handle pose `(x, y, θ)`, m, m, rad.
    pub pose: [f64; 3],
    /// True when the kinematic consistency monitor (MODELS §10.3) failed.
    pub closure_fault: bool,
    /// Singularity margin (MODELS §10.4), dimensionless in [0, 1].
    pub singularity_margin: f64,
    /// True when this tick missed its deadline (deadlines were skipped before
    /// it, or it started more than a period late; see
    /// [`TickInfo::missed_deadline`](crate::runner::TickInfo::missed_deadline)).
    pub deadline_missed: bool,
    /// Time since the previous tick started, in periods (1 = on time; see
    /// [`TickInterval`](crate::runner::TickInterval)). A non-finite value counts as a stall.
    pub elapsed_periods: f64,
    /// True when device I/O reported the device lost.
    pub device_lost: bool,
    /// Any other values that must be finite (velocities, wrenches, …).
    pub extra: &'a [f64],
}

impl SafetyInput<'_> {
    /// A nominal input at tick `tick`: pose at the origin, margin 1, on time, no flags.
    pub fn nominal(tick: u64) -> SafetyInput<'static> {
        SafetyInput {
            tick,
            pose: [0.0; 3],
            closure_fault: false,
            singularity_margin: 1.0,
            deadline_missed: false,
            elapsed_periods: 1.0,
            device_lost: false,
            extra: &[],
        }
    }
}

/// The cause of a watchdog trip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FaultKind {
    /// The device stopped answering.
    DeviceLost,
    /// Torque `index` (0–3) was `value` (NaN or ±∞).
    NonFiniteTorque {
        /// Motor index, 0–3.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// Pose component `index` (0 = x, 1 = y, 2 = θ) was non-finite.
    NonFinitePose {
        /// Component index.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// The singularity margin was non-finite.
    NonFiniteMargin {
        /// The offending value.
        value: f64,
    },
    /// Extra monitored value `index` was non-finite.
    NonFiniteValue {
        /// Index into [`SafetyInput::extra`].
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// The two pantograph endpoints disagree with the crank radius.
    ClosureFault,
    /// The singularity margin fell below the limit.
    Singularity {
        /// Margin measured.
        margin: f64,
        /// Limit configured.
        limit: f64,
    },
    /// One tick came too long after the previous one.
    Stall {
        /// Time since the previous tick, in periods.
        periods: f64,
        /// Limit configured, in periods.
        limit: f64,
    },
    /// Too many consecutive ticks missed their deadline.
    MissedDeadlines {
        /// Consecutive ticks that missed.
        run: u32,
        /// Limit configured.
        limit: u32,
    },
}

/// A latched watchdog fault: its cause and the tick it happened in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fault {
    /// Tick index at which the fault was detected.
    pub tick: u64,
    /// What happened.
    pub kind: FaultKind,
}

impl Fault {
    /// The reason as one line of text (same as `Display`).
    pub fn reason(&self) -> String {
        self.to_string()
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "watchdog tripped at tick {}, torques set to zero: ",
            self.tick
        )?;
        match self.kind {
            FaultKind::DeviceLost => write!(f, "the device was lost"),
            FaultKind::NonFiniteTorque { index, value } => {
                write!(f, "non-finite torque command τ[{index}] = {value}")
            }
            FaultKind::NonFinitePose { index, value } => write!(
                f,
                "non-finite handle pose {} = {value}",
                ["x", "y", "θ"][index.min(2)]
            ),
            FaultKind::NonFiniteMargin { value } => {
                write!(f, "non-finite singularity margin {value}")
            }
            FaultKind::NonFiniteValue { index, value } => {
                write!(f, "non-finite monitored value #{index} = {value}")
            }
            FaultKind::ClosureFault => write!(
                f,
                "kinematic closure fault: the pantograph endpoints disagree with the crank radius (check encoder calibration)"
            ),
            FaultKind::Singularity { margin, limit } => write!(
                f,
                "singularity margin {margin:.3} below the limit {limit:.3} (handle near the workspace boundary)"
            ),
            FaultKind::Stall { periods, limit } => write!(
                f,
                "the loop stalled: this tick came {periods:.1} periods after the previous one on the host's own account (limit {limit:.1}; the wait for the device is not counted): the host was late, not the device, and the device held its torques unsupervised. Without real-time priority (see the summary's `real-time:` line) the machine is overloaded: run as root or raise the rtprio limit (`ulimit -r 80`), close other programs or lower --rate. With it, something stopped the loop thread: a debugger or SIGSTOP, a higher-priority real-time task, or a virtual machine whose CPU its host took away (a SCHED_FIFO thread on this project's loaded 2-core VM woke up to 9 ms late). Raise max_stall_periods in the device file only for a device that is safe to leave holding its torque that long"
            ),
            FaultKind::MissedDeadlines { run, limit } => write!(
                f,
                "{run} consecutive ticks missed their deadline (limit {limit}); the machine is too loaded for this rate"
            ),
        }
    }
}

/// The latching safety watchdog.
#[derive(Debug, Clone)]
pub struct Watchdog {
    config: WatchdogConfig,
    latched: Option<Fault>,
    missed_run: u32,
}

impl Watchdog {
    /// A watchdog with thresholds `config` (validated).
    pub fn new(config: WatchdogConfig) -> Result<Self, String> {
        config.validate()?;
        Ok(Self {
            config,
            latched: None,
            missed_run: 0,
        })
    }

    /// Checks this tick. If the watchdog is (or becomes) latched, sets
    /// `torques` to zero and returns the fault; otherwise leaves them alone.
    /// Never allocates.
    #[inline]
    pub fn guard(&mut self, input: &SafetyInput, torques: &mut [f64; 4]) -> Result<(), Fault> {
        let res = self.check(input, torques);
        if res.is_err() {
            *torques = [0.0; 4];
        }
        res
    }

    /// Checks this tick without touching the torques: `Err` (the latched
    /// fault) means the caller must command zero torque.
    pub fn check(&mut self, input: &SafetyInput, torques: &[f64; 4]) -> Result<(), Fault> {
        if let Some(f) = self.latched {
            return Err(f);
        }
        self.missed_run = if input.deadline_missed {
            self.missed_run.saturating_add(1)
        } else {
            0
        };
        match self.detect(input, torques) {
            None => Ok(()),
            Some(kind) => {
                let fault = Fault {
                    tick: input.tick,
                    kind,
                };
                self.latched = Some(fault);
                Err(fault)
            }
        }
    }

    /// The first fault condition present in this tick, if any.
    fn detect(&self, input: &SafetyInput, torques: &[f64; 4]) -> Option<FaultKind> {
        if input.device_lost {
            return Some(FaultKind::DeviceLost);
        }
        if let Some((index, &value)) = torques.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Some(FaultKind::NonFiniteTorque { index, value });
        }
        if let Some((index, &value)) = input.pose.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Some(FaultKind::NonFinitePose { index, value });
        }
        if !input.singularity_margin.is_finite() {
            return Some(FaultKind::NonFiniteMargin {
                value: input.singularity_margin,
            });
        }
        if let Some((index, &value)) = input.extra.iter().enumerate().find(|(_, v)| !v.is_finite())
        {
            return Some(FaultKind::NonFiniteValue { index, value });
        }
        if input.closure_fault {
            return Some(FaultKind::ClosureFault);
        }
        if input.singularity_margin < self.config.min_singularity_margin {
            return Some(FaultKind::Singularity {
                margin: input.singularity_margin,
                limit: self.config.min_singularity_margin,
            });
        }
        if let Some(limit) = self.config.max_stall_periods {
            // (NaN is a stall: a broken clock must not pass.)
            let p = input.elapsed_periods;
            if p.is_nan() || p > limit {
                return Some(FaultKind::Stall { periods: p, limit });
            }
        }
        if let Some(limit) = self.config.max_missed_run {
            if self.missed_run >= limit {
                return Some(FaultKind::MissedDeadlines {
                    run: self.missed_run,
                    limit,
                });
            }
        }
        None
    }

    /// The latched fault, if any.
    pub fn fault(&self) -> Option<Fault> {
        self.latched
    }

    /// True once a fault has latched.
    pub fn is_latched(&self) -> bool {
        self.latched.is_some()
    }

    /// Re-arms the watchdog after the user has dealt with the fault.
    pub fn reset(&mut self) {
        self.latched = None;
        self.missed_run = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 39 item 4: a stall of the loop's own time says the host was late, not the device, and
    /// what to do with and without real-time priority.
    #[test]
    fn a_stall_message_says_the_host_was_late_and_what_to_do_with_and_without_real_time() {
        let mut dog = Watchdog::new(WatchdogConfig::default()).unwrap();
        let mut tau = [0.1; 4];
        let input = SafetyInput {
            elapsed_periods: 101.8,
            ..SafetyInput::nominal(7)
        };
        let f = dog.guard(&input, &mut tau).unwrap_err();
        assert_eq!(tau, [0.0; 4]);
        let m = f.to_string();
        assert!(
            m.contains("101.8 periods") && m.contains("the host was late, not the device"),
            "{m}"
        );
        assert!(
            m.contains("ulimit -r 80") && m.contains("virtual machine"),
            "{m}"
        );
    }
}
