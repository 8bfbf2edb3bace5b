//! [`DeviceSystem`]: the haptic system for any kind of device — the twin pantograph (4 joints,
//! x, y, θ: [`HapticSystem`], MODELS §10–§11; the simulated device, a replay, the Haply twin), a
//! 2-DOF five-bar (2 joints, x and y of a grasp point: [`Planar2System`]; a Haply 2DIY, a UDP
//! five-bar) or a Cartesian point device (the handle point in, a force out: [`PointSystem`]; the
//! Haply Inverse3 in planar mode). All are [`Haptic`](super::Haptic) over their
//! device coupling and run the same tick ([`Haptic::haptic_tick`](super::Haptic::haptic_tick)); the
//! enum only routes the reading to the right device. The one enum every front end drives (the rig
//! of `haptic2d run`, the Haply closed loop of `haptic2d-devices`): the loop, the watchdog, the logs
//! and the display see one interface; each method says what the 2-DOF forms do differently.

use crate::control::passivity::PlanarPassivity;
use crate::device::linalg::{V3, V4};
use crate::device::TwinKinematics;
use crate::world::World;

use super::config::ControllerKind;
use super::planar2::Planar2System;
use super::point::PointSystem;
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
    /// A Cartesian point device holding the slave at a grasp point, as [`Self::TwoDof`]: the handle
    /// point `q[0..2]` (m), the force `τ[0..2]` (N).
    Point(PointSystem),
}

/// `$body` with `$s` bound to the system of whichever variant `$self` holds.
macro_rules! each {
    ($self:expr, $s:ident => $body:expr) => {
        match $self {
            DeviceSystem::Twin($s) => $body,
            DeviceSystem::TwoDof($s) => $body,
            DeviceSystem::Point($s) => $body,
        }
    };
}

impl DeviceSystem {
    /// One tick on joint readings `q` (rad; m on a point device) taken `elapsed` s after the
    /// previous tick (the interval the device's signals are differentiated over; `None`: one period,
    /// a device paced by the ticks), or a paused tick. Never allocates.
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
            DeviceSystem::Point(s) => {
                let (u, elapsed) = ([q[0], q[1]], elapsed.unwrap_or(s.dt()));
                match paused {
                    true => s.haptic_tick_paused(&u),
                    false => s.haptic_tick(&u, elapsed, f64::NAN),
                }
            }
        }
    }

    /// A running tick on joint readings `q` (rad; m on a point device) taken `elapsed` s after the
    /// previous one, of which the loop waited `device_wait` s for the device (so that a stall says
    /// whether the host or the device was late). Never allocates.
    #[inline]
    pub fn tick_timed(&mut self, q: &V4, elapsed: f64, device_wait: f64) -> TickOutput {
        match self {
            DeviceSystem::Twin(s) => s.haptic_tick(q, elapsed, device_wait),
            DeviceSystem::TwoDof(s) => s.haptic_tick(&[q[0], q[1]], elapsed, device_wait),
            DeviceSystem::Point(s) => s.haptic_tick(&[q[0], q[1]], elapsed, device_wait),
        }
    }

    /// The system's stall check alone (for a device paced by the ticks, whose signals are
    /// differentiated over one period): trips when `elapsed` (s) exceeds the stall limit. Returns
    /// true when it tripped. Never allocates.
    #[inline]
    pub fn check_stall(&mut self, elapsed: f64, device_wait: f64) -> bool {
        each!(self, s => s.check_stall(elapsed, device_wait))
    }

    /// Runs the world's contact stage of its first sample now ([`World::prime`]): the first whole
    /// proximity update, the contact records and their buffers' first allocation. Call it once
    /// the system is set up and before the real-time loop starts, so that the loop's first tick
    /// costs what the others do (a pile:1000's sample 0 is about four of its settled samples).
    /// The ticks then compute exactly what they would have without it (the first tick's world
    /// step finds its contact stage done; `haptic_tick` changes nothing the stage reads before
    /// it). It also gives the contact stage room for [`World::contact_room`] records
    /// ([`World::reserve_contacts`]), so that a landing pile's collapse allocates nothing in the
    /// loop. Idempotent; allocates.
    pub fn prime(&mut self) {
        let w = self.world_mut();
        w.reserve_contacts(w.contact_room());
        w.prime();
    }

    /// The world.
    pub fn world(&self) -> &World {
        each!(self, s => s.world())
    }

    /// Mutable access to the world (between ticks).
    pub fn world_mut(&mut self) -> &mut World {
        each!(self, s => s.world_mut())
    }

    /// Index of the slave body.
    pub fn slave(&self) -> usize {
        each!(self, s => s.slave())
    }

    /// The latched safety trip, if any.
    pub fn safety_trip(&self) -> Option<SafetyTrip> {
        each!(self, s => s.safety_trip())
    }

    /// The record of the last tick (`x_m`: the twin's handle pose in the device frame; the 2-DOF
    /// handle point already in world coordinates).
    pub fn last_record(&self) -> &TickRecord {
        each!(self, s => s.last_record())
    }

    /// Switches the controller (checked against the slave's mass; on error nothing changes).
    pub fn set_controller(&mut self, kind: ControllerKind) -> Result<(), String> {
        each!(self, s => s.set_controller(kind))
    }

    /// The twin pantograph's kinematics (for the display's drawing of the linkage); `None` for a
    /// 2-DOF device.
    pub fn twin_kinematics(&self) -> Option<&TwinKinematics> {
        self.twin().map(|s| &s.device().kin)
    }

    /// The passivity controller, if the twin runs one (never on a 2-DOF device).
    pub fn passivity(&self) -> Option<&PlanarPassivity> {
        self.twin().and_then(|s| s.passivity())
    }

    /// Sets the twist target `θ_t` (rad; `None`: off) of a system holding the slave at a grasp point
    /// (a five-bar or a point device: the virtual torsion spring that turns the slave). Returns
    /// false, and does nothing, on the twin (its handle carries θ itself).
    pub fn set_twist_target(&mut self, theta: Option<f64>) -> bool {
        match self {
            DeviceSystem::Twin(_) => return false,
            DeviceSystem::TwoDof(s) => s.set_twist_target(theta),
            DeviceSystem::Point(s) => s.set_twist_target(theta),
        }
        true
    }

    /// The twist target (rad) of a grasp-point system; `None` when off or on the twin.
    pub fn twist_target(&self) -> Option<f64> {
        match self {
            DeviceSystem::Twin(_) => None,
            DeviceSystem::TwoDof(s) => s.twist_target(),
            DeviceSystem::Point(s) => s.twist_target(),
        }
    }

    /// The twin system, if this is one.
    pub fn twin(&self) -> Option<&HapticSystem> {
        match self {
            DeviceSystem::Twin(s) => Some(s),
            _ => None,
        }
    }

    /// Translation from the device frame to the world frame (m): world = device + offset. The 2-DOF
    /// mapping is the translation anchored at the first handle reading (zero before it).
    pub fn device_to_world(&self) -> [f64; 2] {
        let grasp = |d: Option<crate::geom::Vec2>, w: crate::geom::Vec2| match d {
            Some(d) => [w.x - d.x, w.y - d.y],
            None => [0.0; 2],
        };
        match self {
            DeviceSystem::Twin(s) => {
                let m = s.map();
                [
                    m.world_origin[0] - m.device_origin[0],
                    m.world_origin[1] - m.device_origin[1],
                ]
            }
            DeviceSystem::TwoDof(s) => grasp(s.device_origin(), s.world_origin()),
            DeviceSystem::Point(s) => grasp(s.device_origin(), s.world_origin()),
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
            _ => record.x_m,
        }
    }
}
