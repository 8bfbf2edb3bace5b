//! [`CartesianDevice`]: the one boundary between a haptic device and the haptic tick, where CHAI3D
//! puts it (`cGenericHapticDevice`): the device turns its joint reading into the handle's pose,
//! twist and hand-wrench estimate (through its own kinematics and Jacobian), and turns the handle
//! wrench the tick asks for into joint torques (through the transpose of that Jacobian, saturated to
//! its motors). Everything the tick does between the two — the controller, the passivity controller,
//! the workspace bound, the ramp and the gate ([`SafetyStage`](crate::haptic::SafetyStage)) — works
//! in handle coordinates and is the same for every device.
//!
//! ```text
//! joints q (rad) ──sense──▶ pose x (m, m, rad), twist ẋ, hand wrench ŵ_h   (device frame)
//! wrench f (N, N, N·m) ──wrench_to_torques──▶ τ = Jᵀ·f, saturated keeping its direction (N·m)
//! ```
//!
//! Implemented by the twin pantograph ([`TwinPantograph`]: 4 joints, x, y
//! and θ, redundant) and the 2-DOF five-bar ([`Pantograph2Device`](super::pantograph2_device::Pantograph2Device):
//! 2 joints, x and y; a Haply 2DIY, a UDP five-bar) and the Cartesian pass-through
//! ([`PointDevice`](super::PointDevice): the handle point in, a force out; the Inverse3).

use super::fault::DeviceFault;
use super::linalg::{M3, V3, V4};
use super::twin_pantograph::{DeviceEstimate, TorqueCommand, TwinPantograph};

/// A haptic device seen from the tick: pose and twist in, wrench out (see the module doc). No
/// method allocates, locks, prints or does I/O.
pub trait CartesianDevice {
    /// The joint reading (rad): `[f64; 4]` on the twin, `[f64; 2]` on a five-bar.
    type Joints;

    /// Steps 1–2: the handle's pose (m, m, rad; θ = 0 on a 2-DOF device), filtered twist (m/s,
    /// m/s, rad/s) and hand-wrench estimate (N, N, N·m; zero on a device without an observer), in
    /// the device frame, from joint reading `q` taken `elapsed` s after the previous one, with
    /// `tau_prev` (N·m) the torques held over that interval. Remembers the pose (and Jacobian) for
    /// [`Self::wrench_to_torques`]. A fault (unreachable reading, closure monitor, …) is an error.
    fn sense(
        &mut self,
        q: &Self::Joints,
        tau_prev: &V4,
        elapsed: f64,
    ) -> Result<DeviceEstimate, DeviceFault>;

    /// Step 9: the joint torques (N·m; unused motors 0) producing the handle wrench `f` (N, N, N·m;
    /// device frame) at the last sensed pose, saturated to the motor limits keeping the wrench's
    /// direction; `preload` (N·m) is the internal preload of a redundant device (ignored by one
    /// that is not). Below the device's singularity margin the torques are zero and
    /// `near_singular` is set. Before a first reading: [`DeviceFault::NoPose`].
    fn wrench_to_torques(&self, f: &V3, preload: f64) -> Result<TorqueCommand, DeviceFault>;

    /// The motor torque limits (N·m; 0 for a motor the device does not have).
    fn tau_max(&self) -> V4;

    /// The singularity margin at the last sensed pose (dimensionless, the device's own measure).
    fn margin(&self) -> f64;

    /// The handle's mass matrix (kg, kg·m, kg·m²) at the last sensed pose, for the controllers'
    /// master-mass feed-forward and the passivity controller's damping cap; zero for a device
    /// without a dynamic model.
    fn mass_matrix(&self) -> M3;
}

/// The twin pantograph: 4 joints, x, y and θ; redundant (the preload acts in the null space).
impl CartesianDevice for TwinPantograph {
    type Joints = V4;

    /// [`TwinPantograph::estimate_elapsed`].
    fn sense(
        &mut self,
        q: &V4,
        tau_prev: &V4,
        elapsed: f64,
    ) -> Result<DeviceEstimate, DeviceFault> {
        self.estimate_elapsed(q, tau_prev, elapsed)
    }

    /// [`TwinPantograph::torques_for_wrench`]: minimum-norm redundancy resolution plus `preload`.
    fn wrench_to_torques(&self, f: &V3, preload: f64) -> Result<TorqueCommand, DeviceFault> {
        self.torques_for_wrench(f, preload)
    }

    fn tau_max(&self) -> V4 {
        [self.params.tau_max; 4]
    }

    fn margin(&self) -> f64 {
        TwinPantograph::margin(self)
    }

    fn mass_matrix(&self) -> M3 {
        TwinPantograph::mass_matrix(self)
    }
}
