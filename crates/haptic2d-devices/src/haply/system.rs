//! [`HaplySystem`]: the haptic system a Haply device drives — the core's one [`DeviceSystem`]: the
//! 2-DOF system for a 2DIY ([`Planar2System`], the device holding the slave at a grasp point), or
//! the twin-pantograph [`HapticSystem`] with the Haply geometry of the device file. Built once,
//! before the loop; this file only builds it from the device file and shapes one tick's output.

use haptic2d::device::linalg::V4;
use haptic2d::haptic::planar2::{Planar2Config, Planar2System};
use haptic2d::haptic::{
    ControllerKind, DeviceSystem, HapticConfig, HapticSystem, TickRecord, WorkspaceSquare,
};
use haptic2d::world::World;

use super::device_file::{HaplyDeviceFile, HaplyKind};

/// The system behind a Haply device (a [`DeviceSystem`] built from a Haply device file).
#[derive(Clone, Debug)]
pub struct HaplySystem(pub DeviceSystem);

/// One tick's output, in the shape the loop needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HaplyTick {
    /// Joint torques in joint order (N·m); a 2DIY fills the first two.
    pub torques: V4,
    /// True once the system's safety latch is set.
    pub tripped: bool,
    /// The telemetry record.
    pub record: TickRecord,
}

impl HaplySystem {
    /// The system for device file `file` around `world` (its period is the tick period), with
    /// `controller`; `grasp` (m, body frame) is the 2DIY's grasp point on the slave. Errors name the
    /// setting.
    pub fn new(
        world: World,
        file: &HaplyDeviceFile,
        controller: ControllerKind,
        grasp: [f64; 2],
    ) -> Result<Self, String> {
        Ok(HaplySystem(match &file.kind {
            HaplyKind::TwoDiy {
                linkage,
                center,
                half_width,
            } => {
                let mut c = Planar2Config::new(*linkage, file.torque_limit);
                c.controller = controller;
                c.grasp = grasp;
                // The device file's workspace square: the passive wall near its edge and the trip
                // beyond it, as on every device (the same square `haptic2d run` gives the 2DIY).
                c.workspace = WorkspaceSquare::around(*center, *half_width);
                DeviceSystem::TwoDof(Planar2System::new(world, c)?)
            }
            HaplyKind::Twin(p) => {
                let config = HapticConfig {
                    device: *p,
                    controller: file.controller_for(controller),
                    ..HapticConfig::default()
                };
                DeviceSystem::Twin(HapticSystem::new(world, &config)?)
            }
        }))
    }

    /// One tick from the joint angles `q` (rad, joint order), taken on time. Never allocates.
    pub fn tick(&mut self, q: &V4) -> HaplyTick {
        let o = self.0.tick(q, None, false);
        HaplyTick {
            torques: o.torques,
            tripped: o.tripped,
            record: o.record,
        }
    }

    /// The handle position of `record` in world coordinates (m).
    pub fn handle_world(&self, record: &TickRecord) -> [f64; 2] {
        let w = self.0.handle_world_of(record);
        [w[0], w[1]]
    }

    /// The latched safety trip, as text.
    pub fn trip(&self) -> Option<String> {
        self.0.safety_trip().map(|t| t.to_string())
    }

    /// The world.
    pub fn world(&self) -> &World {
        self.0.world()
    }

    /// Index of the slave body.
    pub fn slave(&self) -> usize {
        self.0.slave()
    }
}
