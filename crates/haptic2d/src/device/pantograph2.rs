//! The 2-DOF five-bar of a Haply 2DIY (docs/DEVICES.md §2), in the board's own frame: motor 1 at `(0, 0)`,
//! motor 2 at `(d, 0)`, `d ≥ 0` (0 on gen 2, 0.038 m on gen 3). It reuses [`FiveBar`] (motor axes at
//! `∓d/2`) shifted by `d/2` in x, and adds the 2×2 Jacobian and `τ = Jᵀ f`.
//!
//! Jacobian. With elbows `A_i = B_i + l1·e(q_i)` and distal vectors `u_i = E − A_i`, the loop closure
//! `|E − A_i|² = l2²` differentiates to `u_i·(Ė − Ȧ_i) = 0`, `Ȧ_i = l1·q̇_i·perp(e(q_i))`, so
//!
//! ```text
//! U·Ė = D·q̇,   U = [u_1ᵀ; u_2ᵀ],   D = diag(l1·u_1·perp(e_1), l1·u_2·perp(e_2)),
//! J = ∂E/∂q = U⁻¹·D,               det U = u_1 × u_2 (zero when the distal links are aligned).
//! ```
//!
//! The singularity margin is `|u_1 × u_2| / l2²` (the sine of the angle between the distal links,
//! dimensionless in `[0, 1]`), the 2-DOF counterpart of §10.4.

use crate::geom::{cross, perp, Vec2};

use super::fault::DeviceFault;
use super::five_bar::{e_of, FiveBar};

/// A 2×2 matrix, row-major.
pub type M2 = [[f64; 2]; 2];

/// Geometry of one 2DIY linkage (m), board frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pantograph2 {
    /// Motor spacing `d` (m): motor 2 sits at `(d, 0)`. May be 0.
    pub d: f64,
    /// Proximal link length `l1` (m).
    pub l1: f64,
    /// Distal link length `l2` (m).
    pub l2: f64,
}

/// Kinematic state at one pair of motor angles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pantograph2State {
    /// End point `E` (m, board frame).
    pub e: Vec2,
    /// `J = ∂E/∂q` (m/rad), row-major: `J[r][c] = ∂E_r/∂q_c`.
    pub j: M2,
    /// Singularity margin `|u_1 × u_2| / l2²` (dimensionless).
    pub margin: f64,
}

impl Pantograph2 {
    /// The linkage `d`, `l1`, `l2` (m). Errors name the bad value.
    pub fn new(d: f64, l1: f64, l2: f64) -> Result<Self, String> {
        if !(d.is_finite() && d >= 0.0) {
            return Err(format!(
                "d = {d} m: the motor spacing must be a finite number ≥ 0"
            ));
        }
        if !(l1.is_finite() && l1 > 0.0 && l2.is_finite() && l2 > 0.0) {
            return Err(format!(
                "l1 = {l1} m, l2 = {l2} m: link lengths must be finite numbers > 0"
            ));
        }
        if 2.0 * l2 <= d {
            return Err(format!(
                "l2 = {l2} m must exceed d/2 = {} m for the distal links to meet",
                d / 2.0
            ));
        }
        Ok(Self { d, l1, l2 })
    }

    fn bar(&self) -> FiveBar {
        FiveBar {
            s: self.d,
            l1: self.l1,
            l2: self.l2,
            index: 1,
        }
    }

    /// Shift from the [`FiveBar`] frame (motors at `∓d/2`) to the board frame (m).
    #[inline]
    fn shift(&self) -> Vec2 {
        Vec2::new(0.5 * self.d, 0.0)
    }

    /// Elbows `A`, `B` (m, board frame) at motor angles `q` (rad, from +x, CCW).
    pub fn elbows(&self, q: [f64; 2]) -> [Vec2; 2] {
        let s = self.shift();
        let [a, b] = self.bar().elbows(q);
        [a + s, b + s]
    }

    /// Forward kinematics: end point `E` (m, board frame), branch away from the base.
    pub fn fk(&self, q: [f64; 2]) -> Result<Vec2, DeviceFault> {
        Ok(self.bar().fk(q)? + self.shift())
    }

    /// Inverse kinematics, elbows out: motor angles (rad) putting the end point at `e` (m).
    pub fn ik(&self, e: Vec2) -> Result<[f64; 2], DeviceFault> {
        self.bar().ik(e - self.shift())
    }

    /// End point, Jacobian and singularity margin at motor angles `q` (rad).
    pub fn state(&self, q: [f64; 2]) -> Result<Pantograph2State, DeviceFault> {
        let e = self.fk(q)?;
        let [a, b] = self.elbows(q);
        let (u1, u2) = (e - a, e - b);
        let det = cross(u1, u2);
        let margin = det.abs() / (self.l2 * self.l2);
        if det.is_nan() || det.abs() <= 1e-12 {
            return Err(DeviceFault::Singular);
        }
        let d1 = self.l1 * u1.dot(perp(e_of(q[0])));
        let d2 = self.l1 * u2.dot(perp(e_of(q[1])));
        // U⁻¹ = [[u2y, −u1y], [−u2x, u1x]] / det; J = U⁻¹·diag(d1, d2).
        let j = [
            [u2.y * d1 / det, -u1.y * d2 / det],
            [-u2.x * d1 / det, u1.x * d2 / det],
        ];
        Ok(Pantograph2State { e, j, margin })
    }
}

/// `Jᵀ·f`: motor torques (N·m) for an end-point force `f` (N).
#[inline]
pub fn jt_mul(j: &M2, f: [f64; 2]) -> [f64; 2] {
    [
        j[0][0] * f[0] + j[1][0] * f[1],
        j[0][1] * f[0] + j[1][1] * f[1],
    ]
}

/// `J·q̇`: end-point velocity (m/s) for motor rates `qd` (rad/s).
#[inline]
pub fn j_mul(j: &M2, qd: [f64; 2]) -> [f64; 2] {
    [
        j[0][0] * qd[0] + j[0][1] * qd[1],
        j[1][0] * qd[0] + j[1][1] * qd[1],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gen3() -> Pantograph2 {
        Pantograph2::new(0.038, 0.07, 0.09).unwrap()
    }

    #[test]
    fn ik_fk_round_trip_with_d() {
        let p = gen3();
        for e in [
            Vec2::new(0.019, 0.10),
            Vec2::new(0.0, 0.08),
            Vec2::new(0.04, 0.12),
        ] {
            let q = p.ik(e).unwrap();
            let e2 = p.fk(q).unwrap();
            assert!((e2 - e).length() < 1e-12, "{e:?} -> {e2:?}");
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        for p in [gen3(), Pantograph2::new(0.0, 0.07, 0.09).unwrap()] {
            let q = p.ik(Vec2::new(p.d / 2.0 + 0.01, 0.1)).unwrap();
            let s = p.state(q).unwrap();
            let h = 1e-7;
            for c in 0..2 {
                let mut qp = q;
                let mut qm = q;
                qp[c] += h;
                qm[c] -= h;
                let d = (p.fk(qp).unwrap() - p.fk(qm).unwrap()) / (2.0 * h);
                assert!(
                    (d.x - s.j[0][c]).abs() < 1e-6,
                    "col {c}: {d:?} vs {:?}",
                    s.j
                );
                assert!(
                    (d.y - s.j[1][c]).abs() < 1e-6,
                    "col {c}: {d:?} vs {:?}",
                    s.j
                );
            }
            assert!(s.margin > 0.1 && s.margin <= 1.0);
        }
    }

    #[test]
    fn published_rest_angles_assemble() {
        // docs/DEVICES.md §2: gen 2 offsets (241°, −61°) and gen 3 (168°, 12°) are valid assemblies.
        let g2 = Pantograph2::new(0.0, 0.07, 0.09).unwrap();
        let e = g2.fk([241f64.to_radians(), (-61f64).to_radians()]).unwrap();
        assert!(e.x.abs() < 1e-9 && e.y > 0.0, "{e:?}");
        let e3 = gen3()
            .fk([168f64.to_radians(), 12f64.to_radians()])
            .unwrap();
        assert!((e3.x - 0.019).abs() < 1e-9 && e3.y > 0.0, "{e3:?}");
    }

    #[test]
    fn bad_geometry_is_an_error() {
        assert!(Pantograph2::new(-0.01, 0.07, 0.09).is_err());
        assert!(Pantograph2::new(0.2, 0.07, 0.09).is_err());
        assert!(Pantograph2::new(0.0, f64::NAN, 0.09).is_err());
    }
}
