//! The named steps of one tick of the 2-DOF system ([`Planar2System::tick_timed`] calls them in
//! order; the numbers are DESIGN §1's, as in the twin's `system/steps.rs`). None allocates, locks,
//! prints or does I/O.

use super::Planar2System;
use crate::control::four_channel::TeleopSignals;
use crate::device::linalg::V3;
use crate::device::{CartesianDevice, DeviceEstimate};
use crate::geom::{cross, Vec2};
use crate::haptic::record::{TickRecord, FLAG_NEAR_SINGULAR, FLAG_SAFETY, FLAG_SATURATED};
use crate::haptic::safety::SafetyReason;

/// The handle as sensed this tick: the device's estimate (device frame; `None` after a fault), its
/// singularity margin (NaN without a reading), the handle pose and twist in world coordinates (m,
/// rad; m/s, rad/s; the rotation entries are filled from the slave).
#[derive(Clone, Copy, Debug)]
pub(super) struct Handle {
    pub est: Option<DeviceEstimate>,
    pub margin: f64,
    pub x_m: V3,
    pub v_m: V3,
}

/// The slave after the contact stage: centre `c` (m), angle (rad), angular velocity (rad/s), the
/// grasp offset `r` (m, world frame), the grasp point's position and velocity, and the contact
/// wrench on the slave (N, N·m).
#[derive(Clone, Copy, Debug)]
pub(super) struct Slave2 {
    pub c: Vec2,
    pub theta: f64,
    pub omega: f64,
    pub r: Vec2,
    pub pg: Vec2,
    pub vg: Vec2,
    pub f_e: V3,
}

impl Planar2System {
    /// Step 0. Stall and joint plausibility: the shared safety layer, as in `HapticSystem`.
    pub(super) fn supervise_input(&mut self, q: &[f64; 2], elapsed: f64, device_wait: f64) {
        let at = (self.world.tick(), self.world.time());
        self.safety.supervise_input(at, q, elapsed, device_wait);
    }

    /// Steps 1–2. The device's handle point and filtered velocity over `elapsed` (s), its
    /// singularity margin, and the device → world translation (anchored at the first valid
    /// reading). A fault or a singular pose trips.
    pub(super) fn sense(&mut self, q: &[f64; 2], elapsed: f64, flags: &mut u32) -> Handle {
        let at = (self.world.tick(), self.world.time());
        let est = match self.device.sense(q, &[0.0; 4], elapsed) {
            Ok(e) => Some(e),
            Err(f) => {
                self.safety.trip(at, SafetyReason::Device(f));
                None
            }
        };
        let mut h = Handle {
            est,
            margin: self.device.margin(),
            x_m: [f64::NAN; 3],
            v_m: [0.0; 3],
        };
        if let Some(e) = est {
            let point = Vec2::new(e.pose[0], e.pose[1]);
            let origin = *self.device_origin.get_or_insert(point);
            let p = point - origin + self.world_origin;
            h.x_m = [p.x, p.y, 0.0];
            h.v_m = [e.velocity[0], e.velocity[1], 0.0];
            if h.margin < self.config.min_singularity_margin {
                *flags |= FLAG_NEAR_SINGULAR;
                self.safety.trip(
                    at,
                    SafetyReason::Singularity {
                        margin: h.margin,
                        limit: self.config.min_singularity_margin,
                    },
                );
            }
        }
        h
    }

    /// Steps 3–6. World contacts; the slave's state at the grasp point.
    pub(super) fn contact_stage(&mut self) -> Slave2 {
        self.world.begin_step();
        let body = &self.world.bodies[self.slave];
        let (c, theta, omega) = (body.pose.pos, body.pose.angle, body.omega);
        let r = super::rotate(theta, self.config.grasp);
        let cw = self.world.contact_wrench(self.slave);
        Slave2 {
            c,
            theta,
            omega,
            r,
            pg: c + r,
            vg: body.vel + omega * crate::geom::perp(r),
            f_e: [-cw.force.x, -cw.force.y, -cw.torque],
        }
    }

    /// Step 7. The controller on x and y (the θ channel sees no error: the rotation is left to the
    /// world); both commands zero without a reading or while latched.
    pub(super) fn teleoperate(&mut self, h: &Handle, s: &Slave2) -> (V3, V3) {
        if h.est.is_none() || self.safety.is_latched() {
            return ([0.0; 3], [0.0; 3]);
        }
        let signals = TeleopSignals {
            x_m: h.x_m,
            v_m: h.v_m,
            f_h: [0.0; 3],
            x_s: [s.pg.x, s.pg.y, s.theta],
            v_s: [s.vg.x, s.vg.y, s.omega],
            f_e: [s.f_e[0], s.f_e[1], 0.0],
            master_mass: self.device.mass_matrix(),
        };
        let (mut f_cm, mut f_cs) = self.controller.step(&signals);
        f_cm[2] = 0.0;
        f_cs[2] = 0.0;
        (f_cm, f_cs)
    }

    /// Step 8b. The device file's workspace bound at the handle point (device frame; the device →
    /// world map is a translation, so velocity and force are the same in both).
    pub(super) fn workspace_wall(&mut self, h: &Handle, f_cm: &mut V3) {
        let at = (self.world.tick(), self.world.time());
        if let Some(e) = h.est {
            self.safety.workspace_wall(at, &e.pose, &h.v_m, f_cm);
            f_cm[2] = 0.0;
        }
    }

    /// Step 9. The device's `τ = Jᵀ·f_cm` with direction-preserving saturation, the limit-cycle
    /// monitor, the start-up ramp and the safety gate. Returns the four torques (N·m; the last two
    /// always 0) and whether the gate zeroed them.
    pub(super) fn motor_torques(
        &mut self,
        h: &Handle,
        f_cm: &V3,
        flags: &mut u32,
    ) -> ([f64; 4], bool) {
        let at = (self.world.tick(), self.world.time());
        let mut tau4 = [0.0; 4];
        if let (Some(_), false) = (h.est, self.safety.is_latched()) {
            match self.device.wrench_to_torques(f_cm, 0.0) {
                Ok(cmd) => {
                    if cmd.saturated {
                        *flags |= FLAG_SATURATED;
                    }
                    let tau_max = self.device.tau_max();
                    self.safety.observe_limit_cycle(at, &cmd.tau, &tau_max);
                    let ramp = self.safety.ramp();
                    tau4[0] = cmd.tau[0] * ramp;
                    tau4[1] = cmd.tau[1] * ramp;
                }
                Err(fault) => self.safety.trip(at, SafetyReason::Torques(fault)),
            }
        }
        let gated = self.safety.gate(at, &mut tau4, h.est.is_some());
        if gated {
            *flags |= FLAG_SAFETY;
        }
        (tau4, gated)
    }

    /// Step 10. The slave drive at the grasp point (plus the twist target's torsion
    /// spring-damper, world side only), then the integration of every body.
    pub(super) fn integrate(&mut self, f_cs: &V3, s: &Slave2) {
        let f = Vec2::new(f_cs[0], f_cs[1]);
        let twist = match self.twist_target {
            Some(th) if !self.safety.is_latched() => {
                let (k, b) = self.twist_gains;
                k * (th - s.theta) - b * s.omega
            }
            _ => 0.0,
        };
        self.world.set_drive(self.slave, f, cross(s.r, f) + twist);
        self.world.finish_step();
    }

    /// Step 11. The tick record; `t` (s) is the tick's start time.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn record_tick(
        &mut self,
        t: f64,
        h: &Handle,
        s: &Slave2,
        (f_cm, f_cs): (V3, V3),
        tau4: [f64; 4],
        flags: u32,
    ) {
        let body = &self.world.bodies[self.slave];
        let ledger = self.world.ledger();
        self.record = TickRecord {
            t,
            x_m: h.x_m,
            v_m: h.v_m,
            w_h: [0.0; 3],
            x_s: [s.c.x, s.c.y, s.theta],
            v_s: [body.vel.x, body.vel.y, body.omega],
            f_cm,
            f_cs,
            f_e: s.f_e,
            tau: tau4,
            contacts: self.world.contacts().contact_count() as u32,
            kinetic: ledger.kinetic,
            stored: ledger.stored,
            applied_work: ledger.applied_work,
            po_energy: 0.0,
            alpha: [0.0; 3],
            margin: h.margin,
            closure_error: 0.0,
            flags,
        };
    }
}
