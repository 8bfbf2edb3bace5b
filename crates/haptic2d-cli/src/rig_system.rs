//! [`RigSystem`]: the haptic system inside the rig of `haptic2d run`, for either kind of device —
//! the twin pantograph (4 joints, x, y, θ: [`HapticSystem`], MODELS §10–§11; the simulated device,
//! a replay, the Haply twin) or a 2-DOF five-bar (2 joints, x and y of a grasp point:
//! [`Planar2System`]; a Haply 2DIY, and any other 2-DOF device). The loop, the watchdog, the logs
//! and the display see one interface; each method says what the 2-DOF form does differently.

use haptic2d::control::passivity::PlanarPassivity;
use haptic2d::device::linalg::{V3, V4};
use haptic2d::device::TwinKinematics;
use haptic2d::haptic::planar2::{Planar2Output, Planar2System};
use haptic2d::haptic::{ControllerKind, HapticSystem, SafetyTrip, TickOutput, TickRecord};
use haptic2d::world::World;

/// The system the rig drives.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)]
pub enum RigSystem {
    /// The twin pantograph: x, y and θ.
    Twin(HapticSystem),
    /// A 2-DOF five-bar holding the slave at a grasp point: x and y; the rotation is left to the
    /// world. Joints `q[0..2]`, torques `τ[0..2]` (`τ[2..4]` always zero).
    TwoDof(Planar2System),
}

/// A 2-DOF output in the twin's shape: torques `[τ1, τ2, 0, 0]`; no closure monitor on a five-bar.
#[inline]
fn widen(o: Planar2Output) -> TickOutput {
    TickOutput {
        torques: [o.torques[0], o.torques[1], 0.0, 0.0],
        tripped: o.tripped,
        margin: if o.record.margin.is_finite() {
            o.record.margin
        } else {
            0.0
        },
        closure_fault: false,
        record: o.record,
    }
}

impl RigSystem {
    /// One tick on joint angles `q` (rad) taken `elapsed` s after the previous tick (the interval
    /// the device's signals are differentiated over; `None`: one period, a device paced by the
    /// ticks), or a paused tick. Never allocates.
    #[inline]
    pub fn tick(&mut self, q: &V4, elapsed: Option<f64>, paused: bool) -> TickOutput {
        match self {
            RigSystem::Twin(s) => match (paused, elapsed) {
                (true, _) => s.tick_paused(q),
                (false, None) => s.tick(q),
                (false, Some(e)) => s.tick_elapsed(q, e),
            },
            RigSystem::TwoDof(s) => {
                let q2 = [q[0], q[1]];
                widen(match (paused, elapsed) {
                    (true, _) => s.tick_paused(&q2),
                    (false, None) => s.tick(&q2),
                    (false, Some(e)) => s.tick_elapsed(&q2, e),
                })
            }
        }
    }

    /// A running tick on joint angles `q` (rad) taken `elapsed` s after the previous one, of which
    /// the loop waited `device_wait` s for the device (so that a stall says whether the host or the
    /// device was late). Never allocates.
    #[inline]
    pub fn tick_timed(&mut self, q: &V4, elapsed: f64, device_wait: f64) -> TickOutput {
        match self {
            RigSystem::Twin(s) => s.tick_timed(q, elapsed, device_wait),
            RigSystem::TwoDof(s) => widen(s.tick_timed(&[q[0], q[1]], elapsed, device_wait)),
        }
    }

    /// The system's stall check alone (for a device paced by the ticks, whose signals are
    /// differentiated over one period): trips when `elapsed` (s) exceeds the stall limit. Returns
    /// true when it tripped. Never allocates.
    #[inline]
    pub fn check_stall(&mut self, elapsed: f64, device_wait: f64) -> bool {
        match self {
            RigSystem::Twin(s) => s.check_stall(elapsed, device_wait),
            RigSystem::TwoDof(s) => s.check_stall(elapsed, device_wait),
        }
    }

    /// The world.
    pub fn world(&self) -> &World {
        match self {
            RigSystem::Twin(s) => s.world(),
            RigSystem::TwoDof(s) => s.world(),
        }
    }

    /// Mutable access to the world (between ticks).
    pub fn world_mut(&mut self) -> &mut World {
        match self {
            RigSystem::Twin(s) => s.world_mut(),
            RigSystem::TwoDof(s) => s.world_mut(),
        }
    }

    /// Index of the slave body.
    pub fn slave(&self) -> usize {
        match self {
            RigSystem::Twin(s) => s.slave(),
            RigSystem::TwoDof(s) => s.slave(),
        }
    }

    /// The latched safety trip, if any.
    pub fn safety_trip(&self) -> Option<SafetyTrip> {
        match self {
            RigSystem::Twin(s) => s.safety_trip(),
            RigSystem::TwoDof(s) => s.safety_trip(),
        }
    }

    /// The record of the last tick (`x_m`: the twin's handle pose in the device frame; the 2-DOF
    /// handle point already in world coordinates).
    pub fn last_record(&self) -> &TickRecord {
        match self {
            RigSystem::Twin(s) => s.last_record(),
            RigSystem::TwoDof(s) => s.last_record(),
        }
    }

    /// Switches the controller (checked against the slave's mass; on error nothing changes).
    pub fn set_controller(&mut self, kind: ControllerKind) -> Result<(), String> {
        match self {
            RigSystem::Twin(s) => s.set_controller(kind),
            RigSystem::TwoDof(s) => s.set_controller(kind),
        }
    }

    /// The twin pantograph's kinematics (for the display's drawing of the linkage); `None` for a
    /// 2-DOF device.
    pub fn twin_kinematics(&self) -> Option<&TwinKinematics> {
        match self {
            RigSystem::Twin(s) => Some(&s.device().kin),
            RigSystem::TwoDof(_) => None,
        }
    }

    /// The passivity controller, if the twin runs one (never on a 2-DOF device).
    pub fn passivity(&self) -> Option<&PlanarPassivity> {
        match self {
            RigSystem::Twin(s) => s.passivity(),
            RigSystem::TwoDof(_) => None,
        }
    }

    /// The twin system, if this is one.
    pub fn twin(&self) -> Option<&HapticSystem> {
        match self {
            RigSystem::Twin(s) => Some(s),
            RigSystem::TwoDof(_) => None,
        }
    }

    /// Translation from the device frame to the world frame (m): world = device + offset. The 2-DOF
    /// mapping is the translation anchored at the first handle reading (zero before it).
    pub fn device_to_world(&self) -> [f64; 2] {
        match self {
            RigSystem::Twin(s) => {
                let m = s.map();
                [
                    m.world_origin[0] - m.device_origin[0],
                    m.world_origin[1] - m.device_origin[1],
                ]
            }
            RigSystem::TwoDof(s) => match s.device_origin() {
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
        match self {
            RigSystem::Twin(s) => s.map().pose_to_world(&s.last_record().x_m),
            RigSystem::TwoDof(s) => s.last_record().x_m,
        }
    }
}
