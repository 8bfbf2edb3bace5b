//! The rig of `haptic2d run`: the haptic system (device estimator, controller, world) and the device
//! it drives (simulated twin pantograph with a simulated hand, or a replay), built from a scene's
//! world and rebuilt when the live display resets or switches the scene.

use crate::hand_arg::HandSpec;
use haptic2d::device::linalg::V3;
use haptic2d::haptic::{HapticConfig, HapticSystem};
use haptic2d::world::World;
use haptic2d_rt::io::DEFAULT_REPLAY_COLUMNS;
use haptic2d_rt::{DeviceIo, ReplayDevice, ReplayEnd, SharedTarget, SimIo};
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
        })
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
