//! The named steps of one haptic tick ([`HapticSystem::tick_timed`] calls them in order; the
//! numbers are DESIGN §1's). Each step reads and writes the system's state; none allocates, locks,
//! prints or does I/O.

use super::HapticSystem;
use crate::control::four_channel::TeleopSignals;
use crate::control::passivity::explicit_damping_limit;
use crate::device::linalg::{M3, V3, V4};
use crate::device::{CartesianDevice, DeviceEstimate, DeviceFault};
use crate::geom::Vec2;
use crate::haptic::record::{
    TickRecord, FLAG_NEAR_SINGULAR, FLAG_PASSIVITY_ACTIVE, FLAG_SAFETY, FLAG_SATURATED,
};
use crate::haptic::safety::SafetyReason;

/// The slave body as the contact stage left it: pose and twist in world coordinates and the
/// contact wrench it exerts on the world (`f_e`, N and N·m).
#[derive(Clone, Copy, Debug)]
pub(super) struct SlaveState {
    pub x_s: V3,
    pub v_s: V3,
    pub f_e: V3,
}

/// The device port after the passivity controller: the wrench it asks of the device (handle
/// coordinates), the observer's energy (J) and the damping per axis (N·s/m, N·m·s/rad).
#[derive(Clone, Copy, Debug)]
pub(super) struct PortOutput {
    pub f_port: V3,
    pub po_energy: f64,
    pub alpha: V3,
}

/// The motor stage's result: the torques to write (N·m), whether the final gate zeroed them, and
/// the fraction of the port's wrench the motors actually produced (saturation × ramp × clamp).
#[derive(Clone, Copy, Debug)]
pub(super) struct MotorOutput {
    pub tau: V4,
    pub gated: bool,
    pub applied: f64,
}

impl HapticSystem {
    /// Step 0. Stall: the device held the previous torques for `elapsed` seconds, unsupervised.
    /// Plausibility: a joint reading no hand can produce is a fault of the encoder or driver.
    pub(super) fn supervise_input(&mut self, q: &V4, elapsed: f64, device_wait: f64) {
        let at = (self.world.tick(), self.world.time());
        self.safety.supervise_input(at, q, elapsed, device_wait);
    }

    /// Steps 1–2. Device pose by forward kinematics (θ unwrapped, closure monitor), filtered
    /// twist, and the hand-wrench estimate from the torques of the previous interval (§10.3,
    /// §10.6, §10.7), both over the measured interval. A fault trips the latch; the flag says
    /// whether it was the closure monitor.
    pub(super) fn sense(&mut self, q: &V4, elapsed: f64) -> (Option<DeviceEstimate>, bool) {
        let at = (self.world.tick(), self.world.time());
        match self.device.sense(q, &self.tau_prev, elapsed) {
            Ok(e) => (Some(e), false),
            Err(fault) => {
                let closure = matches!(fault, DeviceFault::ClosureViolation { .. });
                self.safety.trip(at, SafetyReason::Device(fault));
                (None, closure)
            }
        }
    }

    /// Step 1b. Start-up alignment, at the first valid reading (and after a re-arm or a pause):
    /// anchor the mapping so that the measured handle pose maps onto the slave's current pose. The
    /// coupling then starts with zero pose error wherever the handle was, and the slave is not
    /// moved (moving it could put it inside a wall). The torque ramp restarts here.
    pub(super) fn align(&mut self, est: Option<DeviceEstimate>) {
        if let (Some(e), false) = (est, self.aligned) {
            let body = &self.world.bodies[self.slave];
            self.map.device_origin = e.pose;
            self.map.world_origin = [body.pose.pos.x, body.pose.pos.y, body.pose.angle];
            self.aligned = true;
            self.safety.restart_ramp();
        }
    }

    /// Steps 3–6. World: proximity every N_g samples, local contacts and god-objects, contact
    /// states and simultaneous impacts (velocities jump now), then normal and friction forces.
    /// Returns the slave as the controller sees it.
    pub(super) fn contact_stage(&mut self) -> SlaveState {
        self.world.begin_step();
        self.slave_state()
    }

    /// The slave body as the world holds it now: pose, twist and the contact wrench it exerts.
    pub(super) fn slave_state(&self) -> SlaveState {
        let body = &self.world.bodies[self.slave];
        let cw = self.world.contact_wrench(self.slave);
        SlaveState {
            x_s: [body.pose.pos.x, body.pose.pos.y, body.pose.angle],
            v_s: [body.vel.x, body.vel.y, body.omega],
            f_e: [-cw.force.x, -cw.force.y, -cw.torque],
        }
    }

    /// Step 7. Teleoperation: device command `f_cm` and slave drive `f_cs` (§11), in world
    /// coordinates; both zero without a reading or while latched. The master-mass feed-forward
    /// (off by default) gets the device's mass matrix at the measured pose, in world coordinates:
    /// with the twist map `v_w = S·v_d` and the wrench map `f_d = S·f_w` (`S = diag(s, s, 1)`),
    /// `f_d = M_d·a_d` gives `f_w = S⁻¹·M_d·S⁻¹·a_w`.
    pub(super) fn teleoperate(
        &mut self,
        est: Option<DeviceEstimate>,
        slave: &SlaveState,
        m_dev: &M3,
    ) -> (V3, V3) {
        let Some(e) = est else {
            return ([0.0; 3], [0.0; 3]);
        };
        if self.safety.is_latched() {
            return ([0.0; 3], [0.0; 3]);
        }
        let sc = [self.map.scale, self.map.scale, 1.0];
        let master_mass: M3 =
            std::array::from_fn(|i| std::array::from_fn(|j| m_dev[i][j] / (sc[i] * sc[j])));
        let signals = TeleopSignals {
            x_m: self.map.pose_to_world(&e.pose),
            v_m: self.map.twist_to_world(&e.velocity),
            f_h: self.map.wrench_to_world(&std::array::from_fn(|i| {
                e.hand_wrench[i] + self.hand_injection[i]
            })),
            x_s: slave.x_s,
            v_s: slave.v_s,
            f_e: slave.f_e,
            master_mass,
        };
        self.controller.step(&signals)
    }

    /// Step 8. Passivity observer/controller on the device port (§12), in handle coordinates, with
    /// α per axis capped at the explicit-damping limit `2·M_ii/T` of the device's inertia on that
    /// axis. It stops (α = 0, nothing booked but the zero applied) while latched.
    pub(super) fn port_passivity(
        &mut self,
        est: Option<DeviceEstimate>,
        f_cm: &V3,
        m_dev: &M3,
        flags: &mut u32,
    ) -> PortOutput {
        let mut out = PortOutput {
            f_port: self.map.wrench_to_device(f_cm),
            po_energy: 0.0,
            alpha: [0.0; 3],
        };
        let (dt, latched) = (self.dt, self.safety.is_latched());
        if let Some(pc) = self.passivity.as_mut() {
            match (est, latched) {
                (Some(e), false) => {
                    let cap = std::array::from_fn(|i| explicit_damping_limit(m_dev[i][i], dt));
                    out.f_port = pc.update_limited(e.pose, e.velocity, out.f_port, dt, cap);
                    out.alpha = [pc.x.alpha(), pc.y.alpha(), pc.theta.alpha()];
                    if out.alpha.iter().any(|a| *a > 0.0) {
                        *flags |= FLAG_PASSIVITY_ACTIVE;
                    }
                }
                _ => pc.idle(),
            }
            out.po_energy = pc.e_obs();
        }
        out
    }

    /// Step 8b. Workspace bound (device file): a passive wall just past the edge of the workspace
    /// square, and a trip beyond it. Returns the wrench for the motors (handle coordinates).
    pub(super) fn workspace_wall(&mut self, est: Option<DeviceEstimate>, f_port: V3) -> V3 {
        let at = (self.world.tick(), self.world.time());
        let mut f_dev = f_port;
        if let Some(e) = est {
            self.safety
                .workspace_wall(at, &e.pose, &e.velocity, &mut f_dev);
        }
        f_dev
    }

    /// Step 9. Redundancy resolution to four motor torques, saturation (§10.5), the limit-cycle
    /// monitor, the start-up ramp, and the final gate: a fault, a non-finite value, a singular pose
    /// or a request above τ_max by more than the margin zeroes the torques in this same tick; a
    /// request just above τ_max is clamped to it.
    pub(super) fn motor_torques(&mut self, f_dev: &V3, flags: &mut u32) -> MotorOutput {
        let at = (self.world.tick(), self.world.time());
        let mut tau = [0.0; 4];
        let mut wrench_scale = 0.0;
        if !self.safety.is_latched() {
            match self.device.wrench_to_torques(f_dev, self.preload) {
                Ok(cmd) => {
                    tau = cmd.tau;
                    wrench_scale = cmd.wrench_scale;
                    if cmd.saturated {
                        *flags |= FLAG_SATURATED;
                    }
                    let tau_max = self.device.tau_max();
                    self.safety.observe_limit_cycle(at, &cmd.tau, &tau_max);
                    if cmd.near_singular {
                        *flags |= FLAG_NEAR_SINGULAR;
                        let limit = self.safety.latch().min_margin;
                        self.safety.trip(
                            at,
                            SafetyReason::Singularity {
                                margin: cmd.margin,
                                limit,
                            },
                        );
                    }
                }
                Err(fault) => self.safety.trip(at, SafetyReason::Torques(fault)),
            }
        }
        let ramp = self.safety.ramp();
        tau.iter_mut().for_each(|v| *v *= ramp);
        if let Some((i, v)) = self.injected.take() {
            tau[i] = v;
        }
        let peak_before = tau.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let gated = self.safety.gate(at, &mut tau, self.aligned);
        let peak_after = tau.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if gated {
            *flags |= FLAG_SAFETY;
        }
        let applied = if gated || peak_before == 0.0 {
            0.0
        } else {
            wrench_scale * ramp * (peak_after / peak_before)
        };
        MotorOutput {
            tau,
            gated,
            applied,
        }
    }

    /// Step 9b. The passivity observer books the wrench the port actually produced: the
    /// controller's output scaled by the saturation, the ramp and the final clamp (zero when gated).
    pub(super) fn book_port(&mut self, f_port: &V3, applied: f64) {
        if let Some(pc) = self.passivity.as_mut() {
            pc.book_applied([
                applied * f_port[0],
                applied * f_port[1],
                applied * f_port[2],
            ]);
        }
    }

    /// Step 10. Slave drive `f_cs` held over the sample, then passive integration of every body
    /// to k+1 (§6); the torques `tau` are the next tick's "previous interval" for the observer.
    pub(super) fn integrate(&mut self, f_cs: &V3, tau: V4) {
        self.world
            .set_drive(self.slave, Vec2::new(f_cs[0], f_cs[1]), f_cs[2]);
        self.world.finish_step();
        self.tau_prev = tau;
    }

    /// Step 11. Log: signals, energies and the contact count into the tick record; `t` (s) is the
    /// tick's start time.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn record_tick(
        &mut self,
        t: f64,
        est: Option<DeviceEstimate>,
        slave: &SlaveState,
        (f_cm, f_cs): (V3, V3),
        port: &PortOutput,
        tau: V4,
        flags: u32,
    ) {
        let ledger = self.world.ledger();
        let (x_m, v_m, w_h) = est.map_or(([0.0; 3], [0.0; 3], [0.0; 3]), |e| {
            (e.pose, e.velocity, e.hand_wrench)
        });
        self.record = TickRecord {
            t,
            x_m,
            v_m,
            w_h,
            x_s: slave.x_s,
            v_s: slave.v_s,
            f_cm,
            f_cs,
            f_e: slave.f_e,
            tau,
            contacts: self.world.contacts().contact_count() as u32,
            kinetic: ledger.kinetic,
            stored: ledger.stored,
            applied_work: ledger.applied_work,
            po_energy: port.po_energy,
            alpha: port.alpha,
            margin: self.device.margin(),
            closure_error: est.map_or(f64::NAN, |e| e.closure_error),
            flags,
        };
    }
}
