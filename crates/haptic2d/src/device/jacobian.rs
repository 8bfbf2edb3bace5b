//! The device Jacobian `J_a` (4×3, `q̇ = J_a·ẋ`), its time derivative, the singularity margin and the
//! scaled condition number (§10.4).

use crate::geom::{cross, perp, Vec2};

use super::fault::DeviceFault;
use super::five_bar::e_of;
use super::linalg::{jt_d_j, sym3_eigenvalues, M43, V3};
use super::twin::{Configuration, TwinKinematics};

/// Smallest `|l1·(P − E)·e⊥(q)|` (m²) accepted before a row of `J_a` is declared singular.
const DEN_EPS: f64 = 1e-12;

/// Index of the pantograph (0 or 1) that joint `i` (0..4) belongs to.
#[inline]
fn pantograph_of(i: usize) -> usize {
    i / 2
}

/// `J_a` at a configuration: `row(j,i) = (P_j − E_ji)ᵀ·A_j / (l1·(P_j − E_ji)·e⊥(q_ji))` with
/// `A_1 = [I₂ | 0]`, `A_2 = [I₂ | r_c·e⊥(θ)]` (rad/m for the x, y columns, rad/rad for θ).
///
/// Derivation: differentiating `|P − E_i(q_i)|² = l2²` gives `(P − E)·Ṗ = l1·q̇·(P − E)·e⊥(q)`.
pub fn jacobian_at(kin: &TwinKinematics, cfg: &Configuration) -> Result<M43, DeviceFault> {
    let l1 = kin.pantographs[0].l1;
    let ep_theta = perp(e_of(cfg.x[2]));
    let mut j = [[0.0; 3]; 4];
    for (i, row) in j.iter_mut().enumerate() {
        let pj = pantograph_of(i);
        let n = cfg.p[pj] - cfg.e[i];
        let den = l1 * n.dot(perp(e_of(cfg.q[i])));
        if den.abs() <= DEN_EPS || !den.is_finite() {
            return Err(DeviceFault::Singular);
        }
        let rot = if pj == 1 {
            kin.r_c * n.dot(ep_theta)
        } else {
            0.0
        };
        *row = [n.x / den, n.y / den, rot / den];
    }
    Ok(j)
}

/// `J_a` at handle pose `x` (computed through device inverse kinematics).
pub fn jacobian(kin: &TwinKinematics, x: &V3) -> Result<M43, DeviceFault> {
    jacobian_at(kin, &kin.configuration(x)?)
}

/// The time derivative `J̇_a` (4×3) at a configuration moving with handle twist `xd`, analytic:
/// with `a = (P − E)ᵀA_j` and `den = l1·(P − E)·e⊥(q)`, `roẇ = ȧ/den − a·ḋen/den²`, where
/// `ṅ = Ṗ_j − Ė`, `Ṗ_j = A_j·ẋ`, `Ė = l1·q̇·e⊥(q)`, `ȧ = (ṅ_x, ṅ_y, r_c(ṅ·e⊥(θ) − θ̇·n·e(θ)))` and
/// `ḋen = l1·(ṅ·e⊥(q) − q̇·n·e(q))`.
pub fn jacobian_dot_at(kin: &TwinKinematics, cfg: &Configuration, j: &M43, xd: &V3) -> M43 {
    let l1 = kin.pantographs[0].l1;
    let e_theta = e_of(cfg.x[2]);
    let ep_theta = perp(e_theta);
    let v1 = Vec2::new(xd[0], xd[1]);
    let pdot = [v1, v1 + kin.r_c * xd[2] * ep_theta];
    let mut jd = [[0.0; 3]; 4];
    for (i, row_dot) in jd.iter_mut().enumerate() {
        let pj = pantograph_of(i);
        let eq = e_of(cfg.q[i]);
        let epq = perp(eq);
        let n = cfg.p[pj] - cfg.e[i];
        let den = l1 * n.dot(epq);
        let row = &j[i];
        let qd = row[0] * xd[0] + row[1] * xd[1] + row[2] * xd[2];
        let ndot = pdot[pj] - l1 * qd * epq;
        let den_dot = l1 * (ndot.dot(epq) - qd * n.dot(eq));
        let a = [row[0] * den, row[1] * den, row[2] * den];
        let a_dot = if pj == 1 {
            [
                ndot.x,
                ndot.y,
                kin.r_c * (ndot.dot(ep_theta) - xd[2] * n.dot(e_theta)),
            ]
        } else {
            [ndot.x, ndot.y, 0.0]
        };
        for c in 0..3 {
            row_dot[c] = a_dot[c] / den - a[c] * den_dot / (den * den);
        }
    }
    jd
}

/// Singularity margin at a configuration (dimensionless, in `[0, 1]`): the minimum over pantographs
/// and motors of `|sin|` of the proximal–distal angle (type 1) and of the distal–distal angle (type 2).
pub fn singularity_margin_at(kin: &TwinKinematics, cfg: &Configuration) -> f64 {
    let l1 = kin.pantographs[0].l1;
    let l2 = kin.pantographs[0].l2;
    let mut m = f64::INFINITY;
    for pj in 0..2 {
        let mut distal = [Vec2::ZERO; 2];
        for (k, d) in distal.iter_mut().enumerate() {
            let i = 2 * pj + k;
            *d = (cfg.p[pj] - cfg.e[i]) / l2;
            let proximal = (cfg.e[i] - kin.pantographs[pj].base(k)) / l1;
            m = m.min(cross(proximal, *d).abs());
        }
        m = m.min(cross(distal[0], distal[1]).abs());
    }
    m
}

/// Singularity margin at handle pose `x` (see [`singularity_margin_at`]); errors when `x` is unreachable.
pub fn singularity_margin(kin: &TwinKinematics, x: &V3) -> Result<f64, DeviceFault> {
    Ok(singularity_margin_at(kin, &kin.configuration(x)?))
}

/// 2-norm condition number `σ_max/σ_min` of `J_a` with its rotation column scaled by `1/r_c`
/// (so that all three columns are in rad/m), from the eigenvalues of the 3×3 `JᵀJ`.
pub fn condition_number(j: &M43, r_c: f64) -> f64 {
    let mut js = *j;
    for row in js.iter_mut() {
        row[2] /= r_c;
    }
    let ev = sym3_eigenvalues(&jt_d_j(&js, &[1.0; 4]));
    if ev[0] <= 0.0 {
        return f64::INFINITY;
    }
    (ev[2] / ev[0]).sqrt()
}
