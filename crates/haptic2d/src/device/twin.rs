//! Twin-pantograph kinematics: device forward kinematics from the four encoders (with θ unwrapping and
//! the closure-consistency monitor) and device inverse kinematics (§10.1, §10.3).

use crate::geom::{wrap_angle, Vec2};

use super::fault::DeviceFault;
use super::five_bar::{e_of, FiveBar};
use super::linalg::{V3, V4};
use super::params::DeviceParams;

/// Geometry of the two pantographs and the crank. Joint order everywhere: `(q_11, q_12, q_21, q_22)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwinKinematics {
    /// Pantograph 1 (its endpoint `P_1` carries the handle shaft) and pantograph 2 (crank pin `P_2`).
    pub pantographs: [FiveBar; 2],
    /// Crank radius `r_c` (m): `P_2 = P_1 + r_c·e(θ)`.
    pub r_c: f64,
    /// Closure-monitor tolerance (m).
    pub closure_tol: f64,
}

/// A full kinematic configuration: handle pose, joint angles, endpoints and elbows, mutually consistent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Configuration {
    /// Handle pose `(x, y, θ)` (m, m, rad; θ unwrapped).
    pub x: V3,
    /// Joint angles `(q_11, q_12, q_21, q_22)` (rad).
    pub q: V4,
    /// Endpoints `P_1`, `P_2` (m).
    pub p: [Vec2; 2],
    /// Elbows `E_11, E_12, E_21, E_22` (m).
    pub e: [Vec2; 4],
}

/// The result of device forward kinematics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwinFk {
    /// Handle pose `(x, y, θ)` (m, m, rad), θ unwrapped against the previous value.
    pub pose: V3,
    /// Closure error `|P_2 − P_1| − r_c` (m), for logging.
    pub closure_error: f64,
}

impl TwinKinematics {
    /// The kinematics of the device described by `p` (no validation here; see [`DeviceParams::validate`]).
    pub fn new(p: &DeviceParams) -> Self {
        let bar = |index| FiveBar {
            s: p.s,
            l1: p.l1,
            l2: p.l2,
            index,
        };
        Self {
            pantographs: [bar(1), bar(2)],
            r_c: p.r_c,
            closure_tol: p.closure_tol,
        }
    }

    /// Endpoints `P_1 = (x, y)` and `P_2 = (x, y) + r_c·e(θ)` (m) of handle pose `x`.
    #[inline]
    pub fn endpoints(&self, x: &V3) -> [Vec2; 2] {
        let p1 = Vec2::new(x[0], x[1]);
        [p1, p1 + self.r_c * e_of(x[2])]
    }

    /// Device inverse kinematics: the four joint angles (rad) for handle pose `x`, elbows out.
    pub fn ik(&self, x: &V3) -> Result<V4, DeviceFault> {
        Ok(self.configuration(x)?.q)
    }

    /// The full configuration at handle pose `x` (via inverse kinematics).
    pub fn configuration(&self, x: &V3) -> Result<Configuration, DeviceFault> {
        if !x.iter().all(|v| v.is_finite()) {
            return Err(DeviceFault::NonFinite);
        }
        let p = self.endpoints(x);
        let qa = self.pantographs[0].ik(p[0])?;
        let qb = self.pantographs[1].ik(p[1])?;
        let ea = self.pantographs[0].elbows(qa);
        let eb = self.pantographs[1].elbows(qb);
        Ok(Configuration {
            x: *x,
            q: [qa[0], qa[1], qb[0], qb[1]],
            p,
            e: [ea[0], ea[1], eb[0], eb[1]],
        })
    }

    /// Device forward kinematics from the four encoder angles `q` (rad):
    /// `P_1 = FK(q_11, q_12)`, `P_2 = FK(q_21, q_22)`, `(x, y) = P_1`,
    /// `θ = θ_prev + wrap(atan2(P_2 − P_1) − θ_prev)` (unwrapped; rotation is unlimited).
    ///
    /// The closure monitor returns [`DeviceFault::ClosureViolation`] when
    /// `| |P_2 − P_1| − r_c | ≥ closure_tol`.
    pub fn fk(&self, q: &V4, theta_prev: f64) -> Result<TwinFk, DeviceFault> {
        if !theta_prev.is_finite() {
            return Err(DeviceFault::NonFinite);
        }
        let p1 = self.pantographs[0].fk([q[0], q[1]])?;
        let p2 = self.pantographs[1].fk([q[2], q[3]])?;
        let d = p2 - p1;
        let closure_error = d.length() - self.r_c;
        if closure_error.abs() >= self.closure_tol {
            return Err(DeviceFault::ClosureViolation {
                error: closure_error,
            });
        }
        let raw = d.y.atan2(d.x);
        let theta = theta_prev + wrap_angle(raw - theta_prev);
        Ok(TwinFk {
            pose: [p1.x, p1.y, theta],
            closure_error,
        })
    }
}
