//! [`DeviceSystem`]: the haptic system for either kind of device — the twin pantograph (4 joints,
//! x, y, θ: [`HapticSystem`], MODELS §10–§11; the simulated device, a replay, the Haply twin) or a
//! 2-DOF five-bar (2 joints, x and y of a grasp point: [`Planar2System`]; a Haply 2DIY, a UDP
//! five-bar, the Inverse3). Both are [`Haptic`](super::Haptic) over their device coupling and run
//! the same tick ([`Haptic::haptic_tick`](super::Haptic::haptic_tick)); the enum only routes the
//! joint reading to the right device. The one enum every front end drives (the rig of `haptic2d
//! run`, the Haply closed loop of `haptic2d-devices`): the loop, the watchdog, the logs and the
//! display see one interface; each method says what the 2-DOF form does differently.

use crate::control::passivity::PlanarPassivity;
use crate::device::linalg::{V3, V4};
use crate::device::TwinKinematics;
use crate::world::World;

use super::config::ControllerKind;
use super::planar2::Planar2System;
use super::record::TickRecord;
use super::safety::SafetyTrip;
use super::system::HapticSystem;
use super::tick::TickOutput;

/// The system a device drives.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)]
pub enum DeviceSystem {
    /// The twin pantograph: x, y and θ.
    Twin(HapticSystem),
    /// A 2-DOF five-bar holding the slave at a grasp point: x and y; the rotation is left to the
    /// world. Joints `q[0..2]`, torques `τ[0..2]` (`τ[2..4]` always zero).
    TwoDof(Planar2System),
}

impl DeviceSystem {
    /// One tick on joint angles `q` (rad) taken `elapsed` s after the previous tick (the interval
    /// the device's signals are differentiated over; `None`: one period, a device paced by the
    /// ticks), or a paused tick. Never allocates.
    #[inline]
    pub fn tick(&mut self, q: &V4, elapsed: Option<f64>, paused: bool) -> TickOutput {
        match self {
            DeviceSystem::Twin(s) => {
                let elapsed = elapsed.unwrap_or(s.dt());
                match paused {
                    true => s.haptic_tick_paused(q),
                    false => s.haptic_tick(q, elapsed, f64::NAN),
                }
            }
            DeviceSystem::TwoDof(s) => {
                let (q2, elapsed) = ([q[0], q[1]], elapsed.unwrap_or(s.dt()));
                match paused {
                    true => s.haptic_tick_paused(&q2),
                    false => s.haptic_tick(&q2, elapsed, f64::NAN),
                }
            }
        }
    }

    /// A running tick on joint angles `q` (rad) taken `elapsed` s after the previous one, of which
    /// the loop waited `device_wait` s for the device (so that a stall says whether the host or the
    /// device was late). Never allocates.
    #[inline]
    pub fn tick_timed(&mut self, q: &V4, elapsed: f64, device_wait: f64) -> TickOutput {
        match self {
            DeviceSystem::Twin(s) => s.haptic_tick(q, elapsed, device_wait),
            DeviceSystem::TwoDof(s) => s.haptic_tick(&[q[0], q[1]], elapsed, device_wait),
        }
    }

    /// The system's stall check alone (for a device paced by the ticks, whose signals are
    /// differentiated over one period): trips when `elapsed` (s) exceeds the stall limit. Returns
    /// true when it tripped. Never allocates.
    #[inline]
    pub fn check_stall(&mut self, elapsed: f64, device_wait: f64) -> bool {
        match self {
            DeviceSystem::Twin(s) => s.check_stall(elapsed, device_wait),
            DeviceSystem::TwoDof(s) => s.check_stall(elapsed, device_wait),
        }
    }

    /// The world.
    pub fn world(&self) -> &World {
        match self {
            DeviceSystem::Twin(s) => s.world(),
            DeviceSystem::TwoDof(s) => s.world(),
        }
    }

    /// Mutable access to the world (between ticks).
    pub fn world_mut(&mut self) -> &mut World {
        match self {
            DeviceSystem::Twin(s) => s.world_mut(),
            DeviceSystem::TwoDof(s) => s.world_mut(),
        }
    }

    /// Index of the slave body.
    pub fn slave(&self) -> usize {
        match self {
            DeviceSystem::Twin(s) => s.slave(),
            DeviceSystem::TwoDof(s) => s.slave(),
        }
    }

    /// The latched safety trip, if any.
    pub fn safety_trip(&self) -> Option<SafetyTrip> {
        match self {
            DeviceSystem::Twin(s) => s.safety_trip(),
            DeviceSystem::TwoDof(s) => s.safety_trip(),
        }
    }

    /// The record of the last tick (`x_m`: the twin's handle pose in the device frame; the 2-DOF
    /// handle point already in world coordinates).
    pub fn last_record(&self) -> &TickRecord {
        match self {
            DeviceSystem::Twin(s) => s.last_record(),
            DeviceSystem::TwoDof(s) => s.last_record(),
        }
    }

    /// Switches the controller (checked against the slave's mass; on error nothing changes).
    pub fn set_controller(&mut self, kind: ControllerKind) -> Result<(), String> {
        match self {
            DeviceSystem::Twin(s) => s.set_controller(kind),
            DeviceSystem::TwoDof(s) => s.set_controller(kind),
        }
    }

    /// The twin pantograph's kinematics (for the display's drawing of the linkage); `None` for a
    /// 2-DOF device.
    pub fn twin_kinematics(&self) -> Option<&TwinKinematics> {
        match self {
            DeviceSystem::Twin(s) => Some(&s.device().kin),
            DeviceSystem::TwoDof(_) => None,
        }
    }

    /// The passivity controller, if the twin runs one (never on a 2-DOF device).
    pub fn passivity(&self) -> Option<&PlanarPassivity> {
        match self {
            DeviceSystem::Twin(s) => s.passivity(),
            DeviceSystem::TwoDof(_) => None,
        }
    }

    /// The twin system, if this is one.
    pub fn twin(&self) -> Option<&HapticSystem> {
        match self {
            DeviceSystem::Twin(s) => Some(s),
            DeviceSystem::TwoDof(_) => None,
        }
    }

    /// Translation from the device frame to the world frame (m): world = device + offset. The 2-DOF
    /// mapping is the translation anchored at the first handle reading (zero before it).
    pub fn device_to_world(&self) -> [f64; 2] {
        match self {
            DeviceSystem::Twin(s) => {
                let m = s.map();
                [
                    m.world_origin[0] - m.device_origin[0],
                    m.world_origin[1] - m.device_origin[1],
                ]
            }
            DeviceSystem::TwoDof(s) => match s.device_origin() {
                Some(d) => {
                    let w = s.world_origin();
                    [w.x - d.x, w.y - d.y]
                }
                None => [0.0; 2],
            },
        }
    }

    /// Where the handle is, in world coordinates (m, m, rad; a 2-DOF handle's θ is the slave's).
    pub fn handle_world(&self) -> V3 {
        self.handle_world_of(self.last_record())
    }

    /// The handle pose of `record` (one of this system's tick records) in world coordinates (m, m,
    /// rad): the twin's record holds the device pose, mapped here; the 2-DOF record holds it already.
    pub fn handle_world_of(&self, record: &TickRecord) -> V3 {
        match self {
            DeviceSystem::Twin(s) => s.map().pose_to_world(&record.x_m),
            DeviceSystem::TwoDof(_) => record.x_m,
        }
    }
}
