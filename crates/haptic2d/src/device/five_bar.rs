//! One symmetric five-bar pantograph: forward and inverse kinematics (§10.3).

use crate::geom::{perp, Vec2};

use super::fault::DeviceFault;

/// A symmetric five-bar: motor axes at `B_1 = (−s/2, 0)` and `B_2 = (+s/2, 0)`, proximal links `l1`
/// driven by the motor angles `q_1`, `q_2` (rad, from +x, CCW), distal links `l2` meeting at the
/// endpoint `P`. Working mode: elbows out (left elbow left, right elbow right), endpoint away from the
/// base.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FiveBar {
    /// Motor-axis spacing `s` (m).
    pub s: f64,
    /// Proximal link length `l1` (m).
    pub l1: f64,
    /// Distal link length `l2` (m).
    pub l2: f64,
    /// Index of this pantograph (1 or 2), only used in fault reports.
    pub index: u8,
}

/// `e(q) = (cos q, sin q)`.
#[inline]
pub fn e_of(q: f64) -> Vec2 {
    let (s, c) = q.sin_cos();
    Vec2::new(c, s)
}

impl FiveBar {
    /// Motor axis `i` (0 = left, 1 = right) in the base frame (m).
    #[inline]
    pub fn base(&self, i: usize) -> Vec2 {
        if i == 0 {
            Vec2::new(-0.5 * self.s, 0.0)
        } else {
            Vec2::new(0.5 * self.s, 0.0)
        }
    }

    /// Elbow positions `E_i = B_i + l1·e(q_i)` (m) for motor angles `q = (q_1, q_2)` (rad).
    #[inline]
    pub fn elbows(&self, q: [f64; 2]) -> [Vec2; 2] {
        [
            self.base(0) + self.l1 * e_of(q[0]),
            self.base(1) + self.l1 * e_of(q[1]),
        ]
    }

    /// Forward kinematics: endpoint `P` (m) from the motor angles (rad), assembly mode away from the base:
    /// `P = (E_1 + E_2)/2 + h·perp(Δ)/D`, `Δ = E_2 − E_1`, `h = sqrt(l2² − D²/4)`.
    ///
    /// Errors with [`DeviceFault::FkNoAssembly`] when `D` is not in `(0, 2·l2)`.
    pub fn fk(&self, q: [f64; 2]) -> Result<Vec2, DeviceFault> {
        if !q[0].is_finite() || !q[1].is_finite() {
            return Err(DeviceFault::NonFinite);
        }
        let [e1, e2] = self.elbows(q);
        let delta = e2 - e1;
        let d = delta.length();
        if !(d > 0.0 && d < 2.0 * self.l2) {
            return Err(DeviceFault::FkNoAssembly {
                pantograph: self.index,
                elbow_distance: d,
            });
        }
        let h = (self.l2 * self.l2 - 0.25 * d * d).sqrt();
        Ok(0.5 * (e1 + e2) + (h / d) * perp(delta))
    }

    /// Inverse kinematics, elbows out: motor angles `(q_1, q_2)` (rad) that put the endpoint at `p` (m).
    /// For motor `i`: `ρ = |P − B_i|`, `φ = atan2(P − B_i)`, `γ = acos((l1² + ρ² − l2²)/(2·l1·ρ))`,
    /// `q_1 = φ + γ`, `q_2 = φ − γ`.
    ///
    /// Errors with [`DeviceFault::Unreachable`] when an `acos` argument leaves `[−1, 1]`.
    pub fn ik(&self, p: Vec2) -> Result<[f64; 2], DeviceFault> {
        if !p.x.is_finite() || !p.y.is_finite() {
            return Err(DeviceFault::NonFinite);
        }
        let mut q = [0.0; 2];
        for (i, qi) in q.iter_mut().enumerate() {
            let r = p - self.base(i);
            let rho = r.length();
            let arg = (self.l1 * self.l1 + rho * rho - self.l2 * self.l2) / (2.0 * self.l1 * rho);
            if !(-1.0..=1.0).contains(&arg) {
                return Err(DeviceFault::Unreachable {
                    pantograph: self.index,
                    motor: i as u8 + 1,
                    arg,
                });
            }
            let phi = r.y.atan2(r.x);
            let gamma = arg.acos();
            *qi = if i == 0 { phi + gamma } else { phi - gamma };
        }
        Ok(q)
    }
}
