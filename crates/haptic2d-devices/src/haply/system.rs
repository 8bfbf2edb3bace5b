//! [`HaplySystem`]: the haptic system a Haply device drives — the 2-DOF system for a 2DIY
//! ([`Planar2System`], the device holding the slave at a grasp point), or the twin-pantograph
//! [`HapticSystem`] with the Haply geometry of the device file. Built once, before the loop.

use haptic2d::device::linalg::V4;
use haptic2d::haptic::planar2::{Planar2Config, Planar2System};
use haptic2d::haptic::{ControllerKind, HapticConfig, HapticSystem, TickRecord};
use haptic2d::world::World;

use super::device_file::{HaplyDeviceFile, HaplyKind};

/// The system behind a Haply device.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)]
pub enum HaplySystem {
    /// One 2DIY: x and y of the grasp point; rotation left to the world.
    TwoDof(Planar2System),
    /// The twin pantograph: x, y and θ (MODELS §10–§11).
    Twin(HapticSystem),
}

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
        match &file.kind {
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
                c.workspace = haptic2d::haptic::WorkspaceSquare::around(*center, *half_width);
                Ok(HaplySystem::TwoDof(Planar2System::new(world, c)?))
            }
            HaplyKind::Twin(p) => {
                let config = HapticConfig {
                    device: *p,
                    controller: file.controller_for(controller),
                    ..HapticConfig::default()
                };
                Ok(HaplySystem::Twin(HapticSystem::new(world, &config)?))
            }
        }
    }

    /// One tick from the joint angles `q` (rad, joint order). Never allocates.
    pub fn tick(&mut self, q: &V4) -> HaplyTick {
        match self {
            HaplySystem::TwoDof(s) => {
                let o = s.tick(&[q[0], q[1]]);
                HaplyTick {
                    torques: o.record.tau,
                    tripped: o.tripped,
                    record: o.record,
                }
            }
            HaplySystem::Twin(s) => {
                let o = s.tick(q);
                HaplyTick {
                    torques: o.torques,
                    tripped: o.tripped,
                    record: o.record,
                }
            }
        }
    }

    /// The handle position of `record` in world coordinates (m): the 2-DOF record holds it already;
    /// the twin's record holds the device pose, mapped here.
    pub fn handle_world(&self, record: &TickRecord) -> [f64; 2] {
        match self {
            HaplySystem::TwoDof(_) => [record.x_m[0], record.x_m[1]],
            HaplySystem::Twin(s) => {
                let w = s.map().pose_to_world(&record.x_m);
                [w[0], w[1]]
            }
        }
    }

    /// The latched safety trip, as text.
    pub fn trip(&self) -> Option<String> {
        match self {
            HaplySystem::TwoDof(s) => s.safety_trip().map(|t| t.to_string()),
            HaplySystem::Twin(s) => s.safety_trip().map(|t| t.to_string()),
        }
    }

    /// The world.
    pub fn world(&self) -> &World {
        match self {
            HaplySystem::TwoDof(s) => s.world(),
            HaplySystem::Twin(s) => s.world(),
        }
    }

    /// Index of the slave body.
    pub fn slave(&self) -> usize {
        match self {
            HaplySystem::TwoDof(s) => s.slave(),
            HaplySystem::Twin(s) => s.slave(),
        }
    }
}
