//! [`DeviceCoupling`]: what the one haptic tick ([`Haptic`](super::Haptic)) needs to know about a
//! device beyond its [`CartesianDevice`] boundary — how its handle is tied to the slave body. Two
//! couplings exist:
//!
//! | | [`TwinCoupling`](super::TwinCoupling) | [`GraspCoupling`](super::GraspCoupling) |
//! |---|---|---|
//! | device | twin pantograph (x, y, θ) | 2-DOF five-bar (x, y) |
//! | device → world | [`DeviceMap`](super::DeviceMap): scale, anchored at the first reading | translation, anchored at the first reading |
//! | slave point | the body's centre | a grasp point `r_g`; θ taken from the slave |
//! | singularity trip | step 9 (redundancy resolution) | step 2b (at the reading) |
//! | record `x_m` | handle pose, device frame | handle point, world frame |
//!
//! Every other step — stall, plausibility, controller, passivity controller, workspace bound,
//! saturation, limit cycle, ramp, gate, integration — is the tick's, the same for every device. No
//! method allocates, locks, prints or does I/O.

use crate::control::four_channel::TeleopSignals;
use crate::device::linalg::{M3, V3};
use crate::device::{CartesianDevice, DeviceEstimate};
use crate::geom::Vec2;
use crate::haptic::record::TickRecord;
use crate::world::World;

/// The slave body as the contact stage left it: the point the device holds (pose and twist in
/// world coordinates: the body's centre, or a grasp point with the body's angle), the body's centre
/// pose and twist (m, m, rad; m/s, m/s, rad/s), the grasp offset `r` in the world frame (m; zero at
/// the centre), and the contact wrench the slave exerts on the world (`f_e`, N, N, N·m, about the
/// centre).
#[derive(Clone, Copy, Debug)]
pub struct SlaveState {
    /// Pose of the held point (m, m, rad).
    pub x_s: V3,
    /// Twist of the held point (m/s, m/s, rad/s).
    pub v_s: V3,
    /// Pose of the body's centre (m, m, rad).
    pub centre: V3,
    /// Twist of the body's centre (m/s, m/s, rad/s).
    pub centre_twist: V3,
    /// Grasp offset from the centre, world frame (m).
    pub r: Vec2,
    /// Wrench the slave exerts on the world (N, N, N·m).
    pub f_e: V3,
}

impl SlaveState {
    /// Body `i` of `world` as it stands, held at its centre.
    pub fn at_centre(world: &World, i: usize) -> Self {
        let body = &world.bodies[i];
        let cw = world.contact_wrench(i);
        let centre = [body.pose.pos.x, body.pose.pos.y, body.pose.angle];
        let centre_twist = [body.vel.x, body.vel.y, body.omega];
        Self {
            x_s: centre,
            v_s: centre_twist,
            centre,
            centre_twist,
            r: Vec2::new(0.0, 0.0),
            f_e: [-cw.force.x, -cw.force.y, -cw.torque],
        }
    }
}

/// A device as the haptic tick drives it: its [`CartesianDevice`] and how the handle is tied to the
/// slave (see the module doc for the two kinds).
pub trait DeviceCoupling {
    /// The device behind the Cartesian boundary.
    type Device: CartesianDevice;

    /// True when the device's singularity margin is checked at the reading (step 2b, before the
    /// controller runs); false when the redundancy resolution reports it at step 9.
    const MARGIN_AT_SENSE: bool;

    /// The device.
    fn device(&self) -> &Self::Device;
    /// The device, mutably (for sensing).
    fn device_mut(&mut self) -> &mut Self::Device;

    /// Step 1b. Anchors the device → world map at the reading `e` if it is not anchored yet, so the
    /// handle lands on the slave's held point (`world`, body `slave`) with no coupling force.
    /// Returns true when it anchored now (the torque ramp then restarts).
    fn align(&mut self, e: &DeviceEstimate, world: &World, slave: usize) -> bool;
    /// Forgets the anchor (a pause or a re-arm): the next reading anchors again.
    fn unalign(&mut self, world: &World, slave: usize);
    /// A re-arm after a fault: restart the device's estimates (velocity filter, observer).
    fn rearm(&mut self) {}

    /// Steps 3–6, last: the slave body `i` of `world` as the controller sees it.
    fn slave_state(&self, world: &World, i: usize) -> SlaveState;

    /// Step 7. The controller's signals in world coordinates for reading `e`, slave `s` and the
    /// device's mass matrix `m_dev` (device frame, kg, kg·m, kg·m²).
    fn teleop_signals(&self, e: &DeviceEstimate, s: &SlaveState, m_dev: &M3) -> TeleopSignals;
    /// Step 7, after the controller: zero the command axes the device cannot render (N, N, N·m).
    fn constrain(&self, _f: &mut V3) {}

    /// A world wrench (N, N, N·m) in the device frame.
    fn wrench_to_device(&self, f: &V3) -> V3;
    /// A device-frame wrench (N, N, N·m) in world coordinates.
    fn wrench_to_world(&self, f: &V3) -> V3;
    /// The internal preload of a redundant device (N·m; 0 otherwise).
    fn preload(&self) -> f64 {
        0.0
    }

    /// Step 10. The slave drive for command `f_cs` (world, N, N, N·m, at the held point): the force
    /// (N) and the torque about the centre (N·m); `latched` says the safety latch holds.
    fn drive(&self, f_cs: &V3, s: &SlaveState, latched: bool) -> (Vec2, f64);

    /// Step 11. The device's own conventions in the record the tick filled (`x_m`, `v_m`, `w_h`,
    /// `closure_error` from the reading `est`, device frame): `paused` for a paused tick, `gated`
    /// when the final gate zeroed the torques. `world` is the world after the tick.
    fn record(
        &self,
        _rec: &mut TickRecord,
        _est: Option<&DeviceEstimate>,
        _world: &World,
        _slave: usize,
        _paused: bool,
        _gated: bool,
    ) {
    }
}
