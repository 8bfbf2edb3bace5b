//! [`HapticSystem`]: the twin pantograph's haptic system, `Haptic<TwinCoupling>` — the device
//! (x, y, θ) behind a [`DeviceMap`] (scale, anchored at the first reading), the slave held at its
//! centre, the optional passivity controller on the device port. The tick is the one of
//! [`Haptic`] (`tick.rs`); this file holds the twin's coupling and its API.

use crate::control::four_channel::TeleopSignals;
use crate::control::passivity::PlanarPassivity;
use crate::device::linalg::{M3, V3, V4};
use crate::device::{DeviceEstimate, TwinPantograph};
use crate::geom::Vec2;
use crate::world::World;

use super::config::{find_slave, ControllerKind, HapticConfig};
use super::controller::Controller;
use super::coupling::{DeviceCoupling, SlaveState};
use super::mapping::DeviceMap;
use super::safety::{Safety, SafetyConfig};
use super::safety_stage::SafetyStage;
use super::tick::{Haptic, TickOutput};
use super::workspace::WorkspaceBound;

/// The whole haptic system of DESIGN §1 for the twin pantograph: twin-pantograph estimator,
/// teleoperation controller, optional passivity controller on the device port, and the virtual
/// world with its slave body (see [`Haptic`] for the tick and its safety).
pub type HapticSystem = Haptic<TwinCoupling>;

/// The twin pantograph as the tick drives it: the device, its [`DeviceMap`] to the world (anchored
/// at the first reading), the preload of its redundancy resolution and the experiments' hand-wrench
/// injection. The slave is held at its centre.
#[derive(Clone, Debug)]
pub struct TwinCoupling {
    device: TwinPantograph,
    map: DeviceMap,
    preload: f64,
    /// A wrench added to the hand-wrench estimate before the controller (handle frame: N, N, N·m);
    /// zero except in experiments ([`HapticSystem::set_hand_estimate_injection`]).
    hand_injection: V3,
    /// False until the first valid reading after construction, a re-arm or a pause.
    aligned: bool,
}

impl DeviceCoupling for TwinCoupling {
    type Device = TwinPantograph;
    const MARGIN_AT_SENSE: bool = false;

    fn device(&self) -> &TwinPantograph {
        &self.device
    }
    fn device_mut(&mut self) -> &mut TwinPantograph {
        &mut self.device
    }

    /// Anchors the map: the measured handle pose maps onto the slave's current pose.
    fn align(&mut self, e: &DeviceEstimate, world: &World, slave: usize) -> bool {
        if self.aligned {
            return false;
        }
        let body = &world.bodies[slave];
        self.map.device_origin = e.pose;
        self.map.world_origin = [body.pose.pos.x, body.pose.pos.y, body.pose.angle];
        self.aligned = true;
        true
    }

    fn unalign(&mut self, _world: &World, _slave: usize) {
        self.aligned = false;
    }

    /// The estimates are stale after a fault (a stall, lost readings): restart the velocity filter
    /// and the observer, keeping the θ unwrapping reference.
    fn rearm(&mut self) {
        let theta = self
            .device
            .pose()
            .map_or(self.map.device_origin[2], |p| p[2]);
        self.device.reset(theta);
    }

    fn slave_state(&self, world: &World, i: usize) -> SlaveState {
        SlaveState::at_centre(world, i)
    }

    /// The handle through the map, the hand-wrench estimate plus the injection, and the master mass
    /// in world coordinates: with the twist map `v_w = S·v_d` and the wrench map `f_d = S·f_w`
    /// (`S = diag(s, s, 1)`), `f_d = M_d·a_d` gives `f_w = S⁻¹·M_d·S⁻¹·a_w`.
    fn teleop_signals(&self, e: &DeviceEstimate, s: &SlaveState, m_dev: &M3) -> TeleopSignals {
        let sc = [self.map.scale, self.map.scale, 1.0];
        let master_mass: M3 =
            std::array::from_fn(|i| std::array::from_fn(|j| m_dev[i][j] / (sc[i] * sc[j])));
        TeleopSignals {
            x_m: self.map.pose_to_world(&e.pose),
            v_m: self.map.twist_to_world(&e.velocity),
            f_h: self.map.wrench_to_world(&std::array::from_fn(|i| {
                e.hand_wrench[i] + self.hand_injection[i]
            })),
            x_s: s.x_s,
            v_s: s.v_s,
            f_e: s.f_e,
            master_mass,
        }
    }

    fn wrench_to_device(&self, f: &V3) -> V3 {
        self.map.wrench_to_device(f)
    }
    fn wrench_to_world(&self, f: &V3) -> V3 {
        self.map.wrench_to_world(f)
    }
    fn preload(&self) -> f64 {
        self.preload
    }

    /// The drive at the centre: force and torque as commanded.
    fn drive(&self, f_cs: &V3, _s: &SlaveState, _latched: bool) -> (Vec2, f64) {
        (Vec2::new(f_cs[0], f_cs[1]), f_cs[2])
    }
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
        let coupling = TwinCoupling {
            device,
            map,
            preload: config.preload,
            hand_injection: [0.0; 3],
            aligned: false,
        };
        let safety = SafetyStage::new(
            safety,
            Safety::new(
                config.device.min_singularity_margin,
                tau_max,
                safety.torque_trip_margin,
            ),
            WorkspaceBound::new(&config.device, dt),
            dt,
        );
        Ok(Haptic::assemble(
            coupling,
            controller,
            config.passivity,
            world,
            slave,
            safety,
        ))
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
        self.haptic_tick(q, elapsed, device_wait)
    }

    /// A paused sample: [`Haptic::haptic_tick_paused`]. Never allocates, locks, prints or does I/O.
    pub fn tick_paused(&mut self, q: &V4) -> TickOutput {
        self.haptic_tick_paused(q)
    }

    /// Switches the teleoperation controller to `kind`, starting from its reset state (no integrator
    /// or filter state carried over); its gains are checked against the slave's mass as in
    /// [`Self::new`], and on error the running controller is kept.
    pub fn set_controller(&mut self, kind: ControllerKind) -> Result<(), String> {
        self.controller = Controller::build(kind, &self.world, self.slave, self.dt)?;
        Ok(())
    }

    /// Experiments only (issue 36, "the hand is replaced by a constant force" read as a force in the
    /// hand-force estimate): from the next tick on, `w` (handle frame: N, N, N·m) is added to the
    /// observer's hand-wrench estimate that the controller receives (`f_h` of §11.1). The recorded
    /// `w_h` stays the observer's own estimate. Non-finite values are ignored; zero turns it off.
    pub fn set_hand_estimate_injection(&mut self, w: V3) {
        if w.iter().all(|v| v.is_finite()) {
            self.coupling.hand_injection = w;
        }
    }

    /// The device ↔ world mapping.
    pub fn map(&self) -> &DeviceMap {
        &self.coupling.map
    }
    /// The device estimator.
    pub fn device(&self) -> &TwinPantograph {
        &self.coupling.device
    }
    /// The passivity controller, if enabled.
    pub fn passivity(&self) -> Option<&PlanarPassivity> {
        self.passivity.as_ref()
    }
    /// The start-up ramp factor the next tick applies (0 at the first valid reading, 1 once ramped in).
    pub fn ramp(&self) -> f64 {
        if self.coupling.aligned {
            self.safety.ramp()
        } else {
            0.0
        }
    }
    /// The handle pose the device should start at (m, m, rad): the mapping's device origin (before
    /// the first tick; from then on, the handle pose the start-up alignment anchored).
    pub fn device_start(&self) -> V3 {
        self.coupling.map.device_origin
    }
}
