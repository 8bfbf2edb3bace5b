//! [`Pantograph2Device`]: a 2-DOF five-bar ([`Pantograph2`]) behind the [`CartesianDevice`]
//! boundary — a Haply 2DIY and a UDP five-bar (the Inverse3 is a [`PointDevice`](super::PointDevice)). The
//! handle point and its Jacobian come from the linkage; the twist is the §10.7 velocity filter on
//! the handle point (device frame); there is no hand-wrench observer (no dynamic model of a 2DIY),
//! so the estimate is zero; `τ = Jᵀ·f` is scaled down as a whole when a motor would exceed its
//! limit (direction kept).

use super::cartesian::CartesianDevice;
use super::fault::DeviceFault;
use super::filter::VelocityFilter;
use super::linalg::{M3, V3, V4};
use super::pantograph2::{jt_mul, Pantograph2, Pantograph2State};
use super::twin_pantograph::{DeviceEstimate, TorqueCommand};

/// The estimate of a 2-DOF handle point `p` (m, device frame) read `elapsed` s after the previous
/// reading: pose `(x, y, 0)`, the velocity of `filter` (§10.7), no hand wrench, no closure error.
pub(super) fn planar_estimate(
    filter: &mut VelocityFilter,
    p: [f64; 2],
    elapsed: f64,
) -> DeviceEstimate {
    let pose = [p[0], p[1], 0.0];
    let v = filter.update_elapsed(&pose, elapsed);
    DeviceEstimate {
        pose,
        velocity: [v[0], v[1], 0.0],
        hand_wrench: [0.0; 3],
        closure_error: 0.0,
    }
}

/// A five-bar with its motor limits, velocity filter and the state at the last reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pantograph2Device {
    /// The linkage (m).
    pub linkage: Pantograph2,
    /// Motor torque limits `(τ_1, τ_2)` (N·m), each > 0.
    pub tau_max: [f64; 2],
    /// Below this singularity margin (dimensionless `|sin|` of the distal links) the torques are
    /// zero and `near_singular` is set.
    pub min_margin: f64,
    filter: VelocityFilter,
    state: Option<Pantograph2State>,
}

impl Pantograph2Device {
    /// The device for `linkage` with motor limits `tau_max` (N·m), the singularity limit
    /// `min_margin`, and a velocity filter of cut-off `velocity_cutoff_hz` (Hz) at period `dt` (s).
    pub fn new(
        linkage: Pantograph2,
        tau_max: [f64; 2],
        min_margin: f64,
        velocity_cutoff_hz: f64,
        dt: f64,
    ) -> Self {
        Self {
            linkage,
            tau_max,
            min_margin,
            filter: VelocityFilter::new(velocity_cutoff_hz, dt),
            state: None,
        }
    }

    /// End point (m), Jacobian and margin at the last reading; `None` before one or after a fault.
    pub fn state(&self) -> Option<Pantograph2State> {
        self.state
    }
}

impl CartesianDevice for Pantograph2Device {
    type Joints = [f64; 2];

    /// The handle point `E(q)` (θ = 0), its filtered velocity over `elapsed` (§10.7), no hand
    /// wrench (`tau_prev` unused: no observer).
    fn sense(
        &mut self,
        q: &[f64; 2],
        _tau_prev: &V4,
        elapsed: f64,
    ) -> Result<DeviceEstimate, DeviceFault> {
        let s = match self.linkage.state(*q) {
            Ok(s) => s,
            Err(f) => {
                self.state = None;
                return Err(f);
            }
        };
        self.state = Some(s);
        Ok(planar_estimate(&mut self.filter, [s.e.x, s.e.y], elapsed))
    }

    /// `τ = Jᵀ·(f_x, f_y)` (the moment `f[2]` has no motor), scaled by
    /// `s = min(1, min_i τ_max,i / |τ_i|)`.
    fn wrench_to_torques(&self, f: &V3, _preload: f64) -> Result<TorqueCommand, DeviceFault> {
        let s = self.state.ok_or(DeviceFault::NoPose)?;
        if s.margin < self.min_margin {
            return Ok(TorqueCommand::near_singular(s.margin));
        }
        let tau = jt_mul(&s.j, [f[0], f[1]]);
        let mut scale: f64 = 1.0;
        for (t, max) in tau.iter().zip(self.tau_max) {
            if t.abs() > max {
                scale = scale.min(max / t.abs());
            }
        }
        Ok(TorqueCommand {
            tau: [tau[0] * scale, tau[1] * scale, 0.0, 0.0],
            wrench_scale: scale,
            saturated: scale < 1.0,
            near_singular: false,
            margin: s.margin,
        })
    }

    fn tau_max(&self) -> V4 {
        [self.tau_max[0], self.tau_max[1], 0.0, 0.0]
    }

    /// NaN before a reading.
    fn margin(&self) -> f64 {
        self.state.map_or(f64::NAN, |s| s.margin)
    }

    /// Zero: no dynamic model of the linkage.
    fn mass_matrix(&self) -> M3 {
        [[0.0; 3]; 3]
    }
}
