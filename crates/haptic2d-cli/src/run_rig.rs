//! The rig of `haptic2d run`: the haptic system (device estimator, controller, world) and the device
//! it drives (simulated twin pantograph with a simulated hand, a replay, or a real device), built
//! from a scene's world and rebuilt when the live display resets or switches the scene.
//!
//! The real devices (`--device haply:…`, `udp:…`, `inverse3…`) come from the device registry of
//! `haptic2d-devices` ([`haptic2d_devices::registry`], re-exported here): the device choice, the
//! model the system is built for (a twin: [`HapticSystem`]; a five-bar: [`Planar2System`]; a
//! Cartesian point device such as the Inverse3: [`PointSystem`]), and the closure that opens the
//! device.
//!
//! The rig does the rest: the stability gate with the hand released (`--allow-unstable`), zero
//! torques until the first valid reading and the start-up ramp of the shared safety layer, the
//! stall check on the loop's own time (see [`Rig::tick_system`]), the final clamp.

use crate::grip_twist::GripTwist;
use crate::hand_arg::HandSpec;
use haptic2d::device::linalg::{V3, V4};
use haptic2d::device::DeviceParams;
use haptic2d::haptic::planar2::{GraspConfig, Planar2Config, Planar2System};
use haptic2d::haptic::{
    ControllerKind, DeviceSystem, HapticConfig, HapticSystem, PointConfig, PointSystem,
    SafetyConfig, TickOutput,
};
use haptic2d::world::World;
use haptic2d_devices::device_safety::DeviceSafety;
pub use haptic2d_devices::registry::{DeviceChoice, DeviceModel, MatchController, RealDevice};
use haptic2d_rt::clock::now_ns;
use haptic2d_rt::io::DEFAULT_REPLAY_COLUMNS;
use haptic2d_rt::{
    DeviceError, DeviceIo, ReplayDevice, ReplayEnd, SafetyInput, SharedTarget, SimIo, TickInfo,
    TickInterval, WatchdogConfig,
};
use std::sync::Arc;
use std::time::Duration;

/// The limits of a real device the rig keeps after opening it (to rebuild its system).
#[derive(Clone, Debug, PartialEq)]
struct RealLimits {
    model: DeviceModel,
    wait_periods: f64,
    max_missed_run: Option<u32>,
    max_stall_periods: f64,
    safety: DeviceSafety,
}

/// The stall limit of the simulated device (s): at least 40 ms, twice the shared 20 ms floor of a
/// real device. Its plant advances only per tick, so a late tick cannot hurt anyone; the latch is
/// there so that `run --device sim` stops on a stalled loop as a real device does (a 50 ms stop of
/// the host trips), without tripping on the scheduling of a loaded machine: at load average 9 on
/// this project's 2-core VM, without real-time priority, three 3 s runs saw gaps of 25, 10 and 9 ms.
pub const SIM_MIN_STALL_TIME: f64 = 0.04;

/// The safety settings of the simulated device and a replay: the defaults with
/// [`SIM_MIN_STALL_TIME`].
fn sim_safety() -> SafetyConfig {
    SafetyConfig {
        min_stall_time: SIM_MIN_STALL_TIME,
        ..SafetyConfig::default()
    }
}

/// RK4 sub-steps of the simulated plant per tick: one per 0.5 ms of period (at least one).
fn plant_substeps(dt: f64) -> u32 {
    ((dt / 0.0005).ceil() as u32).max(1)
}

/// The haptic system and its device, owned by the loop thread.
pub struct Rig {
    /// Device estimator, controller, passivity controller and world (twin or 2-DOF).
    pub system: DeviceSystem,
    /// The device I/O (a 2-DOF device fills `q[0..2]`).
    pub io: Box<dyn DeviceIo + Send>,
    /// The settings the system was built with; `controller` follows the page's selection. For a
    /// real twin, `device` holds its parameters; for a 2-DOF device it is unused.
    pub config: HapticConfig,
    /// Which device.
    pub device: DeviceChoice,
    /// What the simulated hand does (simulated device only).
    pub hand: HandSpec,
    /// The target a `follow` hand pulls the handle towards (m, m, rad, handle coordinates): set by
    /// the page's pointer. `None` for any other hand or device.
    pub target: Option<Arc<SharedTarget>>,
    /// A real device's model and limits; `None` for the simulation and a replay.
    real: Option<RealLimits>,
    /// A real device's controller matching (applied to the page's controller switches too).
    match_controller: Option<MatchController>,
    /// A real device's stability gate (§11.4): every controller switch and scene switch from the
    /// display must be stable with the hand released, like the configuration `run` started with.
    /// Off for the simulation and a replay, and with `--allow-unstable`.
    released_gate: bool,
    /// Measures the interval between ticks (wake to wake).
    interval: TickInterval,
    /// Time the last read waited for the device (ns; real devices only).
    read_wait_ns: u64,
    /// The same for the read of the previous tick (ns).
    prev_read_wait_ns: u64,
    /// The last tick's interval on the loop's own account, in periods (1 for a device paced by the
    /// ticks): what the watchdog's stall check sees.
    elapsed_periods: f64,
    /// The twist target from a device that senses its handle's orientation (2-DOF devices).
    grip: GripTwist,
}

impl Rig {
    /// Builds the system around `world` (of the scene loaded from `source`, named in errors) and
    /// opens the simulated device or the replay. The simulated device starts at rest at the system's
    /// start pose; a `follow` hand holds it there until the target moves. For a real device use
    /// [`Self::with_real`].
    pub fn new(
        world: World,
        source: &str,
        config: HapticConfig,
        device: DeviceChoice,
        hand: HandSpec,
    ) -> Result<Self, String> {
        if device.is_real() {
            return Err(format!(
                "{device:?}: a real device is opened with Rig::with_real"
            ));
        }
        let system = HapticSystem::with_safety(world, &config, sim_safety())
            .map_err(|e| format!("scene {source}: {e}"))?;
        let target = (device == DeviceChoice::Sim && hand == HandSpec::Follow)
            .then(|| Arc::new(SharedTarget::new(system.device_start())));
        let io: Box<dyn DeviceIo + Send> = match &device {
            DeviceChoice::Replay(p) if crate::run_log::is_mcap(p) => Box::new(
                haptic2d_rt::mcap::McapReplay::from_path(p, ReplayEnd::Error)?,
            ),
            DeviceChoice::Replay(p) => Box::new(ReplayDevice::from_path(
                p,
                DEFAULT_REPLAY_COLUMNS,
                ReplayEnd::Error,
            )?),
            _ => Box::new(Self::sim(&system, &config, &hand, target.as_ref())?),
        };
        Ok(Self {
            hand,
            target,
            ..Self::fresh(DeviceSystem::Twin(system), io, config, device)
        })
    }

    /// A rig of `system` driving `io`, the hand following (no target, no real device), with the
    /// per-run state of the tick fresh: no released-stability gate, no interval measured yet, one
    /// period elapsed, no grip turn.
    fn fresh(
        system: DeviceSystem,
        io: Box<dyn DeviceIo + Send>,
        config: HapticConfig,
        device: DeviceChoice,
    ) -> Self {
        Self {
            system,
            io,
            config,
            device,
            hand: HandSpec::Follow,
            target: None,
            real: None,
            match_controller: None,
            released_gate: false,
            interval: TickInterval::new(),
            read_wait_ns: 0,
            prev_read_wait_ns: 0,
            elapsed_periods: 1.0,
            grip: GripTwist::default(),
        }
    }

    /// Builds the system for the real device `real` around `world` (errors name the scene and the
    /// setting; nothing is opened then), then opens the device at the world's period (its error:
    /// the device and what to check). A twin's parameters replace `config.device`.
    pub fn with_real(
        world: World,
        source: &str,
        mut config: HapticConfig,
        device: DeviceChoice,
        real: RealDevice,
    ) -> Result<Self, RealOpenError> {
        if let DeviceModel::Twin(p) = &real.model {
            config.device = *p;
        }
        if let Some(m) = &real.match_controller {
            config.controller = m(config.controller);
        }
        let limits = RealLimits {
            model: real.model,
            wait_periods: real.wait_periods,
            max_missed_run: real.max_missed_run,
            max_stall_periods: real.max_stall_periods,
            safety: real.safety,
        };
        let period = Duration::from_secs_f64(world.params.dt);
        let system = Self::real_system(world, &config, &limits).map_err(|e| {
            RealOpenError::Config(format!("scene {source} with {}: {e}", real.summary))
        })?;
        let io = (real.open)(period).map_err(RealOpenError::Open)?;
        Ok(Self {
            real: Some(limits),
            match_controller: real.match_controller,
            ..Self::fresh(system, io, config, device)
        })
    }

    /// The system of a real device. The tick's own stall limit is the loop's allowance plus the
    /// device's own reply timeout: the interval it sees (wake to wake) includes the wait for the
    /// device, which the driver bounds (lost device, exit 4); the watchdog checks the loop's own
    /// share against the plain limit (see [`Self::tick_system`]).
    fn real_system(
        world: World,
        config: &HapticConfig,
        limits: &RealLimits,
    ) -> Result<DeviceSystem, String> {
        // The device file's plausibility bounds and stall floor (its `[safety]` table).
        let safety = limits.safety.apply(SafetyConfig {
            max_stall_periods: limits.max_stall_periods + limits.wait_periods,
            ..SafetyConfig::default()
        });
        Ok(match &limits.model {
            DeviceModel::Twin(_) => {
                DeviceSystem::Twin(HapticSystem::with_safety(world, config, safety)?)
            }
            DeviceModel::FiveBar {
                linkage,
                tau_max,
                workspace,
                ..
            } => {
                if config.passivity.is_some() {
                    return Err("--passivity is not available on a 2-DOF device (its port has no hand-wrench observer); leave it out".into());
                }
                let mut c = Planar2Config::new(*linkage, *tau_max);
                c.controller = config.controller;
                c.slave = config.slave.clone();
                c.safety = safety;
                c.workspace = *workspace;
                DeviceSystem::TwoDof(Planar2System::new(world, c)?)
            }
            DeviceModel::Point {
                force_limit,
                workspace,
                ..
            } => {
                if config.passivity.is_some() {
                    return Err("--passivity is not available on a point device (its port has no hand-wrench observer); leave it out".into());
                }
                let mut common = GraspConfig::new(*workspace);
                common.controller = config.controller;
                common.slave = config.slave.clone();
                common.safety = safety;
                DeviceSystem::Point(PointSystem::new(
                    world,
                    PointConfig {
                        force_limit: *force_limit,
                        common,
                    },
                )?)
            }
        })
    }

    /// The watchdog's thresholds for this rig: the device file's singularity margin always; for a
    /// real device also the stall limit of the shared safety settings (on the loop's own time) and
    /// the device's limit of consecutive missed deadlines. A device paced by the ticks (the
    /// simulated plant, a replay) does not move between ticks, so a late tick cannot hurt anyone:
    /// stalls and misses are counted in the timing summary but do not stop the run.
    pub fn watchdog_config(&self) -> WatchdogConfig {
        let real = !self.io.paced_by_ticks();
        let missed = match &self.real {
            Some(l) => l.max_missed_run,
            None => Some(10),
        };
        WatchdogConfig {
            min_singularity_margin: match &self.real {
                // The 2-DOF system trips on its own margin (a five-bar's margin is another measure;
                // a point device has none).
                Some(RealLimits {
                    model: DeviceModel::FiveBar { .. } | DeviceModel::Point { .. },
                    ..
                }) => 0.0,
                _ => self.config.device.min_singularity_margin,
            },
            max_missed_run: if real { missed } else { None },
            // The device file's periods, at least its stall floor (`[safety] stall_floor`).
            max_stall_periods: real.then_some({
                let (periods, floor) = self.real.as_ref().map_or(
                    (
                        SafetyConfig::default().max_stall_periods,
                        SafetyConfig::default().min_stall_time,
                    ),
                    |l| (l.max_stall_periods, l.safety.stall_floor),
                );
                periods.max(floor / self.system.world().params.dt)
            }),
        }
    }

    /// Reads the device, timing the read of a real device (the wait for the device is the driver's
    /// business, bounded by its timeout, and is left out of the stall check). Never allocates.
    #[inline]
    pub fn read(&mut self) -> Result<V4, DeviceError> {
        if self.io.paced_by_ticks() {
            return self.io.read_encoders();
        }
        let t0 = now_ns();
        let r = self.io.read_encoders();
        self.read_wait_ns = now_ns().saturating_sub(t0);
        r
    }

    /// One tick of the system on encoder angles `q` (rad), `paused` or running. Never allocates.
    ///
    /// A device paced by the ticks gets one period. A real device gets the measured wake-to-wake
    /// interval `Δ_k` (its signals are differentiated over it; the system's own stall limit allows
    /// for the device's reply timeout), and the watchdog sees the loop's own share of it,
    ///
    /// ```text
    /// Δ_loop,k = Δ_k − w_{k−1},   w_{k−1} = time the previous tick's read waited for the device,
    /// ```
    ///
    /// i.e. sleep overshoot and computation: a loop that stalls (an overloaded machine, a blocked
    /// thread) trips the stall check within the tick, with its reason; a device that is slow or
    /// silent is the driver's read timeout (lost device, exit 4), never a stall.
    pub fn tick_system(&mut self, q: &V4, info: &TickInfo, paused: bool) -> TickOutput {
        let elapsed_ns = self.interval.update(info);
        let wait_ns = std::mem::replace(&mut self.prev_read_wait_ns, self.read_wait_ns);
        // A sensed handle orientation turns the slave's twist target (2-DOF and point devices).
        if let (Some(a), None) = (self.io.handle_angle(), self.system.twin()) {
            let slave_angle = self.system.world().bodies[self.system.slave()].pose.angle;
            self.system
                .set_twist_target(self.grip.target(a, slave_angle));
        }
        if paused {
            self.elapsed_periods = 1.0;
            self.system.tick(q, None, true)
        } else if self.io.paced_by_ticks() {
            self.elapsed_periods = 1.0;
            if self.device == DeviceChoice::Sim {
                // The simulated device stalls like a real one (issue 34): its plant advances only
                // per tick, but a loop that stops longer than the stall limit is a safety stop, so
                // `run --device sim` behaves as it will on hardware. Its signals still use one
                // period (the run stays deterministic when nothing stalls).
                self.system.check_stall(elapsed_ns as f64 * 1e-9, 0.0);
            }
            self.system.tick(q, None, false)
        } else {
            let own_ns = elapsed_ns.saturating_sub(wait_ns);
            self.elapsed_periods = own_ns as f64 / info.period_ns as f64;
            self.system
                .tick_timed(q, elapsed_ns as f64 * 1e-9, wait_ns as f64 * 1e-9)
        }
    }

    /// The watchdog's input for the tick `info` whose output is `out`: the real singularity margin
    /// and closure status of the tick, the loop's own interval in periods, the deadline flag and
    /// whether the device was lost (`lost`; the pose is then unknown and reported as zeros).
    pub fn safety_input(
        &self,
        info: &TickInfo,
        out: &TickOutput,
        lost: bool,
    ) -> SafetyInput<'static> {
        SafetyInput {
            deadline_missed: info.missed_deadline(),
            device_lost: lost,
            pose: if lost { [0.0; 3] } else { out.record.x_m },
            closure_fault: out.closure_fault,
            singularity_margin: if lost { 1.0 } else { out.margin },
            elapsed_periods: self.elapsed_periods,
            ..SafetyInput::nominal(info.index)
        }
    }

    fn sim(
        system: &HapticSystem,
        config: &HapticConfig,
        hand: &HandSpec,
        target: Option<&Arc<SharedTarget>>,
    ) -> Result<SimIo, String> {
        let (start, dt) = (system.device_start(), system.dt());
        let mut sim = SimIo::new(
            &config.device,
            start,
            hand.model(start),
            dt,
            plant_substeps(dt),
        )?;
        if let Some(t) = target {
            t.set(start);
            sim.follow(t.clone());
        }
        Ok(sim)
    }

    /// Rebuilds the system around `world` with the current settings (controller, passivity
    /// controller and estimator start from their reset states), and puts a simulated device back at
    /// rest at the start pose with the hand target there (a replay keeps playing; a real device
    /// stays open, and the new system aligns to the handle and ramps in from zero). On error nothing
    /// changes. Allocates: call it between ticks.
    pub fn rebuild(&mut self, world: World) -> Result<(), String> {
        self.check_released(&self.config, &world)?;
        let system = match &self.real {
            Some(l) => Self::real_system(world, &self.config, l)?,
            None => {
                let system = HapticSystem::with_safety(world, &self.config, sim_safety())?;
                if self.device == DeviceChoice::Sim {
                    self.io = Box::new(Self::sim(
                        &system,
                        &self.config,
                        &self.hand,
                        self.target.as_ref(),
                    )?);
                }
                DeviceSystem::Twin(system)
            }
        };
        self.system = system;
        self.interval.reset();
        self.grip.reset();
        Ok(())
    }

    /// Translation from handle coordinates to world coordinates (m): world = device + offset (the
    /// mapping has scale 1 in `haptic2d run`).
    pub fn device_to_world(&self) -> [f64; 2] {
        self.system.device_to_world()
    }

    /// Moves the hand target to the world pose `world` (m, m, rad), clamped to the device workspace
    /// square. Returns the target actually set, in world coordinates, or `None` (nothing done) when
    /// no hand follows a target. On a 2-DOF device (the real hand moves x and y) only the angle is
    /// used: it becomes the twist target of the slave's virtual torsion spring (the wheel / Q–E).
    pub fn set_hand_target(&mut self, world: V3) -> Option<V3> {
        if self.system.set_twist_target(Some(world[2])) {
            return Some(self.hand_target_world());
        }
        let t = self.target.as_ref()?;
        let map = self.system.twin()?.map();
        let p = &self.config.device;
        let mut d = map.pose_to_device(&world);
        let hw = p.workspace_half_width;
        d[0] = d[0].clamp(p.workspace_center_x - hw, p.workspace_center_x + hw);
        d[1] = d[1].clamp(p.workspace_center_y - hw, p.workspace_center_y + hw);
        t.set(d);
        Some(map.pose_to_world(&t.get()))
    }

    /// The hand target in world coordinates (m, m, rad), or, when no hand follows a target, where
    /// the handle is.
    pub fn hand_target_world(&self) -> V3 {
        match (&self.target, &self.system) {
            (Some(t), DeviceSystem::Twin(s)) => s.map().pose_to_world(&t.get()),
            // 2-DOF and point devices: the handle's x and y, and the twist target (else the
            // slave's angle).
            (_, DeviceSystem::TwoDof(_) | DeviceSystem::Point(_)) => {
                let h = self.system.handle_world();
                [h[0], h[1], self.system.twist_target().unwrap_or(h[2])]
            }
            _ => self.system.handle_world(),
        }
    }

    /// Switches the controller to `kind` (from the page), matched to a real device as at start;
    /// on error nothing changes.
    pub fn set_controller(&mut self, kind: ControllerKind) -> Result<(), String> {
        let k = match &self.match_controller {
            Some(m) => m(kind),
            None => kind,
        };
        let candidate = HapticConfig {
            controller: k,
            ..self.config.clone()
        };
        self.check_released(&candidate, self.system.world())?;
        self.system.set_controller(k)?;
        self.config.controller = k;
        Ok(())
    }

    /// Turns on the stability gate for a real device (`run` without `--allow-unstable`): from now on a
    /// controller or scene switch that the analysis finds unstable with the hand released is refused
    /// with the axis and the fix, and the loop keeps its current configuration. No effect on the
    /// simulation or a replay.
    pub fn enforce_released_stability(&mut self) {
        self.released_gate = self.real.is_some();
    }

    /// The gate of [`Self::enforce_released_stability`] for `config` on `world`.
    fn check_released(&self, config: &HapticConfig, world: &World) -> Result<(), String> {
        match (&self.real, self.released_gate) {
            (Some(l), true) => crate::cmd_stability::check_real_device(&l.model, config, world)
                .map_err(|e| format!("{e}\n    (refused: the loop keeps its current configuration; restart with --allow-unstable to override)")),
            _ => Ok(()),
        }
    }

    /// The twin pantograph's parameters when the display should draw the linkage (simulated device,
    /// replay, real twin); `None` for a 2-DOF device.
    pub fn twin_params(&self) -> Option<&DeviceParams> {
        self.system.twin().map(|_| &self.config.device)
    }
}

/// Why a real device's rig could not be built.
#[derive(Debug)]
pub enum RealOpenError {
    /// The configuration was rejected (bad input, exit 2).
    Config(String),
    /// The device could not be opened or did not answer (exit 4).
    Open(String),
}

/// Rigs and ticks the CLI's unit tests share.
#[cfg(test)]
pub(crate) mod test_rig {
    use super::*;

    /// The world of the built-in scene `box-in-walls` at 1 kHz.
    pub(crate) fn box_in_walls() -> World {
        let scene = haptic2d::scene::builtin("box-in-walls", Some(1000.0));
        scene.unwrap().unwrap().world
    }

    /// The simulated twin on `box-in-walls` at 1 kHz, the hand following its target.
    pub(crate) fn sim_rig() -> Rig {
        Rig::new(
            box_in_walls(),
            "box-in-walls",
            HapticConfig::default(),
            DeviceChoice::Sim,
            HandSpec::Follow,
        )
        .unwrap()
    }

    /// Tick `k` of a 1 kHz loop that is always on time (deadline `k` ms).
    pub(crate) fn tick_info(k: u64) -> TickInfo {
        TickInfo {
            index: k,
            deadline_index: k,
            t_s: k as f64 * 1e-3,
            period_s: 1e-3,
            period_ns: 1_000_000,
            lateness_ns: 0,
            skipped: 0,
            deadline_ns: k * 1_000_000,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::test_rig::{box_in_walls, sim_rig as rig, tick_info as info};
    use super::*;
    use haptic2d::device::pantograph2::Pantograph2;
    use haptic2d::haptic::WorkspaceSquare;
    use haptic2d_rt::Watchdog;

    /// Issue 11: `run` gave the watchdog a nominal singularity margin (1) and no closure fault.
    #[test]
    fn the_watchdog_gets_the_real_margin_and_closure_status() {
        let mut rig = rig();
        let mut dog = Watchdog::new(rig.watchdog_config()).unwrap();
        assert_eq!(rig.watchdog_config().min_singularity_margin, 0.1);
        let q = rig.io.read_encoders().unwrap();
        let out = rig.tick_system(&q, &info(0), false);
        let input = rig.safety_input(&info(0), &out, false);
        assert!(input.singularity_margin < 1.0 && input.singularity_margin > 0.1);
        assert_eq!(
            input.singularity_margin,
            rig.system.twin().unwrap().device().margin()
        );
        assert!(!input.closure_fault);
        let mut tau = out.torques;
        assert!(dog.guard(&input, &mut tau).is_ok());
        // A slipped cable on pantograph 2: the closure monitor fails, and the watchdog hears it.
        let mut bad = q;
        bad[2] += 0.05;
        let out = rig.tick_system(&bad, &info(1), false);
        let input = rig.safety_input(&info(1), &out, false);
        assert!(input.closure_fault);
        let f = dog.guard(&input, &mut tau).unwrap_err();
        assert_eq!(f.kind, haptic2d_rt::FaultKind::ClosureFault);
        assert_eq!(tau, [0.0; 4]);
    }

    #[test]
    fn a_simulated_device_is_paced_by_the_ticks() {
        let mut rig = rig();
        let cfg = rig.watchdog_config();
        assert_eq!(cfg.max_stall_periods, None);
        assert_eq!(cfg.max_missed_run, None);
        // A 15 ms gap (below the 40 ms stall limit): the simulated plant advanced one period, so
        // the tick uses one period and neither the system nor the watchdog sees a stall.
        let q = rig.io.read_encoders().unwrap();
        rig.tick_system(&q, &info(0), false);
        let out = rig.tick_system(&q, &info(15), false);
        assert!(!out.tripped);
        assert_eq!(
            rig.safety_input(&info(15), &out, false).elapsed_periods,
            1.0
        );
    }

    /// Issue 34 (build item 5): a 50 ms host stop on `--device sim` exited 0; the simulated device
    /// now latches like a real one: zero torques in the tick that sees the gap, the reason a stall
    /// of the host.
    #[test]
    fn a_simulated_device_latches_zero_torques_on_a_stalled_loop() {
        let mut rig = rig();
        let q = rig.io.read_encoders().unwrap();
        for k in 0..5 {
            assert!(!rig.tick_system(&q, &info(k), false).tripped);
        }
        let out = rig.tick_system(&q, &info(55), false);
        assert!(out.tripped);
        assert_eq!(out.torques, [0.0; 4]);
        let trip = rig.system.safety_trip().unwrap();
        match trip.reason {
            haptic2d::haptic::SafetyReason::Stall {
                elapsed,
                limit,
                device_wait,
            } => {
                assert!((elapsed - 0.051).abs() < 1e-12, "{elapsed}");
                assert!((limit - SIM_MIN_STALL_TIME).abs() < 1e-12, "{limit}");
                assert_eq!(device_wait, 0.0);
            }
            r => panic!("wrong reason {r:?}"),
        }
        let msg = trip.to_string();
        assert!(msg.contains("The host was late"), "{msg}");
    }

    /// A real 2-DOF device that answers at once, or after `wait` in the read of tick `slow_at`.
    struct FakeBoard {
        q: [f64; 2],
        reads: u64,
        slow_at: u64,
        wait: std::time::Duration,
        last: [f64; 4],
    }

    impl DeviceIo for FakeBoard {
        fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
            if self.reads == self.slow_at {
                std::thread::sleep(self.wait);
            }
            self.reads += 1;
            Ok([self.q[0], self.q[1], 0.0, 0.0])
        }
        fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
            self.last = *tau;
            Ok(())
        }
        fn zero_torques(&mut self) {
            self.last = [0.0; 4];
        }
        fn name(&self) -> &str {
            "fake-board"
        }
    }

    /// A rig on a fake gen 3 2DIY held at its workspace centre; the read of tick `slow_at` waits
    /// `wait`; the device's own timeout is `wait_periods`.
    fn board_rig(slow_at: u64, wait: std::time::Duration, wait_periods: f64) -> Rig {
        let linkage = Pantograph2::new(0.038, 0.07, 0.09).unwrap();
        let q = linkage.ik(haptic2d::geom::Vec2::new(0.019, 0.10)).unwrap();
        let real = RealDevice {
            name: "fake-board".into(),
            model: DeviceModel::FiveBar {
                linkage,
                tau_max: 0.123,
                center: [0.019, 0.10],
                workspace: WorkspaceSquare::around([0.019, 0.10], 0.03),
                identified: None,
            },
            summary: "a fake 2DIY".into(),
            wait_periods,
            max_missed_run: None,
            max_stall_periods: 5.0,
            safety: DeviceSafety::default(),
            match_controller: None,
            open: Box::new(move |_| {
                Ok(Box::new(FakeBoard {
                    q,
                    reads: 0,
                    slow_at,
                    wait,
                    last: [0.0; 4],
                }) as Box<dyn DeviceIo + Send>)
            }),
        };
        fake_board_rig(real)
    }

    /// The rig of `haptic2d run` on the built-in `box-in-walls` scene at 1 kHz, default settings,
    /// driving the (fake) Haply board `real`.
    fn fake_board_rig(real: RealDevice) -> Rig {
        Rig::with_real(
            box_in_walls(),
            "box-in-walls",
            HapticConfig::default(),
            DeviceChoice::Haply("fake".into()),
            real,
        )
        .unwrap()
    }

    /// A 2-DOF device whose joint 0 turns `step` rad per read from its workspace centre (or, a point
    /// device, whose x moves `step` m per read).
    struct MovingBoard {
        q: [f64; 2],
        step: f64,
    }

    impl DeviceIo for MovingBoard {
        fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
            self.q[0] += self.step;
            Ok([self.q[0], self.q[1], 0.0, 0.0])
        }
        fn write_torques(&mut self, _tau: &[f64; 4]) -> Result<(), DeviceError> {
            Ok(())
        }
        fn zero_torques(&mut self) {}
        fn name(&self) -> &str {
            "moving-board"
        }
    }

    /// `shipped` (a file of devices/) with its `[safety]` lines edited by `edit`, in `dir`.
    fn safety_file(
        dir: &std::path::Path,
        shipped: &str,
        edit: impl Fn(String) -> String,
    ) -> std::path::PathBuf {
        let text = std::fs::read_to_string(format!(
            "{}/../../devices/{shipped}",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap();
        let p = dir.join(shipped);
        std::fs::write(&p, edit(text)).unwrap();
        p
    }

    /// Ticks the real device `real` (its I/O replaced by a board turning joint 0 at 10 rad/s, or a
    /// point device moving at 10 m/s, far below the default bound of 1000 rad/s or m/s) for 20 ms;
    /// returns the trip, if any. The point starts 0.1 m left of its square's centre, so that its
    /// 0.2 m stay inside the square.
    fn run_at_10_per_s(real: RealDevice) -> Option<haptic2d::haptic::SafetyTrip> {
        let mut real = real;
        let q = match &real.model {
            DeviceModel::FiveBar {
                linkage, center, ..
            } => linkage
                .ik(haptic2d::geom::Vec2::new(center[0], center[1]))
                .unwrap(),
            DeviceModel::Point { workspace, .. } => {
                [workspace.centre[0] - 0.1, workspace.centre[1]]
            }
            DeviceModel::Twin(_) => panic!("a 2-DOF or point device"),
        };
        real.open = Box::new(move |_| Ok(Box::new(MovingBoard { q, step: 0.01 }) as _));
        let mut rig = fake_board_rig(real);
        for k in 0..20 {
            let q = rig.read().unwrap();
            rig.tick_system(&q, &info(k), false);
        }
        rig.system.safety_trip()
    }

    /// Issue 38 item 6, issue 34: the device file's `[safety] max_velocity` reaches the system of
    /// every device kind. 10 rad/s (m/s on a point device) passes the default bound and trips a
    /// file's 5, which the trip names; the file's `stall_floor` sets the watchdog's floor.
    fn a_file_velocity_bound_is_honoured(
        load: impl Fn(&std::path::Path) -> RealDevice,
        shipped: &str,
    ) {
        let dir = tempfile::tempdir().unwrap();
        let plain = safety_file(dir.path(), shipped, |t| t);
        assert_eq!(run_at_10_per_s(load(&plain)), None, "{shipped}");
        // Whatever bound the shipped file sets (rad/s on a linkage, m/s on the Inverse3), 5.
        let tight = safety_file(dir.path(), shipped, |t| {
            t.lines()
                .map(|l| match l.split_once('=') {
                    Some((k, _)) if k.trim() == "max_velocity" => "max_velocity = 5.0".to_string(),
                    _ => l.to_string(),
                })
                .collect::<Vec<_>>()
                .join("\n")
                .replace("stall_floor = 0.02 ", "stall_floor = 0.1 ")
        });
        let real = load(&tight);
        assert_eq!(real.safety.stall_floor, 0.1);
        let trip = run_at_10_per_s(real).expect("a trip");
        match trip.reason {
            haptic2d::haptic::SafetyReason::JointSpeed { index, limit, .. } => {
                assert_eq!((index, limit), (0, 5.0), "{trip}")
            }
            r => panic!("{shipped}: wrong reason {r:?}"),
        }
        // The stall floor (0.1 s = 100 periods at 1 kHz) is the watchdog's too.
        let mut real = load(&tight);
        real.open = Box::new(|_| {
            Ok(Box::new(MovingBoard {
                q: [0.0; 2],
                step: 0.0,
            }) as _)
        });
        let rig = fake_board_rig(real);
        let stall = rig.watchdog_config().max_stall_periods.unwrap();
        assert!((stall - 100.0).abs() < 1e-9, "{stall}");
    }

    #[test]
    fn a_haply_file_velocity_bound_and_stall_floor_are_honoured() {
        a_file_velocity_bound_is_honoured(
            |p| haptic2d_devices::registry::haply::real_device("/dev/null", Some(p)).unwrap(),
            "haply-2diy-gen3.toml",
        );
    }

    #[test]
    fn a_udp_file_velocity_bound_and_stall_floor_are_honoured() {
        a_file_velocity_bound_is_honoured(
            |p| {
                haptic2d_devices::registry::udp::real_device("127.0.0.1:5005", Some(p), false)
                    .unwrap()
            },
            "udp-pantograph.toml",
        );
    }

    #[test]
    #[cfg(feature = "inverse3")]
    fn an_inverse3_file_velocity_bound_and_stall_floor_are_honoured() {
        a_file_velocity_bound_is_honoured(
            |p| haptic2d_devices::registry::inverse3::real_device(None, Some(p)).unwrap(),
            "inverse3.toml",
        );
    }

    /// One tick of the loop's order (read, system, watchdog) at `info`; the torques as guarded.
    fn guarded_tick(
        rig: &mut Rig,
        dog: &mut Watchdog,
        info: &TickInfo,
    ) -> (TickOutput, [f64; 4], Result<(), haptic2d_rt::Fault>) {
        let q = rig.read().unwrap();
        let out = rig.tick_system(&q, info, false);
        let mut tau = out.torques;
        let g = dog.guard(&rig.safety_input(info, &out, false), &mut tau);
        (out, tau, g)
    }

    /// Task L item 2: a stalled loop (the tick wakes 30 periods after the previous one, no wait
    /// for the device) latches zero torques within that tick, and says why.
    #[test]
    fn a_stalled_loop_latches_zero_torques_within_the_tick_with_its_reason() {
        let mut rig = board_rig(u64::MAX, std::time::Duration::ZERO, 3.0);
        let cfg = rig.watchdog_config();
        assert_eq!(cfg.max_stall_periods, Some(20.0));
        let mut dog = Watchdog::new(cfg).unwrap();
        for k in 0..10 {
            let (out, _, g) = guarded_tick(&mut rig, &mut dog, &info(k));
            assert!(g.is_ok() && !out.tripped, "tick {k}");
        }
        // The loop itself was away: the watchdog sees 30 periods on the loop's own account (its
        // limit: the file's 5 periods, at least the shared 20 ms).
        let (out, tau, g) = guarded_tick(&mut rig, &mut dog, &info(39));
        let f = g.unwrap_err();
        assert!(
            matches!(f.kind, haptic2d_rt::FaultKind::Stall { .. }),
            "{f}"
        );
        assert!(f.to_string().contains("stalled"), "{f}");
        assert_eq!(tau, [0.0; 4]);
        // And the system's own latch (limit max(5 + 3 periods, 20 ms), wake to wake) agrees, with its
        // reason.
        assert!(out.tripped && out.torques == [0.0; 4]);
        let trip = rig.system.safety_trip().unwrap();
        assert!(
            matches!(trip.reason, haptic2d::haptic::SafetyReason::Stall { .. }),
            "{trip}"
        );
    }

    /// Task L item 2: a device slow to answer (20 ms in one read, within its own timeout) is not a
    /// stall of the loop: the wait is left to the driver's timeout (a lost device, exit 4).
    #[test]
    fn a_slow_device_within_its_timeout_is_not_a_loop_stall() {
        let mut rig = board_rig(5, std::time::Duration::from_millis(20), 30.0);
        let mut dog = Watchdog::new(rig.watchdog_config()).unwrap();
        for k in 0..6 {
            let (out, _, g) = guarded_tick(&mut rig, &mut dog, &info(k));
            assert!(g.is_ok() && !out.tripped, "tick {k}");
        }
        // The tick after the slow read wakes 21 periods after the previous one.
        let (out, _, g) = guarded_tick(&mut rig, &mut dog, &info(26));
        assert!(g.is_ok(), "{g:?}");
        assert!(!out.tripped, "{:?}", rig.system.safety_trip());
        assert!(rig.elapsed_periods < 5.0, "{}", rig.elapsed_periods);
    }

    #[test]
    fn a_real_2dof_rig_starts_at_zero_torque_and_has_no_twin_drawing() {
        let mut rig = board_rig(u64::MAX, std::time::Duration::ZERO, 3.0);
        let q = rig.read().unwrap();
        let out = rig.tick_system(&q, &info(0), false);
        assert_eq!(out.torques, [0.0; 4]);
        assert!(rig.twin_params().is_none() && rig.system.twin_kinematics().is_none());
        assert!(rig.target.is_none());
        // The page's wheel / Q–E: only the angle is used, as the slave's twist target.
        let set = rig
            .set_hand_target([9.0, 9.0, 0.3])
            .expect("a 2-DOF rig takes the angle");
        assert_eq!(set[2], 0.3);
        assert_ne!(set[0], 9.0, "x and y stay the handle's");
        match &rig.system {
            DeviceSystem::TwoDof(s) => assert_eq!(s.twist_target(), Some(0.3)),
            _ => unreachable!(),
        }
        assert_eq!(rig.hand_target_world()[2], 0.3);
        // A rebuild (the page's reset) keeps the device and starts a fresh 2-DOF system.
        rig.rebuild(box_in_walls()).unwrap();
        assert!(matches!(rig.system, DeviceSystem::TwoDof(_)));
        assert_eq!(rig.io.name(), "fake-board");
    }

    /// What a fake point device reports: the handle point (m) and the grip angle (rad), and the
    /// force (N) the rig last wrote.
    #[derive(Default)]
    struct PointState {
        point: [f64; 2],
        angle: Option<f64>,
        force: [f64; 4],
    }

    /// A Cartesian point device (an Inverse3 in planar mode, faked): `q = [x, y, 0, 0]` (m).
    struct FakePoint(Arc<std::sync::Mutex<PointState>>);

    impl DeviceIo for FakePoint {
        fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
            let p = self.0.lock().unwrap().point;
            Ok([p[0], p[1], 0.0, 0.0])
        }
        fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
            self.0.lock().unwrap().force = *tau;
            Ok(())
        }
        fn zero_torques(&mut self) {
            self.0.lock().unwrap().force = [0.0; 4];
        }
        fn name(&self) -> &str {
            "fake-point"
        }
        fn handle_angle(&self) -> Option<f64> {
            self.0.lock().unwrap().angle
        }
    }

    /// A rig on a fake point device (force limit 5 N, square (0, 0) ± 0.15 m, the Inverse3's gate
    /// dynamics) resting at (0.01, −0.02) m, with the coupling controller and no start-up ramp.
    fn point_rig() -> (Rig, Arc<std::sync::Mutex<PointState>>) {
        let state = Arc::new(std::sync::Mutex::new(PointState {
            point: [0.01, -0.02],
            ..PointState::default()
        }));
        let shared = state.clone();
        let real = RealDevice {
            name: "fake-point".into(),
            model: DeviceModel::Point {
                force_limit: 5.0,
                workspace: WorkspaceSquare::around([0.0, 0.0], 0.15),
                gate_dynamics: haptic2d_devices::registry::inverse3::GATE_DYNAMICS,
            },
            summary: "a fake point device".into(),
            wait_periods: 20.0,
            max_missed_run: None,
            max_stall_periods: 5.0,
            safety: DeviceSafety::default(),
            match_controller: None,
            open: Box::new(move |_| Ok(Box::new(FakePoint(shared)) as Box<dyn DeviceIo + Send>)),
        };
        let config = HapticConfig {
            controller: ControllerKind::from_name("coupling").unwrap(),
            ..HapticConfig::default()
        };
        let rig = Rig::with_real(
            box_in_walls(),
            "box-in-walls",
            config,
            DeviceChoice::Inverse3(None),
            real,
        )
        .unwrap();
        (rig, state)
    }

    /// Issue 37 item 1: a point device (the Inverse3) runs on the point system, not through a
    /// virtual linkage: the first tick's force is zero, the force then follows the handle (the
    /// coupling pulls it back towards the slave it anchored to) within the 5 N limit, and a
    /// rebuild (the page's reset) keeps the point system.
    #[test]
    fn a_real_point_rig_drives_a_point_system_from_zero_force() {
        let (mut rig, state) = point_rig();
        assert!(matches!(rig.system, DeviceSystem::Point(_)));
        assert!(rig.twin_params().is_none() && rig.system.twin_kinematics().is_none());
        assert_eq!(rig.watchdog_config().min_singularity_margin, 0.0);
        let q = rig.read().unwrap();
        assert_eq!(q, [0.01, -0.02, 0.0, 0.0]);
        let out = rig.tick_system(&q, &info(0), false);
        assert_eq!(out.torques, [0.0; 4], "anchored at the first reading");
        // The handle 5 mm to the right of where it anchored, the slave at rest: the coupling pulls
        // it back (−x), the ramp (0.5 s by default) growing.
        state.lock().unwrap().point = [0.015, -0.02];
        let mut last = 0.0;
        for k in 1..400 {
            let q = rig.read().unwrap();
            let out = rig.tick_system(&q, &info(k), false);
            assert!(!out.tripped, "{:?}", rig.system.safety_trip());
            assert!(out.torques[0].hypot(out.torques[1]) <= 5.0 + 1e-12);
            assert_eq!(out.torques[2..], [0.0; 2]);
            last = out.torques[0];
        }
        assert!(last < -0.1, "pulled back: {last} N");
        rig.rebuild(box_in_walls()).unwrap();
        assert!(matches!(rig.system, DeviceSystem::Point(_)));
        assert_eq!(rig.io.name(), "fake-point");
    }

    /// The VerseGrip's angle turns the slave's twist target on a point device as on a 2DIY
    /// (anchored at the first reading), and the page's wheel sets it too.
    #[test]
    fn a_point_devices_grip_angle_turns_the_slave() {
        let (mut rig, state) = point_rig();
        let theta0 = rig.system.world().bodies[rig.system.slave()].pose.angle;
        state.lock().unwrap().angle = Some(0.2);
        let q = rig.read().unwrap();
        rig.tick_system(&q, &info(0), false);
        assert_eq!(rig.system.twist_target(), Some(theta0));
        state.lock().unwrap().angle = Some(0.5);
        rig.tick_system(&q, &info(1), false);
        let t = rig.system.twist_target().unwrap();
        assert!((t - (theta0 + 0.3)).abs() < 1e-12, "{t}");
        let set = rig.set_hand_target([9.0, 9.0, -0.4]).unwrap();
        assert_eq!(set[2], -0.4);
        assert_ne!(set[0], 9.0, "x and y stay the handle's");
    }

    /// The workspace bound of the device file reaches a point device in the rig: a handle carried
    /// past the square's trip distance latches zero force within the tick, with its reason.
    #[test]
    fn a_point_device_past_its_square_latches_zero_force_in_the_rig() {
        let (mut rig, state) = point_rig();
        let q = rig.read().unwrap();
        rig.tick_system(&q, &info(0), false);
        // 0.15 m half-width, 10 mm trip distance: 0.17 m is past it. Walk there at 1 m/s (below
        // the speed bound) so that only the square can trip.
        let mut tripped = None;
        for k in 1..200u64 {
            let x = (0.01 + 0.001 * k as f64).min(0.17);
            state.lock().unwrap().point = [x, -0.02];
            let q = rig.read().unwrap();
            let out = rig.tick_system(&q, &info(k), false);
            if out.tripped {
                assert_eq!(out.torques, [0.0; 4]);
                tripped = Some(x);
                break;
            }
        }
        let x = tripped.expect("the square trips");
        // The first reading at the trip distance (0.16 m, up to rounding) or past it, not before.
        assert!(x > 0.16 - 1e-9 && x < 0.1615, "tripped at {x} m");
        let trip = rig.system.safety_trip().unwrap();
        assert!(
            matches!(
                trip.reason,
                haptic2d::haptic::SafetyReason::Workspace { axis: 0, .. }
            ),
            "{trip}"
        );
    }

    /// The released-handle stability gate refuses to switch `rig` to `spec`, naming the unstable
    /// axis (x) and the way around it.
    fn assert_gate_refuses(rig: &mut Rig, spec: ControllerKind) {
        let e = rig
            .set_controller(spec)
            .expect_err("the gate refuses the switch");
        assert!(
            e.contains("axis x") && e.contains("--allow-unstable"),
            "{e}"
        );
    }

    /// The released-handle stability gate applies to a point device, linearised with the
    /// Inverse3's gate dynamics: the spec's four-channel gains are refused, the default passes.
    #[test]
    fn display_controller_switch_on_a_point_device_passes_the_released_stability_gate() {
        let (mut rig, _) = point_rig();
        rig.enforce_released_stability();
        let spec = ControllerKind::from_name("four-channel-spec").unwrap();
        assert_gate_refuses(&mut rig, spec);
        rig.set_controller(ControllerKind::default()).unwrap();
    }

    /// Issue 11 (noticed in session 5): the display's controller switch skipped the released-handle
    /// stability gate that `run` applies at start, so a page could switch a real device to the
    /// spec's four-channel gains, unstable when the hand lets go. With the gate on, a switch the
    /// analysis refuses leaves the controller as it was; a stable one goes through.
    #[test]
    fn display_controller_switch_on_a_real_device_passes_the_released_stability_gate() {
        let mut rig = board_rig(u64::MAX, std::time::Duration::ZERO, 3.0);
        rig.enforce_released_stability();
        let before = rig.config.controller.name();
        let spec = ControllerKind::from_name("four-channel-spec").unwrap();
        let cfg = HapticConfig {
            controller: spec,
            ..rig.config.clone()
        };
        let verdict = match &rig.real {
            Some(l) => crate::cmd_stability::check_real_device(&l.model, &cfg, rig.system.world()),
            None => unreachable!("a board rig is real"),
        };
        assert!(
            verdict.is_err(),
            "premise: the spec gains are unstable released here"
        );
        assert_gate_refuses(&mut rig, spec);
        assert_eq!(rig.config.controller.name(), before, "refused: unchanged");
        // The default (stable released, by the analysis) is accepted.
        rig.set_controller(ControllerKind::default()).unwrap();
        // Without the gate (the simulation, or --allow-unstable) the switch is not analysed.
        let mut free = board_rig(u64::MAX, std::time::Duration::ZERO, 3.0);
        free.set_controller(spec).unwrap();
        assert_eq!(free.config.controller.name(), "four-channel-spec");
    }
}
