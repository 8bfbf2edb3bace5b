//! Statics and actuation-redundancy resolution (§10.5): `W = J_aᵀ·τ`; minimum-norm and weighted
//! solutions, the internal-preload null vector `ν` with a fixed sign, and direction-preserving
//! saturation.

use super::fault::DeviceFault;
use super::linalg::{det3, inv3, j_mul_v, jt_d_j, m3_mul_v, M3, M43, V3, V4};

/// The unit null vector `ν` of `J_aᵀ` (`J_aᵀ·ν = 0`), as the generalized cross product of the three
/// columns of `J_a`: `ν_i = (−1)^i·det(J_a without row i)`, normalised. Sign convention (fixed once):
/// the largest-magnitude component is positive, so a given preload `ρ` always squeezes the same way.
pub fn null_vector(j: &M43) -> Result<V4, DeviceFault> {
    let mut nu = [0.0; 4];
    for (i, nui) in nu.iter_mut().enumerate() {
        let mut minor: M3 = [[0.0; 3]; 3];
        let mut r = 0;
        for (k, row) in j.iter().enumerate() {
            if k != i {
                minor[r] = *row;
                r += 1;
            }
        }
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        *nui = sign * det3(&minor);
    }
    let norm = nu.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(DeviceFault::Singular);
    }
    let mut imax = 0;
    for i in 1..4 {
        if nu[i].abs() > nu[imax].abs() {
            imax = i;
        }
    }
    let s = if nu[imax] < 0.0 { -1.0 } else { 1.0 } / norm;
    Ok(nu.map(|v| v * s))
}

/// Minimum-norm joint torques (N·m) producing handle wrench `w` (N, N, N·m):
/// `τ = J_a·(J_aᵀJ_a)⁻¹·W_d`. Among all solutions it minimises `Σ τ_i²`.
pub fn min_norm_torques(j: &M43, w: &V3) -> Result<V4, DeviceFault> {
    weighted_torques(j, w, &[1.0; 4])
}

/// Weighted solution `τ = Λ⁻¹J_a(J_aᵀΛ⁻¹J_a)⁻¹W_d` with `Λ⁻¹ = diag(lambda_inv)`. For the spec's
/// weighting by actuator limits use `lambda_inv = τ_max,i²` (N²·m²); `[1; 4]` gives minimum norm.
pub fn weighted_torques(j: &M43, w: &V3, lambda_inv: &V4) -> Result<V4, DeviceFault> {
    if !w.iter().all(|v| v.is_finite()) {
        return Err(DeviceFault::NonFinite);
    }
    let g = jt_d_j(j, lambda_inv);
    let gi = inv3(&g).ok_or(DeviceFault::Singular)?;
    let y = m3_mul_v(&gi, w);
    let t = j_mul_v(j, &y);
    Ok([
        lambda_inv[0] * t[0],
        lambda_inv[1] * t[1],
        lambda_inv[2] * t[2],
        lambda_inv[3] * t[3],
    ])
}

/// Result of [`saturate`]: the torques to send and what saturation did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Saturated {
    /// Joint torques (N·m), each `|τ_i| ≤ τ_max`.
    pub tau: V4,
    /// Factor `∈ [0, 1]` applied to the wrench part (1 = not saturated).
    pub wrench_scale: f64,
}

/// Direction-preserving saturation of `τ = τ_wrench + ρ·ν`: if `max_i |τ_i| > τ_max`, the wrench part
/// is scaled by `min_i (τ_max − |ρ·ν_i|)/|τ_wrench,i|` so the handle wrench keeps its direction and the
/// preload is kept. The preload is first clamped to `|ρ| ≤ 0.1·τ_max` (§10.5).
pub fn saturate(tau_wrench: &V4, rho: f64, nu: &V4, tau_max: f64) -> Saturated {
    let rho = rho.clamp(-0.1 * tau_max, 0.1 * tau_max);
    let total = |s: f64| -> V4 { std::array::from_fn(|i| s * tau_wrench[i] + rho * nu[i]) };
    let t = total(1.0);
    if t.iter().all(|v| v.abs() <= tau_max) {
        return Saturated {
            tau: t,
            wrench_scale: 1.0,
        };
    }
    let mut scale: f64 = 1.0;
    for i in 0..4 {
        let tw = tau_wrench[i].abs();
        if tw > 0.0 {
            scale = scale.min((tau_max - (rho * nu[i]).abs()) / tw);
        }
    }
    let scale = scale.max(0.0);
    Saturated {
        tau: total(scale),
        wrench_scale: scale,
    }
}
