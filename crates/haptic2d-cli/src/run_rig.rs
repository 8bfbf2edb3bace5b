//! The rig of `haptic2d run`: the haptic system (device estimator, controller, world) and the device
//! it drives (simulated twin pantograph with a simulated hand, or a replay), built from a scene's
//! world and rebuilt when the live display resets or switches the scene.

use crate::hand_arg::HandSpec;
use haptic2d::device::linalg::{V3, V4};
use haptic2d::haptic::{HapticConfig, HapticSystem, TickOutput};
use haptic2d::world::World;
use haptic2d_rt::io::DEFAULT_REPLAY_COLUMNS;
use haptic2d_rt::{
    DeviceIo, ReplayDevice, ReplayEnd, SafetyInput, SharedTarget, SimIo, TickInfo, TickInterval,
    WatchdogConfig,
};
use std::path::PathBuf;
use std::sync::Arc;

/// The device the loop drives.
#[derive(Clone, Debug, PartialEq)]
pub enum DeviceChoice {
    /// The simulated twin pantograph, pushed by the simulated hand.
    Sim,
    /// Recorded encoder angles `q1..q4` (rad) played back from a CSV file, or the encoders of an
    /// MCAP tick log (`.mcap`).
    Replay(PathBuf),
}

impl DeviceChoice {
    /// Parses `--device`: `sim` or `replay:FILE.csv`; the error says how to fix it.
    pub fn parse(s: &str) -> Result<Self, String> {
        if s == "sim" {
            return Ok(DeviceChoice::Sim);
        }
        if let Some(f) = s.strip_prefix("replay:") {
            if f.is_empty() {
                return Err("--device replay:FILE.csv needs a file name".into());
            }
            return Ok(DeviceChoice::Replay(PathBuf::from(f)));
        }
        Err(format!(
            "--device `{s}` is not available\n    fix: use --device sim (the simulated twin pantograph) or --device replay:FILE.csv"
        ))
    }
}

/// RK4 sub-steps of the simulated plant per tick: one per 0.5 ms of period (at least one).
fn plant_substeps(dt: f64) -> u32 {
    ((dt / 0.0005).ceil() as u32).max(1)
}

/// The haptic system and its device, owned by the loop thread.
pub struct Rig {
    /// Device estimator, controller, passivity controller and world.
    pub system: HapticSystem,
    /// The device I/O.
    pub io: Box<dyn DeviceIo + Send>,
    /// The settings the system was built with; `controller` follows the page's selection.
    pub config: HapticConfig,
    /// Which device.
    pub device: DeviceChoice,
    /// What the simulated hand does (simulated device only).
    pub hand: HandSpec,
    /// The target a `follow` hand pulls the handle towards (m, m, rad, handle coordinates): set by
    /// the page's pointer. `None` for any other hand or device.
    pub target: Option<Arc<SharedTarget>>,
    /// Measures the interval between ticks (wake to wake).
    interval: TickInterval,
    /// The last tick's interval, in periods (1 for a device paced by the ticks).
    elapsed_periods: f64,
}

impl Rig {
    /// Builds the system around `world` (of the scene loaded from `source`, named in errors) and
    /// opens the device. The simulated device starts at rest at the system's start pose; a `follow`
    /// hand holds it there until the target moves.
    pub fn new(
        world: World,
        source: &str,
        config: HapticConfig,
        device: DeviceChoice,
        hand: HandSpec,
    ) -> Result<Self, String> {
        let system =
            HapticSystem::new(world, &config).map_err(|e| format!("scene {source}: {e}"))?;
        let target = (device == DeviceChoice::Sim && hand == HandSpec::Follow)
            .then(|| Arc::new(SharedTarget::new(system.device_start())));
        let io: Box<dyn DeviceIo + Send> = match &device {
            DeviceChoice::Sim => Box::new(Self::sim(&system, &config, &hand, target.as_ref())?),
            DeviceChoice::Replay(p) if crate::run_log::is_mcap(p) => Box::new(
                haptic2d_rt::mcap::McapReplay::from_path(p, ReplayEnd::Error)?,
            ),
            DeviceChoice::Replay(p) => Box::new(ReplayDevice::from_path(
                p,
                DEFAULT_REPLAY_COLUMNS,
                ReplayEnd::Error,
            )?),
        };
        Ok(Self {
            system,
            io,
            config,
            device,
            hand,
            target,
            interval: TickInterval::new(),
            elapsed_periods: 1.0,
        })
    }

    /// The watchdog's thresholds for this rig: the device file's singularity margin always; for a
    /// real device also the stall limit of the tick's safety settings and 10 consecutive missed
    /// deadlines. A device paced by the ticks (the simulated plant, a replay) does not move between
    /// ticks, so a late tick cannot hurt anyone: stalls and misses are counted in the timing summary
    /// but do not stop the run.
    pub fn watchdog_config(&self) -> WatchdogConfig {
        let real = !self.io.paced_by_ticks();
        WatchdogConfig {
            min_singularity_margin: self.config.device.min_singularity_margin,
            max_missed_run: real.then_some(10),
            max_stall_periods: real.then_some(self.system.safety_config().max_stall_periods),
        }
    }

    /// One tick of the system on encoder angles `q` (rad), `paused` or running. A real device gets
    /// the measured interval since the previous tick (the system differentiates over it and trips
    /// on a stall); a device paced by the ticks gets one period. Never allocates.
    pub fn tick_system(&mut self, q: &V4, info: &TickInfo, paused: bool) -> TickOutput {
        let elapsed_ns = self.interval.update(info);
        if paused {
            self.elapsed_periods = 1.0;
            self.system.tick_paused(q)
        } else if self.io.paced_by_ticks() {
            self.elapsed_periods = 1.0;
            self.system.tick(q)
        } else {
            self.elapsed_periods = elapsed_ns as f64 / info.period_ns as f64;
            let elapsed_s = elapsed_ns as f64 * 1e-9;
            self.system.tick_elapsed(q, elapsed_s)
        }
    }

    /// The watchdog's input for the tick `info` whose output is `out`: the real singularity margin
    /// and closure status of the tick, the interval in periods, the deadline flag and whether the
    /// device was lost (`lost`; the pose is then unknown and reported as zeros).
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
    /// rest at the start pose with the hand target there (a replay keeps playing). On error nothing
    /// changes. Allocates: call it between ticks.
    pub fn rebuild(&mut self, world: World) -> Result<(), String> {
        let system = HapticSystem::new(world, &self.config)?;
        if self.device == DeviceChoice::Sim {
            self.io = Box::new(Self::sim(
                &system,
                &self.config,
                &self.hand,
                self.target.as_ref(),
            )?);
        }
        self.system = system;
        self.interval.reset();
        Ok(())
    }

    /// Translation from handle coordinates to world coordinates (m): world = device + offset (the
    /// mapping has scale 1 in `haptic2d run`).
    pub fn device_to_world(&self) -> [f64; 2] {
        let m = self.system.map();
        [
            m.world_origin[0] - m.device_origin[0],
            m.world_origin[1] - m.device_origin[1],
        ]
    }

    /// Moves the hand target to the world pose `world` (m, m, rad), clamped to the device workspace
    /// square. Returns the target actually set, in world coordinates, or `None` (nothing done) when
    /// no hand follows a target.
    pub fn set_hand_target(&self, world: V3) -> Option<V3> {
        let t = self.target.as_ref()?;
        let map = self.system.map();
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
        let map = self.system.map();
        match &self.target {
            Some(t) => map.pose_to_world(&t.get()),
            None => map.pose_to_world(&self.system.last_record().x_m),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic2d::scene::builtin;
    use haptic2d_rt::Watchdog;

    fn rig() -> Rig {
        let scene = builtin("box-in-walls", Some(1000.0)).unwrap().unwrap();
        Rig::new(
            scene.world,
            "box-in-walls",
            HapticConfig::default(),
            DeviceChoice::Sim,
            HandSpec::Follow,
        )
        .unwrap()
    }

    fn info(k: u64) -> TickInfo {
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
        assert_eq!(input.singularity_margin, rig.system.device().margin());
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
        // A 50 ms gap: the simulated plant advanced one period, so the tick uses one period and
        // neither the system nor the watchdog sees a stall.
        let q = rig.io.read_encoders().unwrap();
        rig.tick_system(&q, &info(0), false);
        let out = rig.tick_system(&q, &info(50), false);
        assert!(!out.tripped);
        assert_eq!(
            rig.safety_input(&info(50), &out, false).elapsed_periods,
            1.0
        );
    }
}
