//! [`HapticSystem`]: device + controller + passivity controller + world, and the per-sample
//! [`HapticSystem::tick`] in the order of §0.5.

use crate::control::passivity::PlanarPassivity;
use crate::device::linalg::{V3, V4};
use crate::device::TwinPantograph;
use crate::world::World;

use super::config::{find_slave, ControllerKind, HapticConfig};
use super::controller::Controller;
use super::mapping::DeviceMap;
use super::record::{TickRecord, FLAG_SAFETY};
use super::safety::{Safety, SafetyConfig, SafetyTrip};
use super::safety_stage::SafetyStage;
use super::workspace::WorkspaceBound;

mod steps;

use steps::PortOutput;

/// What one tick hands back to the caller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickOutput {
    /// The four motor torques to write to the amplifiers now and hold for one period (N·m); all zero
    /// when the safety latch is set.
    pub torques: V4,
    /// True when the safety latch is set (this tick or earlier).
    pub tripped: bool,
    /// The singularity margin at the measured pose (dimensionless, §10.4); 0 when the device could
    /// not be read this tick. For a watchdog downstream.
    pub margin: f64,
    /// True when the kinematic consistency (closure) monitor of §10.3 failed this tick.
    pub closure_fault: bool,
    /// The tick's telemetry record.
    pub record: TickRecord,
}

/// The whole haptic system of DESIGN §1: twin-pantograph estimator, teleoperation controller, optional
/// passivity controller on the device port, and the virtual world with its slave body.
///
/// Safety (DESIGN §7) is part of the system, so every device gets it: the torques are exactly zero
/// until the first valid device reading; at that reading the mapping is re-anchored so that the
/// measured handle pose lands on the slave's pose (no coupling force on the first tick), and the
/// torques ramp in over [`SafetyConfig::ramp_time`]; the workspace bound of the device file is a
/// passive wall with a trip beyond it; a stall trips; the final gate clamps to `τ_max`.
#[derive(Clone, Debug)]
pub struct HapticSystem {
    device: TwinPantograph,
    controller: Controller,
    passivity: Option<PlanarPassivity>,
    world: World,
    slave: usize,
    map: DeviceMap,
    /// The shared safety steps: stall, plausibility, workspace bound, limit cycle, ramp, gate.
    safety: SafetyStage,
    preload: f64,
    dt: f64,
    tau_prev: V4,
    injected: Option<(usize, f64)>,
    /// A wrench added to the hand-wrench estimate before the controller (handle frame: N, N, N·m);
    /// zero except in experiments ([`HapticSystem::set_hand_estimate_injection`]).
    hand_injection: V3,
    /// False until the first valid reading after construction, a re-arm or a pause.
    aligned: bool,
    record: TickRecord,
}

impl HapticSystem {
    /// Builds the system around `world` (its sample period is the tick period) with the default
    /// [`SafetyConfig`]. Checks the device parameters at that period, the controller gains against
    /// the slave's mass (§6.4), the passivity controller, the mapping and the preload; errors name
    /// the setting to fix.
    pub fn new(world: World, config: &HapticConfig) -> Result<Self, String> {
        Self::with_safety(world, config, SafetyConfig::default())
    }

    /// [`Self::new`] with the safety settings `safety` (ramp time, stall limit, torque trip margin).
    pub fn with_safety(
        mut world: World,
        config: &HapticConfig,
        safety: SafetyConfig,
    ) -> Result<Self, String> {
        safety.validate()?;
        let dt = world.params.dt;
        let slave = find_slave(&world, config.slave.as_deref())?;
        let body = &world.bodies[slave];
        let world_origin = [body.pose.pos.x, body.pose.pos.y, body.pose.angle];
        let controller = Controller::build(config.controller, &world, slave, dt)?;
        if let Some(p) = &config.passivity {
            p.validate()?;
        }
        let mut device = TwinPantograph::new(config.device, dt, config.observer)?;
        let mut map = DeviceMap::centred(&config.device, world_origin);
        if let Some(o) = config.device_origin {
            map.device_origin = o;
        }
        map.scale = config.scale;
        map.validate()?;
        let margin = crate::device::jacobian::singularity_margin(&device.kin, &map.device_origin)
            .map_err(|e| {
            format!(
                "device origin {:?} is not reachable: {e}",
                map.device_origin
            )
        })?;
        if margin < config.device.min_singularity_margin {
            return Err(format!(
                "device origin {:?} is too close to a singularity (margin {margin:.3})",
                map.device_origin
            ));
        }
        let tau_max = config.device.tau_max;
        if !(config.preload.is_finite() && config.preload.abs() <= 0.1 * tau_max) {
            return Err(format!(
                "preload must be finite with |preload| <= 0.1 x tau_max = {} N m (got {})",
                0.1 * tau_max,
                config.preload
            ));
        }
        if !config.keep_slave_loads {
            world.loads.retain(|l| l.body != slave);
        }
        device.reset(map.device_origin[2]);
        Ok(Self {
            device,
            controller,
            passivity: config.passivity,
            world,
            slave,
            map,
            safety: SafetyStage::new(
                safety,
                Safety::new(
                    config.device.min_singularity_margin,
                    tau_max,
                    safety.torque_trip_margin,
                ),
                WorkspaceBound::new(&config.device, dt),
                dt,
            ),
            preload: config.preload,
            dt,
            tau_prev: [0.0; 4],
            injected: None,
            hand_injection: [0.0; 3],
            aligned: false,
            record: TickRecord::default(),
        })
    }

    /// One haptic sample taken on time (one period after the previous one): see
    /// [`Self::tick_elapsed`].
    pub fn tick(&mut self, q: &V4) -> TickOutput {
        self.tick_elapsed(q, self.dt)
    }

    /// One haptic sample, §0.5 steps 1–11, from the four encoder angles `q` (rad) read `elapsed`
    /// seconds (measured) after the previous tick's reading, to the four motor torques (N·m). Never
    /// allocates, locks, prints or does I/O.
    ///
    /// `elapsed` is what the real-time loop measured; a device paced by the ticks themselves (a
    /// simulated plant that advances one period per tick, a replay) passes `T` (or calls
    /// [`Self::tick`]). A late tick differentiates and integrates the device signals over the measured
    /// interval; one later than the stall limit (`max_stall_periods` periods, at least `min_stall_time`,
    /// [`SafetyConfig::stall_limit`]) trips the latch, because the device
    /// held its last torques unsupervised for that long. The world still steps by `T`: its
    /// integrator is passive for that step (§6).
    ///
    /// The caller writes `torques` to the amplifiers right after the call (step 9's output); the world
    /// integration of step 10 has then already run, which only moves the write by the integration
    /// time (about a microsecond) and keeps the tick one call.
    pub fn tick_elapsed(&mut self, q: &V4, elapsed: f64) -> TickOutput {
        self.tick_timed(q, elapsed, f64::NAN)
    }

    /// [`Self::tick_elapsed`] with the part of `elapsed` the loop spent waiting for the device's
    /// reply, `device_wait` (s; NaN = unknown), so that a stall says whether the host or the device
    /// was late. Never allocates, locks, prints or does I/O.
    pub fn tick_timed(&mut self, q: &V4, elapsed: f64, device_wait: f64) -> TickOutput {
        let t = self.world.time();
        let mut flags = 0u32;
        self.supervise_input(q, elapsed, device_wait); // 0
        let (est, closure_fault) = self.sense(q, elapsed); // 1–2
        self.align(est); // 1b
        let slave = self.contact_stage(); // 3–6
        let m_dev = self.device.mass_matrix(); // at the measured pose, for steps 7 and 8
        let (f_cm, mut f_cs) = self.teleoperate(est, &slave, &m_dev); // 7
        let port = self.port_passivity(est, &f_cm, &m_dev, &mut flags); // 8
        let f_dev = self.workspace_wall(est, port.f_port); // 8b
        let motor = self.motor_torques(&f_dev, &mut flags); // 9
        if motor.gated {
            f_cs = [0.0; 3];
        }
        self.book_port(&port.f_port, motor.applied); // 9b
        self.integrate(&f_cs, motor.tau); // 10
        let f_cm = self.map.wrench_to_world(&f_dev);
        self.record_tick(t, est, &slave, (f_cm, f_cs), &port, motor.tau, flags); // 11
        self.output(motor.tau, est.is_some(), closure_fault)
    }

    /// A paused sample (the live display's pause): the device is still estimated from the encoder
    /// angles `q` (rad; steps 1–2, so the pose unwrapping, the velocity filter and the hand-wrench
    /// observer keep tracking the handle while the user moves it), but neither controller runs, the
    /// world is not stepped (its time stands still) and the torques are zero. The record shows the
    /// device, the frozen slave and zero commands. Never allocates, locks, prints or does I/O.
    pub fn tick_paused(&mut self, q: &V4) -> TickOutput {
        let t = self.world.time();
        self.safety.supervise_paused((self.world.tick(), t), q);
        let (est, closure_fault) = self.sense(q, self.dt); // 1–2
        let mut tau = [0.0; 4];
        let mut flags = 0u32;
        if self.safety.gate((self.world.tick(), t), &mut tau, false) {
            flags |= FLAG_SAFETY;
        }
        self.tau_prev = tau;
        // The handle moves while the slave is frozen: the next running tick re-aligns and ramps in.
        self.aligned = false;
        self.safety.restart_clock();
        if let Some(pc) = self.passivity.as_mut() {
            pc.idle();
        }
        let slave = self.slave_state();
        let port = PortOutput {
            f_port: [0.0; 3],
            po_energy: self.passivity.as_ref().map_or(0.0, |p| p.e_obs()),
            alpha: [0.0; 3],
        };
        self.record_tick(t, est, &slave, ([0.0; 3], [0.0; 3]), &port, tau, flags); // 11
        self.output(tau, est.is_some(), closure_fault)
    }

    /// The tick's output: the torques (N·m) written now, the latch, the singularity margin when the
    /// device was read (`sensed`; 0 otherwise), the closure monitor's verdict and the record.
    fn output(&self, torques: V4, sensed: bool, closure_fault: bool) -> TickOutput {
        TickOutput {
            torques,
            tripped: self.safety.is_latched(),
            margin: if sensed { self.device.margin() } else { 0.0 },
            closure_fault,
            record: self.record,
        }
    }

    /// Switches the teleoperation controller to `kind`, starting from its reset state (no integrator
    /// or filter state carried over); its gains are checked against the slave's mass as in
    /// [`Self::new`], and on error the running controller is kept.
    pub fn set_controller(&mut self, kind: ControllerKind) -> Result<(), String> {
        self.controller = Controller::build(kind, &self.world, self.slave, self.dt)?;
        Ok(())
    }

    /// Fault injection for safety tests and hardware commissioning: at the next tick, torque `index`
    /// (0–3) is replaced by `value` just before the safety gate (e.g. NaN to check that a non-finite
    /// torque is zeroed in the same tick). An out-of-range index is ignored.
    pub fn inject_torque_fault(&mut self, index: usize, value: f64) {
        if index < 4 {
            self.injected = Some((index, value));
        }
    }

    /// Experiments only (issue 36, "the hand is replaced by a constant force" read as a force in the
    /// hand-force estimate): from the next tick on, `w` (handle frame: N, N, N·m) is added to the
    /// observer's hand-wrench estimate that the controller receives (`f_h` of §11.1). The recorded
    /// `w_h` stays the observer's own estimate. Non-finite values are ignored; zero turns it off.
    pub fn set_hand_estimate_injection(&mut self, w: V3) {
        if w.iter().all(|v| v.is_finite()) {
            self.hand_injection = w;
        }
    }

    /// The world (bodies, contacts, ledger).
    pub fn world(&self) -> &World {
        &self.world
    }
    /// Mutable access to the world (e.g. to move a body between ticks).
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }
    /// Index of the slave body in the world.
    pub fn slave(&self) -> usize {
        self.slave
    }
    /// The device ↔ world mapping.
    pub fn map(&self) -> &DeviceMap {
        &self.map
    }
    /// The workspace bound rendered from the device file.
    pub fn workspace(&self) -> &WorkspaceBound {
        self.safety.workspace()
    }
    /// The device estimator.
    pub fn device(&self) -> &TwinPantograph {
        &self.device
    }
    /// The passivity controller, if enabled.
    pub fn passivity(&self) -> Option<&PlanarPassivity> {
        self.passivity.as_ref()
    }
    /// The latched safety trip, if any.
    pub fn safety_trip(&self) -> Option<SafetyTrip> {
        self.safety.trip_info()
    }
    /// Re-arms the safety latch (an explicit user action). The next tick re-aligns the mapping to the
    /// handle's measured pose and ramps the torques in again from zero, as at start-up.
    pub fn reset_safety(&mut self) {
        self.safety.rearm();
        // The estimates are stale after a fault (a stall, lost readings): restart the velocity filter
        // and the observer, keeping the θ unwrapping reference.
        let theta = self
            .device
            .pose()
            .map_or(self.map.device_origin[2], |p| p[2]);
        self.device.reset(theta);
        self.aligned = false;
        self.safety.restart_clock();
    }

    /// The stall check of [`Self::tick_elapsed`] on its own, for a device paced by the ticks (the
    /// simulated plant) whose signals are differentiated over one period but whose loop can still
    /// stall: trips ([`SafetyReason::Stall`](super::safety::SafetyReason::Stall)) when `elapsed` (s since the previous tick; of which
    /// `device_wait` s waiting for the device, NaN = unknown) exceeds the stall limit `max(max_stall_periods·T, min_stall_time)`; the
    /// next tick's torques are then zero. Returns true when it tripped. Never allocates.
    pub fn check_stall(&mut self, elapsed: f64, device_wait: f64) -> bool {
        let at = (self.world.tick(), self.world.time());
        self.safety.check_stall(at, elapsed, device_wait)
    }
    /// The safety settings (ramp, stall limit, torque trip margin).
    pub fn safety_config(&self) -> &SafetyConfig {
        self.safety.config()
    }
    /// The start-up ramp factor the next tick applies (0 at the first valid reading, 1 once ramped in).
    pub fn ramp(&self) -> f64 {
        if self.aligned {
            self.safety.ramp()
        } else {
            0.0
        }
    }
    /// The record of the last tick.
    pub fn last_record(&self) -> &TickRecord {
        &self.record
    }
    /// The sample period `T` (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// The handle pose the device should start at (m, m, rad): the mapping's device origin (before
    /// the first tick; from then on, the handle pose the start-up alignment anchored).
    pub fn device_start(&self) -> V3 {
        self.map.device_origin
    }
}
