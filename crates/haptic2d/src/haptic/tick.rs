//! [`Haptic`]: the haptic system — a device behind its [`DeviceCoupling`], a teleoperation
//! controller, the optional passivity controller on the device port, the shared safety steps and the
//! virtual world — and **the** haptic tick, written once for every device in the order of §0.5:
//!
//! ```text
//! 0.   supervise_input     stall, joint plausibility                       (safety stage)
//! 1–2. sense               q (rad) ⇒ handle pose, twist, hand wrench        (device)
//! 2b.  guard_singularity   margin at the reading ⇒ trip (2-DOF devices)
//! 1b.  align               first reading ⇒ device → world anchor, ramp restart (coupling)
//! 3–6. contact_stage       world.begin_step ⇒ slave at its held point       (coupling)
//! 7.   teleoperate         handle, slave ⇒ f_cm (device), f_cs (slave)
//! 8.   port_passivity      f_cm ⇒ f_port (device frame), α, E_obs
//! 8b.  workspace_wall      f_port ⇒ f_dev (wall past the square, trip beyond)
//! 9.   motor_torques       f_dev ⇒ τ: Jᵀ, saturation, limit cycle, ramp, gate
//! 9b.  book_port           the wrench the motors produced ⇒ passivity observer
//! 10.  integrate           f_cs at the held point ⇒ world.finish_step
//! 11.  record_tick         ⇒ TickRecord
//! ```
//!
//! The twin pantograph's system is [`HapticSystem`](super::HapticSystem) (`Haptic<TwinCoupling>`),
//! the 2-DOF five-bar's [`Planar2System`](super::planar2::Planar2System)
//! (`Haptic<GraspCoupling>`); both run [`Haptic::haptic_tick`] and [`Haptic::haptic_tick_paused`].

use crate::control::passivity::PlanarPassivity;
use crate::device::linalg::V4;
use crate::device::{CartesianDevice, DeviceFault};
use crate::world::World;

use super::controller::Controller;
use super::coupling::{DeviceCoupling, SlaveState};
use super::record::{TickRecord, FLAG_SAFETY};
use super::safety::{SafetyConfig, SafetyReason, SafetyTrip};
use super::safety_stage::SafetyStage;
use super::workspace::WorkspaceBound;

mod steps;

use steps::PortOutput;

/// What one tick hands back to the caller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickOutput {
    /// The four motor torques to write to the amplifiers now and hold for one period (N·m); all zero
    /// when the safety latch is set; `τ[2..4]` zero on a 2-DOF device.
    pub torques: V4,
    /// True when the safety latch is set (this tick or earlier).
    pub tripped: bool,
    /// The singularity margin at the measured pose (dimensionless, §10.4, the device's own measure);
    /// 0 when the device could not be read this tick. For a watchdog downstream.
    pub margin: f64,
    /// True when the kinematic consistency (closure) monitor of §10.3 failed this tick (never on a
    /// five-bar).
    pub closure_fault: bool,
    /// The tick's telemetry record.
    pub record: TickRecord,
}

/// The haptic system over device coupling `C` (see the module doc).
///
/// Safety (DESIGN §7) is part of the system, so every device gets it: the torques are exactly zero
/// until the first valid device reading; at that reading the device → world map is anchored so
/// that the handle lands on the slave's held point (no coupling force on the first tick), and the
/// torques ramp in over [`SafetyConfig::ramp_time`]; the workspace bound of the device file is a
/// passive wall with a trip beyond it; a stall trips; the final gate clamps to `τ_max`.
#[derive(Clone, Debug)]
pub struct Haptic<C> {
    pub(super) coupling: C,
    pub(super) controller: Controller,
    pub(super) passivity: Option<PlanarPassivity>,
    pub(super) world: World,
    pub(super) slave: usize,
    /// The shared safety steps: stall, plausibility, workspace bound, limit cycle, ramp, gate.
    pub(super) safety: SafetyStage,
    pub(super) dt: f64,
    /// The torques written at the previous tick (N·m), held over the interval the observer reads.
    pub(super) tau_prev: V4,
    pub(super) injected: Option<(usize, f64)>,
    pub(super) record: TickRecord,
}

impl<C: DeviceCoupling> Haptic<C>
where
    <C::Device as CartesianDevice>::Joints: AsRef<[f64]>,
{
    /// The system's parts; the constructors of [`HapticSystem`](super::HapticSystem) and
    /// [`Planar2System`](super::planar2::Planar2System) validate them first.
    pub(super) fn assemble(
        coupling: C,
        controller: Controller,
        passivity: Option<PlanarPassivity>,
        world: World,
        slave: usize,
        safety: SafetyStage,
    ) -> Self {
        Self {
            coupling,
            controller,
            passivity,
            dt: world.params.dt,
            world,
            slave,
            safety,
            tau_prev: [0.0; 4],
            injected: None,
            record: TickRecord::default(),
        }
    }

    /// One haptic sample, §0.5 steps 0–11, from the joint angles `q` (rad) read `elapsed` seconds
    /// (measured) after the previous tick's reading, of which the loop waited `device_wait` s for
    /// the device (NaN = unknown; a stall then says whether the host or the device was late), to the
    /// motor torques (N·m). Never allocates, locks, prints or does I/O.
    ///
    /// A late tick differentiates the device signals over the measured interval; one later than the
    /// stall limit ([`SafetyConfig::stall_limit`]) trips the latch, because the device held its last
    /// torques unsupervised for that long. The world still steps by `T` (its integrator is passive
    /// for that step, §6). The caller writes `torques` right after the call; the world integration
    /// of step 10 has then already run, which only moves the write by about a microsecond.
    pub fn haptic_tick(
        &mut self,
        q: &<C::Device as CartesianDevice>::Joints,
        elapsed: f64,
        device_wait: f64,
    ) -> TickOutput {
        let t = self.world.time();
        let mut flags = 0u32;
        self.supervise_input(q, elapsed, device_wait); // 0
        let (est, closure_fault) = self.sense(q, elapsed); // 1–2
        self.guard_singularity(est.is_some(), &mut flags); // 2b
        self.align(est); // 1b
        let slave = self.contact_stage(); // 3–6
        let m_dev = self.coupling.device().mass_matrix(); // at the measured pose, for 7 and 8
        let (f_cm, mut f_cs) = self.teleoperate(est, &slave, &m_dev); // 7
        let port = self.port_passivity(est, &f_cm, &m_dev, &mut flags); // 8
        let f_dev = self.workspace_wall(est, port.f_port); // 8b
        let motor = self.motor_torques(&f_dev, est.is_some(), &mut flags); // 9
        if motor.gated {
            f_cs = [0.0; 3];
        }
        self.book_port(&port.f_port, motor.applied); // 9b
        self.integrate(&f_cs, &slave, motor.tau); // 10
        let f_cm = self.coupling.wrench_to_world(&f_dev);
        let forces = (f_cm, f_cs);
        self.record_tick(
            t,
            est,
            &slave,
            forces,
            &port,
            motor.tau,
            flags,
            (false, motor.gated),
        ); // 11
        self.output(motor.tau, est.is_some(), closure_fault)
    }

    /// A paused sample (the live display's pause): the device is still read from `q` (rad; steps
    /// 1–2, so the pose unwrapping, the velocity filter and the hand-wrench observer keep tracking
    /// the handle while the user moves it), but no controller runs, the world is not stepped (its
    /// time stands still) and the torques are zero. The record shows the device, the frozen slave
    /// and zero commands; the next running tick re-anchors the map and ramps the torques in from
    /// zero. Never allocates, locks, prints or does I/O.
    pub fn haptic_tick_paused(&mut self, q: &<C::Device as CartesianDevice>::Joints) -> TickOutput {
        let t = self.world.time();
        self.safety.supervise_paused(self.at(), q.as_ref()); // 0
        let (est, closure_fault) = self.sense(q, self.dt); // 1–2
        let mut tau = [0.0; 4];
        let mut flags = 0u32;
        let gated = self.safety.gate(self.at(), &mut tau, false);
        if gated {
            flags |= FLAG_SAFETY;
        }
        self.tau_prev = tau;
        if let Some(pc) = self.passivity.as_mut() {
            pc.idle();
        }
        let slave = SlaveState::at_centre(&self.world, self.slave);
        let port = PortOutput {
            f_port: [0.0; 3],
            po_energy: self.passivity.as_ref().map_or(0.0, |p| p.e_obs()),
            alpha: [0.0; 3],
        };
        let zero = ([0.0; 3], [0.0; 3]);
        self.record_tick(t, est, &slave, zero, &port, tau, flags, (true, gated)); // 11
        self.unalign(); // the handle moves while the slave is frozen
        self.output(tau, est.is_some(), closure_fault)
    }

    /// The tick's output: the torques (N·m) written now, the latch, the singularity margin when the
    /// device was read (`sensed`; 0 otherwise), the closure monitor's verdict and the record.
    fn output(&self, torques: V4, sensed: bool, closure_fault: bool) -> TickOutput {
        TickOutput {
            torques,
            tripped: self.safety.is_latched(),
            margin: if sensed {
                self.coupling.device().margin()
            } else {
                0.0
            },
            closure_fault,
            record: self.record,
        }
    }

    /// Forgets the device → world anchor: the next running tick anchors at the handle, restarts the
    /// ramp from zero and does not check a stall against the time before it.
    fn unalign(&mut self) {
        self.coupling.unalign(&self.world, self.slave);
        self.safety.restart_ramp();
        self.safety.restart_clock();
    }

    /// Re-arms the safety latch (an explicit user action). The device's estimates restart and the
    /// next tick re-anchors the map at the handle and ramps the torques in again from zero, as at
    /// start-up.
    pub fn reset_safety(&mut self) {
        self.safety.rearm();
        self.coupling.rearm();
        self.unalign();
    }

    /// Fault injection for safety tests and hardware commissioning: at the next tick, torque `index`
    /// (0–3) is replaced by `value` just before the safety gate (e.g. NaN to check that a non-finite
    /// torque is zeroed in the same tick). An out-of-range index is ignored.
    pub fn inject_torque_fault(&mut self, index: usize, value: f64) {
        if index < 4 {
            self.injected = Some((index, value));
        }
    }

    /// Latches the safety stop from outside (e.g. the device was lost): zero torques from now on.
    pub fn trip_device(&mut self, fault: DeviceFault) {
        let at = self.at();
        self.safety.trip(at, SafetyReason::Device(fault));
    }

    /// The stall check of [`Self::haptic_tick`] on its own, for a device paced by the ticks (the
    /// simulated plant) whose signals are differentiated over one period but whose loop can still
    /// stall: trips ([`SafetyReason::Stall`]) when `elapsed` (s since the previous tick; of which
    /// `device_wait` s waiting for the device, NaN = unknown) exceeds the stall limit
    /// `max(max_stall_periods·T, min_stall_time)`; the next tick's torques are then zero. Returns
    /// true when it tripped. Never allocates.
    pub fn check_stall(&mut self, elapsed: f64, device_wait: f64) -> bool {
        let at = self.at();
        self.safety.check_stall(at, elapsed, device_wait)
    }

    /// The device coupling (the device, its map to the world).
    pub fn coupling(&self) -> &C {
        &self.coupling
    }
    /// The world (bodies, contacts, ledger).
    pub fn world(&self) -> &World {
        &self.world
    }
    /// Mutable access to the world (e.g. to move a body or switch its laws between ticks).
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }
    /// Index of the slave body in the world.
    pub fn slave(&self) -> usize {
        self.slave
    }
    /// The workspace bound the tick applies (from the device file).
    pub fn workspace(&self) -> &WorkspaceBound {
        self.safety.workspace()
    }
    /// The latched safety trip, if any.
    pub fn safety_trip(&self) -> Option<SafetyTrip> {
        self.safety.trip_info()
    }
    /// The safety settings (ramp, stall limit, torque trip margin).
    pub fn safety_config(&self) -> &SafetyConfig {
        self.safety.config()
    }
    /// The record of the last tick.
    pub fn last_record(&self) -> &TickRecord {
        &self.record
    }
    /// The sample period `T` (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }
}

#[cfg(test)]
pub(super) mod tests {
    use crate::device::pantograph2::Pantograph2;
    use crate::geom::Vec2;
    use crate::haptic::planar2::{Planar2Config, Planar2System};
    use crate::haptic::{
        ControllerKind, DeviceSystem, HapticConfig, HapticSystem, SafetyReason, SafetyTrip,
        TickOutput,
    };
    use crate::world::World;

    /// Asserts that `out`, a tick of `sys`, tripped with zero torques, and returns the latched trip
    /// (its reason is the caller's to check).
    pub(crate) fn tripped(sys: &DeviceSystem, out: &TickOutput) -> SafetyTrip {
        assert!(out.tripped);
        assert_eq!(out.torques, [0.0; 4]);
        sys.safety_trip().unwrap()
    }

    /// The box-in-walls scene at 1 kHz, the slave's world in these tests.
    pub(in crate::haptic) fn box_in_walls() -> World {
        let scene = crate::scene::builtin("box-in-walls", Some(1000.0));
        scene.unwrap().unwrap().world
    }

    /// A gen 3 2DIY linkage (m) with the coupling controller and no ramp, and the joint angles of
    /// its handle `dx` m from the workspace centre along x.
    fn five_bar() -> (DeviceSystem, impl Fn(f64) -> [f64; 4]) {
        let linkage = Pantograph2::new(0.038, 0.07, 0.09).unwrap();
        let mut c = Planar2Config::new(linkage, 0.123);
        c.controller = ControllerKind::from_name("coupling").unwrap();
        c.safety.ramp_time = 0.0;
        let sys = Planar2System::new(box_in_walls(), c).unwrap();
        let q_at = move |dx: f64| {
            let q = linkage.ik(Vec2::new(0.019 + dx, 0.10)).unwrap();
            [q[0], q[1], 0.0, 0.0]
        };
        (DeviceSystem::TwoDof(sys), q_at)
    }

    fn twin() -> (DeviceSystem, [f64; 4]) {
        let sys = HapticSystem::new(box_in_walls(), &HapticConfig::default()).unwrap();
        let q = sys.device().kin.ik(&sys.device_start()).unwrap();
        (DeviceSystem::Twin(sys), q)
    }

    /// The fault injection was the twin's alone while each device had its own tick; with one tick
    /// the 2-DOF device's torques pass the same injection point and the same final gate.
    #[test]
    fn a_non_finite_torque_on_a_five_bar_is_zeroed_by_the_shared_gate_in_the_same_tick() {
        let (mut sys, q_at) = five_bar();
        sys.tick(&q_at(0.0), None, false);
        let out = sys.tick(&q_at(0.004), None, false);
        assert!(!out.tripped && out.torques[0].abs() > 0.0, "{out:?}");
        let DeviceSystem::TwoDof(s) = &mut sys else {
            unreachable!()
        };
        s.inject_torque_fault(1, f64::NAN);
        let out = sys.tick(&q_at(0.004), None, false);
        let trip = tripped(&sys, &out);
        assert!(
            matches!(trip.reason, SafetyReason::NonFiniteTorque { index: 1, .. }),
            "{trip}"
        );
    }

    /// The paused tick is written once: on either device it zeroes the torques, leaves the world's
    /// time standing and still reads the device (the margin of a valid reading is reported).
    #[test]
    fn a_paused_tick_zeroes_torques_and_freezes_the_world_on_either_device() {
        let (twin, q_twin) = twin();
        let (five_bar, q_at) = five_bar();
        for (mut sys, q) in [(twin, q_twin), (five_bar, q_at(0.004))] {
            sys.tick(&q, None, false);
            let t = sys.world().time();
            for _ in 0..3 {
                let out = sys.tick(&q, None, true);
                assert_eq!(out.torques, [0.0; 4]);
                assert!(!out.tripped && out.margin > 0.0, "{out:?}");
            }
            assert_eq!(sys.world().time(), t, "the world stood still");
        }
    }
}
