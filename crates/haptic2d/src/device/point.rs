//! [`PointDevice`]: a Cartesian device behind the [`CartesianDevice`] boundary with no linkage of
//! its own to model — its driver reports the handle point and takes a force (the Haply Inverse3 in
//! planar mode, whose own firmware does the kinematics). Pass-through, `J = I`:
//!
//! ```text
//! reading u = (x, y) (m, device frame) ──sense──▶ pose (x, y, 0), filtered twist (§10.7), no hand wrench
//! wrench f (N, N, N·m) ──wrench_to_torques──▶ "torques" (f_x, f_y, 0, 0) in N, scaled to |f| ≤ F_max
//! ```
//!
//! The "joint" values are the point's coordinates (m) and the "torques" forces (N): the tick's
//! saturation, limit-cycle monitor and gate then work on forces against the force limit `F_max`.
//! The force is scaled as a whole when `|(f_x, f_y)|` exceeds `F_max` (direction kept, as the
//! driver's own clamp does). There is no singularity (margin 1) and no dynamic model (mass zero).

use super::cartesian::CartesianDevice;
use super::fault::DeviceFault;
use super::filter::VelocityFilter;
use super::linalg::{M3, V3, V4};
use super::pantograph2_device::planar_estimate;
use super::twin_pantograph::{DeviceEstimate, TorqueCommand};

/// A handle point read directly, with its force limit, velocity filter and last reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointDevice {
    /// Force limit `F_max` on `|(f_x, f_y)|` (N), > 0.
    pub force_limit: f64,
    filter: VelocityFilter,
    point: Option<[f64; 2]>,
}

impl PointDevice {
    /// A point device with force limit `force_limit` (N) and a velocity filter of cut-off
    /// `velocity_cutoff_hz` (Hz) at period `dt` (s).
    pub fn new(force_limit: f64, velocity_cutoff_hz: f64, dt: f64) -> Self {
        Self {
            force_limit,
            filter: VelocityFilter::new(velocity_cutoff_hz, dt),
            point: None,
        }
    }

    /// The last valid reading (m, device frame); `None` before one or after a fault.
    pub fn point(&self) -> Option<[f64; 2]> {
        self.point
    }
}

impl CartesianDevice for PointDevice {
    /// The handle point `(x, y)` (m, device frame).
    type Joints = [f64; 2];

    /// The pose `(x, y, 0)` of reading `u`, its filtered velocity over `elapsed` (§10.7), no hand
    /// wrench (`tau_prev` unused). A non-finite reading is [`DeviceFault::NonFinite`].
    fn sense(
        &mut self,
        u: &[f64; 2],
        _tau_prev: &V4,
        elapsed: f64,
    ) -> Result<DeviceEstimate, DeviceFault> {
        if !(u[0].is_finite() && u[1].is_finite()) {
            self.point = None;
            return Err(DeviceFault::NonFinite);
        }
        self.point = Some(*u);
        Ok(planar_estimate(&mut self.filter, *u, elapsed))
    }

    /// `(f_x, f_y)` (N; the moment `f[2]` has no actuator), scaled by
    /// `s = min(1, F_max / |(f_x, f_y)|)`.
    fn wrench_to_torques(&self, f: &V3, _preload: f64) -> Result<TorqueCommand, DeviceFault> {
        if self.point.is_none() {
            return Err(DeviceFault::NoPose);
        }
        let norm = f[0].hypot(f[1]);
        let scale = if norm > self.force_limit {
            self.force_limit / norm
        } else {
            1.0
        };
        Ok(TorqueCommand {
            tau: [f[0] * scale, f[1] * scale, 0.0, 0.0],
            wrench_scale: scale,
            saturated: scale < 1.0,
            near_singular: false,
            margin: 1.0,
        })
    }

    /// `(F_max, F_max, 0, 0)` (N).
    fn tau_max(&self) -> V4 {
        [self.force_limit, self.force_limit, 0.0, 0.0]
    }

    /// 1: no singularity; NaN before a reading (as the five-bar's).
    fn margin(&self) -> f64 {
        self.point.map_or(f64::NAN, |_| 1.0)
    }

    /// Zero: no dynamic model.
    fn mass_matrix(&self) -> M3 {
        [[0.0; 3]; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: f64 = 1e-3;

    #[test]
    fn a_point_device_passes_the_reading_and_the_force_through_unchanged() {
        let mut d = PointDevice::new(5.0, 50.0, T);
        let e = d.sense(&[0.012, -0.034], &[0.0; 4], T).unwrap();
        assert_eq!(e.pose, [0.012, -0.034, 0.0]);
        assert_eq!(e.hand_wrench, [0.0; 3]);
        let cmd = d.wrench_to_torques(&[1.5, -2.0, 0.7], 0.0).unwrap();
        assert_eq!(
            cmd.tau,
            [1.5, -2.0, 0.0, 0.0],
            "J = I; no actuator for the moment"
        );
        assert!(!cmd.saturated && !cmd.near_singular);
        assert_eq!(d.margin(), 1.0);
    }

    #[test]
    fn a_force_above_the_limit_is_scaled_down_keeping_its_direction() {
        let mut d = PointDevice::new(5.0, 50.0, T);
        d.sense(&[0.0, 0.0], &[0.0; 4], T).unwrap();
        // |(6, 8)| = 10 N, twice the limit: (3, 4) N.
        let cmd = d.wrench_to_torques(&[6.0, 8.0, 0.0], 0.0).unwrap();
        assert!((cmd.tau[0] - 3.0).abs() < 1e-15 && (cmd.tau[1] - 4.0).abs() < 1e-15);
        assert!(cmd.saturated);
        assert_eq!(cmd.wrench_scale, 0.5);
    }

    #[test]
    fn the_velocity_is_the_filtered_derivative_of_the_point() {
        // A ramp at 0.1 m/s along x: the first-order filter's output rises monotonically to it (up
        // to the rounding of the differences, ~1e-14 m/s).
        let mut d = PointDevice::new(5.0, 50.0, T);
        let mut last = 0.0;
        for k in 0..400 {
            let e = d.sense(&[0.1 * k as f64 * T, 0.0], &[0.0; 4], T).unwrap();
            assert!(e.velocity[0] >= last - 1e-12 && e.velocity[1] == 0.0);
            last = e.velocity[0];
        }
        assert!((last - 0.1).abs() < 1e-3, "settled at {last} m/s");
    }

    #[test]
    fn a_non_finite_reading_is_a_fault_and_no_force_follows_it() {
        let mut d = PointDevice::new(5.0, 50.0, T);
        assert_eq!(
            d.wrench_to_torques(&[1.0, 0.0, 0.0], 0.0),
            Err(DeviceFault::NoPose)
        );
        d.sense(&[0.0, 0.0], &[0.0; 4], T).unwrap();
        assert_eq!(
            d.sense(&[f64::NAN, 0.0], &[0.0; 4], T),
            Err(DeviceFault::NonFinite)
        );
        assert_eq!(
            d.wrench_to_torques(&[1.0, 0.0, 0.0], 0.0),
            Err(DeviceFault::NoPose)
        );
        assert!(d.margin().is_nan());
    }
}
