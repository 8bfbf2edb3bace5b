//! Lumped-mass rigid-body dynamics of the twin pantograph in handle coordinates (§10.6):
//! `M_x(x)·ẍ + c(x, ẋ) = J_aᵀ·(τ − τ_f) + W_h`.
//!
//! Lumping: each distal link's mass is split half to its elbow and half to its endpoint; its rotational
//! inertia beyond these point masses is neglected. Joint inertia `I_j = I_rot·n_g² + I_p + (m_d/2)·l1²`
//! (constant, so joint space has no Coriolis terms); endpoint masses `m_e1 = m_e2 = m_d + m_ee`; the
//! handle (`m_h`, `I_h`) sits at `P_1`.

use crate::geom::Vec2;

use super::fault::DeviceFault;
use super::five_bar::e_of;
use super::jacobian::{jacobian_at, jacobian_dot_at};
use super::linalg::{dot3, j_mul_v, jt_d_j, jt_mul_v, m3_mul_v, M3, M43, V3, V4};
use super::params::DeviceParams;
use super::twin::{Configuration, TwinKinematics};

/// Sign function with `sgn(0) = 0` (so a joint at rest gets no Coulomb torque).
#[inline]
pub fn sgn(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The lumped-mass model of the device.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LumpedDynamics {
    /// The kinematics.
    pub kin: TwinKinematics,
    /// Effective joint inertia `I_j` (kg·m²), the same for all four joints.
    pub joint_inertia: f64,
    /// Point mass at `P_1`: `m_e1 + m_h` (kg).
    pub mass_p1: f64,
    /// Point mass at `P_2`: `m_e2` (kg).
    pub mass_p2: f64,
    /// Handle inertia about `P_1`, `I_h` (kg·m²).
    pub handle_inertia: f64,
    /// Joint Coulomb friction `f_c` (N·m).
    pub f_c: f64,
    /// Joint viscous friction `f_v` (N·m·s/rad).
    pub f_v: f64,
}

/// Every dynamic term at one state `(x, ẋ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicsTerms {
    /// The configuration (joint angles, endpoints, elbows).
    pub cfg: Configuration,
    /// `J_a` (4×3).
    pub j: M43,
    /// Joint rates `q̇ = J_a·ẋ` (rad/s).
    pub qd: V4,
    /// Mass matrix `M_x` (kg, kg·m, kg·m²).
    pub m: M3,
    /// Velocity-product term `c(x, ẋ)` (N, N, N·m).
    pub c: V3,
    /// `J̇_aᵀ·D_I·J_a·ẋ + m_e2·Ȧ_2ᵀ·A_2·ẋ = Ṁ_x·ẋ − c` (N, N, N·m), used by the momentum observer.
    pub momentum_bias: V3,
}

impl LumpedDynamics {
    /// The model of the device described by `p`.
    pub fn new(p: &DeviceParams) -> Self {
        Self {
            kin: TwinKinematics::new(p),
            joint_inertia: p.joint_inertia(),
            mass_p1: p.mass_at_p1(),
            mass_p2: p.mass_at_p2(),
            handle_inertia: p.i_h,
            f_c: p.f_c,
            f_v: p.f_v,
        }
    }

    /// `M_x = J_aᵀ·D_I·J_a + (m_e1 + m_h)·A_1ᵀA_1 + m_e2·A_2ᵀA_2 + diag(0, 0, I_h)` at pose angle `theta`.
    pub fn mass_matrix(&self, j: &M43, theta: f64) -> M3 {
        let mut m = jt_d_j(j, &[self.joint_inertia; 4]);
        let ep = e_of(theta).perp();
        let r = self.kin.r_c;
        let m12 = self.mass_p1 + self.mass_p2;
        m[0][0] += m12;
        m[1][1] += m12;
        m[0][2] += self.mass_p2 * r * ep.x;
        m[2][0] += self.mass_p2 * r * ep.x;
        m[1][2] += self.mass_p2 * r * ep.y;
        m[2][1] += self.mass_p2 * r * ep.y;
        m[2][2] += self.mass_p2 * r * r + self.handle_inertia;
        m
    }

    /// Joint friction `τ_f,i = f_c·sgn(q̇_i) + f_v·q̇_i` (N·m) at joint rates `qd` (rad/s).
    pub fn joint_friction(&self, qd: &V4) -> V4 {
        qd.map(|v| self.f_c * sgn(v) + self.f_v * v)
    }

    /// The friction compensation's feed-forward at estimated joint rates `qd` (rad/s), §10.5: the
    /// model's friction `f_c·sgn(q̇_i) + f_v·q̇_i` (N·m) in the direction of motion, with the Coulomb
    /// part dropped on a joint whose `|q̇_i|` is below `deadband` (rad/s). The caller scales it by
    /// the compensated fraction and saturates it with the rest of the torques.
    pub fn friction_feedforward(&self, qd: &V4, deadband: f64) -> V4 {
        qd.map(|v| {
            let coulomb = if v.abs() < deadband {
                0.0
            } else {
                self.f_c * sgn(v)
            };
            coulomb + self.f_v * v
        })
    }

    /// Every dynamic term at pose `x` and twist `xd`. `c` uses the analytic `J̇_a` (§10.6 allows a
    /// numerical one; the analytic form makes the simulated plant exactly energy-consistent).
    pub fn terms(&self, x: &V3, xd: &V3) -> Result<DynamicsTerms, DeviceFault> {
        let cfg = self.kin.configuration(x)?;
        let j = jacobian_at(&self.kin, &cfg)?;
        let jd = jacobian_dot_at(&self.kin, &cfg, &j, xd);
        let qd = j_mul_v(&j, xd);
        let m = self.mass_matrix(&j, x[2]);
        let r = self.kin.r_c;
        let e = e_of(x[2]);
        let v = Vec2::new(xd[0], xd[1]);
        // c = J_aᵀ·D_I·(J̇_a·ẋ) + m_e2·A_2ᵀ·(Ȧ_2·ẋ),  Ȧ_2·ẋ = −r_c·θ̇²·e(θ) (so its θ entry vanishes).
        let jd_xd = j_mul_v(&jd, xd);
        let mut c = jt_mul_v(&j, &jd_xd.map(|v| v * self.joint_inertia));
        let u = -r * xd[2] * xd[2] * e;
        c[0] += self.mass_p2 * u.x;
        c[1] += self.mass_p2 * u.y;
        // Ṁ_x·ẋ − c = J̇_aᵀ·D_I·J_a·ẋ + m_e2·Ȧ_2ᵀ·A_2·ẋ,  Ȧ_2ᵀ·A_2·ẋ = (0, 0, −r_c·θ̇·e(θ)·v).
        let mut mb = jt_mul_v(&jd, &qd.map(|v| v * self.joint_inertia));
        mb[2] += self.mass_p2 * (-r * xd[2] * e.dot(v));
        Ok(DynamicsTerms {
            cfg,
            j,
            qd,
            m,
            c,
            momentum_bias: mb,
        })
    }

    /// Kinetic energy `½·ẋᵀ·M_x·ẋ` (J) at pose `x` and twist `xd`.
    pub fn kinetic_energy(&self, x: &V3, xd: &V3) -> Result<f64, DeviceFault> {
        let j = jacobian_at(&self.kin, &self.kin.configuration(x)?)?;
        let m = self.mass_matrix(&j, x[2]);
        Ok(0.5 * dot3(xd, &m3_mul_v(&m, xd)))
    }
}

#[cfg(test)]
mod friction_tests {
    use super::*;
    use crate::device::DeviceParams;

    #[test]
    fn friction_feedforward_drops_the_coulomb_part_inside_the_deadband_only() {
        let m = LumpedDynamics::new(&DeviceParams {
            f_c: 0.015,
            f_v: 1e-3,
            ..DeviceParams::default()
        });
        let qd = [0.01, -0.01, 0.2, -0.2];
        let ff = m.friction_feedforward(&qd, 0.05);
        let expect = [1e-5, -1e-5, 0.015 + 2e-4, -0.015 - 2e-4];
        for i in 0..4 {
            assert!((ff[i] - expect[i]).abs() < 1e-15, "{ff:?}");
        }
        // With no deadband it is the model's friction itself.
        assert_eq!(m.friction_feedforward(&qd, 0.0), m.joint_friction(&qd));
    }
}
