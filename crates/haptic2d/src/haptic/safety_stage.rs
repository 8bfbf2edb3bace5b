//! [`SafetyStage`]: the tick's safety code, written once for every device (DESIGN §7). The one tick,
//! [`Haptic::haptic_tick`](super::Haptic::haptic_tick) — run by the twin pantograph's
//! [`HapticSystem`](super::HapticSystem), the 2-DOF
//! [`Planar2System`](super::planar2::Planar2System) (a 2DIY, a UDP five-bar) and the
//! [`PointSystem`](super::PointSystem) (the Inverse3) alike —
//! owns one and calls it at these points of §0.5:
//!
//! ```text
//! 0.  supervise_input     stall (the device held its torques unsupervised), joint plausibility
//! 8b. workspace_wall      the device file's square: a passive wall past the edge, a trip beyond it
//! 9.  observe_limit_cycle a saturated torque that keeps reversing trips
//! 9.  ramp                start-up ramp factor min(1, n/N) since the alignment
//! 9.  gate                final gate (non-finite, above τ_max·(1 + margin) → trip; above τ_max →
//!                         clamp; latched → zero), and the ramp's clock
//! ```
//!
//! The stage holds the latch ([`Safety`]), the settings ([`SafetyConfig`]), the plausibility and
//! limit-cycle monitors, the workspace bound and the ramp's and stall's clocks. None of its methods
//! allocates, locks, prints or does I/O; each takes the tick index and time `(k, t)` (s) it latches
//! a trip at.

use crate::device::linalg::V3;

use super::limit_cycle::LimitCycleMonitor;
use super::plausibility::JointPlausibility;
use super::safety::{Safety, SafetyConfig, SafetyReason, SafetyTrip};
use super::workspace::WorkspaceBound;

/// A tick's place in time: index `k` and time `k·T` (s), the stamp of a trip.
pub type TickClock = (u64, f64);

/// The safety steps of one tick (see the module doc), shared by every device's system.
#[derive(Clone, Debug)]
pub struct SafetyStage {
    latch: Safety,
    config: SafetyConfig,
    plausibility: JointPlausibility,
    limit_cycle: LimitCycleMonitor,
    workspace: WorkspaceBound,
    /// The stall limit `max(max_stall_periods·T, min_stall_time)` (s).
    stall_limit: f64,
    /// Ticks since the alignment (the ramp's clock).
    ramp_ticks: u64,
    /// Ticks of the ramp, `round(ramp_time / T)` (0 = no ramp).
    ramp_len: u64,
    /// True once a tick has read the device (the stall check needs a previous tick).
    started: bool,
}

impl SafetyStage {
    /// The stage for settings `config` (validated by the caller), latch `latch` (singularity margin,
    /// `τ_max` and trip margin of the final gate) and the device's workspace bound `workspace`, at
    /// period `dt` (s).
    pub fn new(config: SafetyConfig, latch: Safety, workspace: WorkspaceBound, dt: f64) -> Self {
        Self {
            latch,
            plausibility: JointPlausibility::new(&config),
            limit_cycle: LimitCycleMonitor::new(&config, dt),
            workspace,
            stall_limit: config.stall_limit(dt),
            ramp_ticks: 0,
            ramp_len: (config.ramp_time / dt).round() as u64,
            started: false,
            config,
        }
    }

    /// Step 0, stall alone: trips ([`SafetyReason::Stall`]) when `elapsed` (s since the previous
    /// tick, of which `device_wait` s waiting for the device, NaN = unknown) exceeds the stall limit,
    /// after a first tick. Returns true when it tripped.
    #[inline]
    pub fn check_stall(&mut self, at: TickClock, elapsed: f64, device_wait: f64) -> bool {
        self.latch.check_stall(
            at.0,
            at.1,
            self.started,
            elapsed,
            device_wait,
            self.stall_limit,
        )
    }

    /// Step 0. Stall: the device held the previous torques for `elapsed` seconds, unsupervised.
    /// Plausibility: a joint reading `q` (rad) no hand can produce is a fault of the encoder or
    /// driver. Starts the stall clock.
    #[inline]
    pub fn supervise_input(&mut self, at: TickClock, q: &[f64], elapsed: f64, device_wait: f64) {
        self.check_stall(at, elapsed, device_wait);
        self.started = true;
        if let Some(reason) = self.plausibility.check(q, elapsed) {
            self.latch.trip(at.0, at.1, reason);
        }
    }

    /// Step 0 of a paused tick: the joint angles' plausibility (no interval, so no speed check); the
    /// limit-cycle window restarts (no torques while paused).
    #[inline]
    pub fn supervise_paused(&mut self, at: TickClock, q: &[f64]) {
        if let Some(reason) = self.plausibility.check_angles(q) {
            self.latch.trip(at.0, at.1, reason);
        }
        self.limit_cycle.reset();
    }

    /// Step 8b. The workspace bound at handle pose `x` (m, m, rad; device frame) and twist `v`:
    /// adds the passive wall to `f` (N, N, N·m; device frame) and trips beyond the trip distance.
    #[inline]
    pub fn workspace_wall(&mut self, at: TickClock, x: &V3, v: &V3, f: &mut V3) {
        if let Some(reason) = self.workspace.apply(x, v, f) {
            self.latch.trip(at.0, at.1, reason);
        }
    }

    /// Step 9. The limit-cycle monitor on the saturated torques `tau` (N·m) against their limits
    /// `tau_max` (N·m; 0 for an absent motor).
    #[inline]
    pub fn observe_limit_cycle(&mut self, at: TickClock, tau: &[f64; 4], tau_max: &[f64; 4]) {
        if let Some(reason) = self.limit_cycle.observe(tau, tau_max) {
            self.latch.trip(at.0, at.1, reason);
        }
    }

    /// The start-up ramp factor of this tick, `min(1, n / N)` with `n` the ticks since the alignment
    /// (exactly 0 at it), `N = round(ramp_time / T)`; 1 without a ramp.
    #[inline]
    pub fn ramp(&self) -> f64 {
        if self.ramp_len == 0 {
            1.0
        } else {
            (self.ramp_ticks as f64 / self.ramp_len as f64).min(1.0)
        }
    }

    /// Step 9, last. The final gate on `tau` (N·m, [`Safety::gate`]); when it lets the torques
    /// through and the device was read and aligned this tick (`counting`), the ramp's clock
    /// advances. Returns true when the torques were zeroed.
    #[inline]
    pub fn gate(&mut self, at: TickClock, tau: &mut [f64; 4], counting: bool) -> bool {
        let gated = self.latch.gate(at.0, at.1, tau);
        if !gated && counting {
            self.ramp_ticks = self.ramp_ticks.saturating_add(1);
        }
        gated
    }

    /// Latches `reason` at `at` (the first reason wins).
    #[inline]
    pub fn trip(&mut self, at: TickClock, reason: SafetyReason) {
        self.latch.trip(at.0, at.1, reason);
    }

    /// True once tripped.
    #[inline]
    pub fn is_latched(&self) -> bool {
        self.latch.is_latched()
    }

    /// The latched trip, if any.
    pub fn trip_info(&self) -> Option<SafetyTrip> {
        self.latch.trip_info()
    }

    /// The latch's limits: singularity margin (dimensionless), `τ_max` (N·m).
    pub fn latch(&self) -> &Safety {
        &self.latch
    }

    /// The settings (ramp, stall limit, plausibility, limit cycle).
    pub fn config(&self) -> &SafetyConfig {
        &self.config
    }

    /// The workspace bound.
    pub fn workspace(&self) -> &WorkspaceBound {
        &self.workspace
    }

    /// The alignment happened this tick: the ramp restarts from zero.
    #[inline]
    pub fn restart_ramp(&mut self) {
        self.ramp_ticks = 0;
    }

    /// The next tick is a first tick again (after a pause or a re-arm): no stall check against the
    /// time before it.
    #[inline]
    pub fn restart_clock(&mut self) {
        self.started = false;
    }

    /// Re-arms the latch (an explicit user action) and restarts the monitors; the caller re-aligns,
    /// which restarts the ramp.
    pub fn rearm(&mut self) {
        self.latch.reset();
        self.plausibility.reset();
        self.limit_cycle.reset();
    }
}
