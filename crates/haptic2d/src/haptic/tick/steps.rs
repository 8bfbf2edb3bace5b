//! The named steps of the one haptic tick ([`Haptic::haptic_tick`] calls them in order; the numbers
//! are §0.5's). Each reads and writes the system's state through the device's
//! [`DeviceCoupling`]; none allocates, locks, prints or does I/O.

use super::Haptic;
use crate::control::passivity::explicit_damping_limit;
use crate::device::linalg::{M3, V3, V4};
use crate::device::{CartesianDevice, DeviceEstimate, DeviceFault};
use crate::haptic::coupling::{DeviceCoupling, SlaveState};
use crate::haptic::record::{
    TickRecord, FLAG_NEAR_SINGULAR, FLAG_PASSIVITY_ACTIVE, FLAG_SAFETY, FLAG_SATURATED,
};
use crate::haptic::safety::SafetyReason;
use crate::haptic::safety_stage::TickClock;

/// The device port after the passivity controller: the wrench it asks of the device (device
/// frame, N, N, N·m), the observer's energy (J) and the damping per axis (N·s/m, N·m·s/rad).
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

impl<C: DeviceCoupling> Haptic<C>
where
    <C::Device as CartesianDevice>::Joints: AsRef<[f64]>,
{
    /// The tick's place in time (index, s): the stamp of a trip.
    pub(super) fn at(&self) -> TickClock {
        (self.world.tick(), self.world.time())
    }

    /// Step 0. Stall: the device held the previous torques for `elapsed` seconds, unsupervised.
    /// Plausibility: a joint reading no hand can produce is a fault of the encoder or driver.
    pub(super) fn supervise_input(
        &mut self,
        q: &<C::Device as CartesianDevice>::Joints,
        elapsed: f64,
        device_wait: f64,
    ) {
        let at = self.at();
        self.safety
            .supervise_input(at, q.as_ref(), elapsed, device_wait);
    }

    /// Steps 1–2. The device's handle pose (forward kinematics; the twin unwraps θ and runs its
    /// closure monitor), filtered twist and hand-wrench estimate from the torques of the previous
    /// interval (§10.3, §10.6, §10.7), over the measured interval. A fault trips the latch; the flag
    /// says whether it was the closure monitor.
    pub(super) fn sense(
        &mut self,
        q: &<C::Device as CartesianDevice>::Joints,
        elapsed: f64,
    ) -> (Option<DeviceEstimate>, bool) {
        let at = self.at();
        let tau_prev = self.tau_prev;
        match self.coupling.device_mut().sense(q, &tau_prev, elapsed) {
            Ok(e) => (Some(e), false),
            Err(fault) => {
                let closure = matches!(fault, DeviceFault::ClosureViolation { .. });
                self.safety.trip(at, SafetyReason::Device(fault));
                (None, closure)
            }
        }
    }

    /// Step 2b. On a device whose singularity margin is known at the reading
    /// ([`DeviceCoupling::MARGIN_AT_SENSE`], the five-bar), a margin below the latch's limit trips
    /// now, before the controller runs. The twin's margin comes with its redundancy resolution
    /// (step 9).
    pub(super) fn guard_singularity(&mut self, sensed: bool, flags: &mut u32) {
        if !(C::MARGIN_AT_SENSE && sensed) {
            return;
        }
        let margin = self.coupling.device().margin();
        let limit = self.safety.latch().min_margin;
        if margin < limit {
            *flags |= FLAG_NEAR_SINGULAR;
            let at = self.at();
            self.safety
                .trip(at, SafetyReason::Singularity { margin, limit });
        }
    }

    /// Step 1b. Start-up alignment, at the first valid reading (and after a re-arm or a pause):
    /// the coupling anchors its device → world map so that the handle lands on the slave's held
    /// point. The coupling then starts with zero pose error wherever the handle was, and the slave
    /// is not moved (moving it could put it inside a wall). The torque ramp restarts here.
    pub(super) fn align(&mut self, est: Option<DeviceEstimate>) {
        if let Some(e) = est {
            if self.coupling.align(&e, &self.world, self.slave) {
                self.safety.restart_ramp();
            }
        }
    }

    /// Steps 3–6. World: proximity every N_g samples, local contacts and god-objects, contact
    /// states and simultaneous impacts (velocities jump now), then normal and friction forces.
    /// Returns the slave as the controller sees it.
    pub(super) fn contact_stage(&mut self) -> SlaveState {
        self.world.begin_step();
        self.coupling.slave_state(&self.world, self.slave)
    }

    /// Step 7. Teleoperation: device command `f_cm` and slave drive `f_cs` (§11), in world
    /// coordinates, on the axes the device renders; both zero without a reading or while latched.
    /// `m_dev` is the device's mass matrix at the measured pose (master-mass feed-forward).
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
        let signals = self.coupling.teleop_signals(&e, slave, m_dev);
        let (mut f_cm, mut f_cs) = self.controller.step(&signals);
        self.coupling.constrain(&mut f_cm);
        self.coupling.constrain(&mut f_cs);
        (f_cm, f_cs)
    }

    /// Step 8. Passivity observer/controller on the device port (§12), in device coordinates, with
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
            f_port: self.coupling.wrench_to_device(f_cm),
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
    /// square, and a trip beyond it. Returns the wrench for the motors (device frame).
    pub(super) fn workspace_wall(&mut self, est: Option<DeviceEstimate>, f_port: V3) -> V3 {
        let at = self.at();
        let mut f_dev = f_port;
        if let Some(e) = est {
            self.safety
                .workspace_wall(at, &e.pose, &e.velocity, &mut f_dev);
        }
        f_dev
    }

    /// Step 9. The device's joint torques for the wrench (`τ = Jᵀ·f`; the twin's redundancy
    /// resolution with its preload), saturation keeping the direction (§10.5), the limit-cycle
    /// monitor, the start-up ramp, and the final gate: a fault, a non-finite value, a singular pose
    /// or a request above τ_max by more than the margin zeroes the torques in this same tick; a
    /// request just above τ_max is clamped to it. The ramp's clock advances only on a tick that
    /// read the device (`sensed`).
    pub(super) fn motor_torques(
        &mut self,
        f_dev: &V3,
        sensed: bool,
        flags: &mut u32,
    ) -> MotorOutput {
        let at = self.at();
        let mut tau = [0.0; 4];
        let mut wrench_scale = 0.0;
        if !self.safety.is_latched() {
            let device = self.coupling.device();
            match device.wrench_to_torques(f_dev, self.coupling.preload()) {
                Ok(cmd) => {
                    tau = cmd.tau;
                    wrench_scale = cmd.wrench_scale;
                    if cmd.saturated {
                        *flags |= FLAG_SATURATED;
                    }
                    let tau_max = device.tau_max();
                    self.safety.observe_limit_cycle(at, &cmd.tau, &tau_max);
                    if cmd.near_singular {
                        *flags |= FLAG_NEAR_SINGULAR;
                        let limit = self.safety.latch().min_margin;
                        let margin = cmd.margin;
                        self.safety
                            .trip(at, SafetyReason::Singularity { margin, limit });
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
        let gated = self.safety.gate(at, &mut tau, sensed);
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

    /// Step 10. Slave drive `f_cs` held over the sample at the held point (the coupling turns it
    /// into a force and a torque about the centre), then passive integration of every body to k+1
    /// (§6); the torques `tau` are the next tick's "previous interval" for the observer.
    pub(super) fn integrate(&mut self, f_cs: &V3, slave: &SlaveState, tau: V4) {
        let latched = self.safety.is_latched();
        let (force, torque) = self.coupling.drive(f_cs, slave, latched);
        self.world.set_drive(self.slave, force, torque);
        self.world.finish_step();
        self.tau_prev = tau;
    }

    /// Step 11. Log: signals, energies and the contact count into the tick record; `t` (s) is the
    /// tick's start time; `(paused, gated)` say what kind of tick it was. The coupling then writes
    /// its own conventions ([`DeviceCoupling::record`]).
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
        (paused, gated): (bool, bool),
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
            x_s: slave.centre,
            v_s: slave.centre_twist,
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
            margin: self.coupling.device().margin(),
            closure_error: est.map_or(f64::NAN, |e| e.closure_error),
            flags,
        };
        let (world, i) = (&self.world, self.slave);
        self.coupling
            .record(&mut self.record, est.as_ref(), world, i, paused, gated);
    }
}
