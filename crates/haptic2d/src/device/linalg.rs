//! Tiny fixed-size linear algebra for the device model: 3-vectors (handle coordinates `x, y, θ`),
//! 4-vectors (joint coordinates), the 4×3 Jacobian and 3×3 matrices. No heap, no external crate.

/// A handle-space 3-vector `(x, y, θ)`: pose (m, m, rad), twist (m/s, m/s, rad/s) or wrench (N, N, N·m).
pub type V3 = [f64; 3];
/// A joint-space 4-vector, ordered `(q_11, q_12, q_21, q_22)`: angles (rad), rates (rad/s) or torques (N·m).
pub type V4 = [f64; 4];
/// A 3×3 matrix, row-major (`m[row][col]`).
pub type M3 = [[f64; 3]; 3];
/// A 4×3 matrix, row-major: the device Jacobian `J_a` maps handle twists to joint rates (`q̇ = J_a·ẋ`).
pub type M43 = [[f64; 3]; 4];

/// The 3×3 zero matrix.
pub const M3_ZERO: M3 = [[0.0; 3]; 3];

/// `a·b` for 3-vectors.
#[inline]
pub fn dot3(a: &V3, b: &V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a·b` for 4-vectors.
#[inline]
pub fn dot4(a: &V4, b: &V4) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// Euclidean norm of a 4-vector.
#[inline]
pub fn norm4(a: &V4) -> f64 {
    dot4(a, a).sqrt()
}

/// `M·v` for a 3×3 matrix.
#[inline]
pub fn m3_mul_v(m: &M3, v: &V3) -> V3 {
    [dot3(&m[0], v), dot3(&m[1], v), dot3(&m[2], v)]
}

/// `J·v` (4×3 times 3-vector → 4-vector), e.g. `q̇ = J_a·ẋ`.
#[inline]
pub fn j_mul_v(j: &M43, v: &V3) -> V4 {
    [
        dot3(&j[0], v),
        dot3(&j[1], v),
        dot3(&j[2], v),
        dot3(&j[3], v),
    ]
}

/// `Jᵀ·t` (3×4 times 4-vector → 3-vector), e.g. the handle wrench `W = J_aᵀ·τ`.
#[inline]
pub fn jt_mul_v(j: &M43, t: &V4) -> V3 {
    let mut w = [0.0; 3];
    for (row, ti) in j.iter().zip(t.iter()) {
        for c in 0..3 {
            w[c] += row[c] * ti;
        }
    }
    w
}

/// `Jᵀ·diag(d)·J` (3×3, symmetric) for a 4×3 `J` and joint weights `d`.
#[inline]
pub fn jt_d_j(j: &M43, d: &V4) -> M3 {
    let mut m = M3_ZERO;
    for (row, di) in j.iter().zip(d.iter()) {
        for r in 0..3 {
            for c in 0..3 {
                m[r][c] += row[r] * di * row[c];
            }
        }
    }
    m
}

/// Determinant of a 3×3 matrix.
#[inline]
pub fn det3(m: &M3) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Inverse of a 3×3 matrix by the adjugate. Returns `None` when `|det| ≤ 1e-300` or the result is not
/// finite (callers turn this into a singularity fault).
pub fn inv3(m: &M3) -> Option<M3> {
    let det = det3(m);
    if !det.is_finite() || det.abs() <= 1e-300 {
        return None;
    }
    let inv_det = 1.0 / det;
    let mut r = M3_ZERO;
    r[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * inv_det;
    r[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * inv_det;
    r[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * inv_det;
    r[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * inv_det;
    r[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * inv_det;
    r[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * inv_det;
    r[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * inv_det;
    r[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * inv_det;
    r[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * inv_det;
    if r.iter().flatten().all(|v| v.is_finite()) {
        Some(r)
    } else {
        None
    }
}

/// Solves `M·x = b` for a 3×3 `M` (via [`inv3`]); `None` when `M` is singular.
pub fn solve3(m: &M3, b: &V3) -> Option<V3> {
    inv3(m).map(|mi| m3_mul_v(&mi, b))
}

/// Eigenvalues of a symmetric 3×3 matrix, ascending, by cyclic Jacobi rotations (converges to machine
/// precision in a handful of sweeps for 3×3).
#[allow(clippy::needless_range_loop)] // index form mirrors the rotation formulas
pub fn sym3_eigenvalues(m: &M3) -> V3 {
    let mut a = *m;
    for _sweep in 0..50 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let scale = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off <= 1e-32 * scale.max(1e-300) {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            // Classic Jacobi rotation zeroing a[p][q].
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Gᵀ A G with G the rotation in the (p, q) plane.
            for k in 0..3 {
                let akp = a[k][p];
                let akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let apk = a[p][k];
                let aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
        }
    }
    let mut e = [a[0][0], a[1][1], a[2][2]];
    e.sort_by(|x, y| x.total_cmp(y));
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn inverse_and_eigenvalues() {
        let m = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let mi = inv3(&m).expect("regular");
        for r in 0..3 {
            for c in 0..3 {
                let mut s = 0.0;
                for k in 0..3 {
                    s += m[r][k] * mi[k][c];
                }
                let e = if r == c { 1.0 } else { 0.0 };
                assert!((s - e).abs() < 1e-14);
            }
        }
        let ev = sym3_eigenvalues(&m);
        let tr = m[0][0] + m[1][1] + m[2][2];
        assert!((ev.iter().sum::<f64>() - tr).abs() < 1e-12);
        assert!((ev[0] * ev[1] * ev[2] - det3(&m)).abs() < 1e-10);
        assert!(inv3(&[[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]]).is_none());
    }
}
