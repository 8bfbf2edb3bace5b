//! Eigenvalues of a small dense real matrix, and roots of a real polynomial (through its companion
//! matrix). The classical route (Wilkinson & Reinsch; *Numerical Recipes* §11.5–11.6):
//!
//! 1. **balance**: similarity scaling by powers of 2 so that row and column norms are comparable
//!    (the loop matrices mix `K/m ≈ 5e4 s⁻²` with `1`; balancing keeps rounding relative);
//! 2. **reduce to upper Hessenberg form** by stabilised elementary similarity transformations
//!    (Gaussian elimination with pivoting below the sub-diagonal);
//! 3. **Francis double-shift QR** on the Hessenberg matrix: each sweep applies the two shifts given
//!    by the trailing 2×2 block (a complex-conjugate pair in real arithmetic) through Householder
//!    reflections of size 3; a negligible sub-diagonal entry deflates one real eigenvalue or a 2×2
//!    block (a real pair or a complex pair). Exceptional shifts at iterations 10 and 20 break cycles.
//!
//! Cost O(n³); the loop matrices are at most 9 × 9.

// Index loops on purpose: the algorithms read like their textbook statements.
#![allow(clippy::needless_range_loop)]

use super::dense::Mat;

/// A complex number `(re, im)`.
pub type Complex = (f64, f64);

/// Eigenvalues of `m` (any order; complex ones in conjugate pairs). Errors if the QR iteration
/// does not converge in 30 iterations for some eigenvalue, or if `m` has a non-finite entry.
pub fn eigenvalues(m: &Mat) -> Result<Vec<Complex>, String> {
    let n = m.n;
    if m.a.iter().any(|v| !v.is_finite()) {
        return Err("eigenvalues: the matrix has a non-finite entry".into());
    }
    if n == 0 {
        return Ok(Vec::new());
    }
    // 1-indexed working copy, (n+1)×(n+1), so the code below reads like the textbook algorithm.
    let mut a = vec![vec![0.0; n + 1]; n + 1];
    for i in 0..n {
        for j in 0..n {
            a[i + 1][j + 1] = m.get(i, j);
        }
    }
    balance(&mut a, n);
    hessenberg(&mut a, n);
    hqr(&mut a, n)
}

/// Roots of `c[0]·sⁿ + c[1]·sⁿ⁻¹ + … + c[n]` (highest power first; `c[0] ≠ 0`): the eigenvalues of
/// the companion matrix (first row `−c[1..]/c[0]`, ones on the sub-diagonal).
pub fn poly_roots(c: &[f64]) -> Result<Vec<Complex>, String> {
    let lead = *c.first().ok_or("poly_roots: no coefficients")?;
    if lead == 0.0 || !lead.is_finite() {
        return Err("poly_roots: the leading coefficient must be finite and non-zero".into());
    }
    let n = c.len() - 1;
    let mut m = Mat::zeros(n);
    for j in 0..n {
        m.set(0, j, -c[j + 1] / lead);
    }
    for i in 1..n {
        m.set(i, i - 1, 1.0);
    }
    eigenvalues(&m)
}

/// Similarity balancing by powers of the radix 2 (exact in floating point).
fn balance(a: &mut [Vec<f64>], n: usize) {
    const RADIX: f64 = 2.0;
    let sqrdx = RADIX * RADIX;
    let mut done = false;
    while !done {
        done = true;
        for i in 1..=n {
            let (mut r, mut c) = (0.0, 0.0);
            for j in 1..=n {
                if j != i {
                    c += a[j][i].abs();
                    r += a[i][j].abs();
                }
            }
            if c != 0.0 && r != 0.0 {
                let mut g = r / RADIX;
                let mut f = 1.0;
                let s = c + r;
                while c < g {
                    f *= RADIX;
                    c *= sqrdx;
                }
                g = r * RADIX;
                while c > g {
                    f /= RADIX;
                    c /= sqrdx;
                }
                if (c + r) / f < 0.95 * s {
                    done = false;
                    let g = 1.0 / f;
                    for j in 1..=n {
                        a[i][j] *= g;
                    }
                    for row in a.iter_mut().take(n + 1).skip(1) {
                        row[i] *= f;
                    }
                }
            }
        }
    }
}

/// Reduction to upper Hessenberg form by elimination with pivoting; entries below the sub-diagonal
/// are zeroed afterwards (they held the multipliers).
fn hessenberg(a: &mut [Vec<f64>], n: usize) {
    for m in 2..n {
        let mut x: f64 = 0.0;
        let mut i = m;
        for j in m..=n {
            if a[j][m - 1].abs() > x.abs() {
                x = a[j][m - 1];
                i = j;
            }
        }
        if i != m {
            for j in (m - 1)..=n {
                let t = a[i][j];
                a[i][j] = a[m][j];
                a[m][j] = t;
            }
            for row in a.iter_mut().take(n + 1).skip(1) {
                row.swap(i, m);
            }
        }
        if x != 0.0 {
            for i in (m + 1)..=n {
                let mut y = a[i][m - 1];
                if y != 0.0 {
                    y /= x;
                    a[i][m - 1] = y;
                    for j in m..=n {
                        a[i][j] -= y * a[m][j];
                    }
                    for row in a.iter_mut().take(n + 1).skip(1) {
                        row[m] += y * row[i];
                    }
                }
            }
        }
    }
    for i in 3..=n {
        for j in 1..(i - 1) {
            a[i][j] = 0.0;
        }
    }
}

fn sign(a: f64, b: f64) -> f64 {
    if b >= 0.0 {
        a.abs()
    } else {
        -a.abs()
    }
}

/// Francis double-shift QR on an upper Hessenberg matrix (1-indexed); returns its eigenvalues.
#[allow(clippy::many_single_char_names, unused_assignments)]
fn hqr(a: &mut [Vec<f64>], n: usize) -> Result<Vec<Complex>, String> {
    let mut wr = vec![0.0; n + 1];
    let mut wi = vec![0.0; n + 1];
    let mut anorm = 0.0;
    for i in 1..=n {
        for j in (i.max(2) - 1)..=n {
            anorm += a[i][j].abs();
        }
    }
    let mut nn = n;
    let mut t = 0.0;
    let (mut p, mut q, mut r) = (0.0, 0.0, 0.0);
    while nn >= 1 {
        let mut its = 0;
        loop {
            // Look for a single small sub-diagonal element.
            let mut l = nn;
            while l >= 2 {
                let mut s = a[l - 1][l - 1].abs() + a[l][l].abs();
                if s == 0.0 {
                    s = anorm;
                }
                if a[l][l - 1].abs() + s == s {
                    a[l][l - 1] = 0.0;
                    break;
                }
                l -= 1;
            }
            let mut x = a[nn][nn];
            if l == nn {
                // One root found.
                wr[nn] = x + t;
                wi[nn] = 0.0;
                nn -= 1;
            } else {
                let mut y = a[nn - 1][nn - 1];
                let mut w = a[nn][nn - 1] * a[nn - 1][nn];
                if l == nn - 1 {
                    // Two roots found: the eigenvalues of the trailing 2×2 block.
                    p = 0.5 * (y - x);
                    q = p * p + w;
                    let mut z = q.abs().sqrt();
                    x += t;
                    if q >= 0.0 {
                        z = p + sign(z, p);
                        wr[nn - 1] = x + z;
                        wr[nn] = wr[nn - 1];
                        if z != 0.0 {
                            wr[nn] = x - w / z;
                        }
                        wi[nn - 1] = 0.0;
                        wi[nn] = 0.0;
                    } else {
                        wr[nn - 1] = x + p;
                        wr[nn] = x + p;
                        wi[nn - 1] = -z;
                        wi[nn] = z;
                    }
                    nn -= 2;
                } else {
                    if its == 30 {
                        return Err("eigenvalues: QR iteration did not converge".into());
                    }
                    if its == 10 || its == 20 {
                        // Exceptional shift.
                        t += x;
                        for i in 1..=nn {
                            a[i][i] -= x;
                        }
                        let s = a[nn][nn - 1].abs() + a[nn - 1][nn - 2].abs();
                        x = 0.75 * s;
                        y = x;
                        w = -0.4375 * s * s;
                    }
                    its += 1;
                    // Form the shift and look for two consecutive small sub-diagonal elements.
                    let mut m = nn - 2;
                    let mut z;
                    loop {
                        z = a[m][m];
                        r = x - z;
                        let s = y - z;
                        p = (r * s - w) / a[m + 1][m] + a[m][m + 1];
                        q = a[m + 1][m + 1] - z - r - s;
                        r = a[m + 2][m + 1];
                        let s = p.abs() + q.abs() + r.abs();
                        p /= s;
                        q /= s;
                        r /= s;
                        if m == l {
                            break;
                        }
                        let u = a[m][m - 1].abs() * (q.abs() + r.abs());
                        let v = p.abs() * (a[m - 1][m - 1].abs() + z.abs() + a[m + 1][m + 1].abs());
                        if u + v == v {
                            break;
                        }
                        m -= 1;
                    }
                    for i in (m + 2)..=nn {
                        a[i][i - 2] = 0.0;
                        if i != m + 2 {
                            a[i][i - 3] = 0.0;
                        }
                    }
                    // Double QR step on rows l..nn and columns m..nn.
                    let mut k = m;
                    while k < nn {
                        if k != m {
                            p = a[k][k - 1];
                            q = a[k + 1][k - 1];
                            r = 0.0;
                            if k != nn - 1 {
                                r = a[k + 2][k - 1];
                            }
                            x = p.abs() + q.abs() + r.abs();
                            if x != 0.0 {
                                p /= x;
                                q /= x;
                                r /= x;
                            }
                        }
                        let s = sign((p * p + q * q + r * r).sqrt(), p);
                        if s != 0.0 {
                            if k == m {
                                if l != m {
                                    a[k][k - 1] = -a[k][k - 1];
                                }
                            } else {
                                a[k][k - 1] = -s * x;
                            }
                            p += s;
                            x = p / s;
                            y = q / s;
                            z = r / s;
                            q /= p;
                            r /= p;
                            for j in k..=nn {
                                p = a[k][j] + q * a[k + 1][j];
                                if k != nn - 1 {
                                    p += r * a[k + 2][j];
                                    a[k + 2][j] -= p * z;
                                }
                                a[k + 1][j] -= p * y;
                                a[k][j] -= p * x;
                            }
                            let mmin = if nn < k + 3 { nn } else { k + 3 };
                            for row in a.iter_mut().take(mmin + 1).skip(l) {
                                p = x * row[k] + y * row[k + 1];
                                if k != nn - 1 {
                                    p += z * row[k + 2];
                                    row[k + 2] -= p * r;
                                }
                                row[k + 1] -= p * q;
                                row[k] -= p;
                            }
                        }
                        k += 1;
                    }
                }
            }
            if nn < 2 || l + 1 >= nn {
                break;
            }
        }
    }
    Ok((1..=n).map(|i| (wr[i], wi[i])).collect())
}

/// The eigenvalue with the largest real part (the right-most pole of a continuous-time system).
pub fn rightmost(ev: &[Complex]) -> Complex {
    ev.iter().copied().fold(
        (f64::NEG_INFINITY, 0.0),
        |b, e| if e.0 > b.0 { e } else { b },
    )
}

/// The largest modulus (the spectral radius of a discrete-time state matrix).
pub fn spectral_radius(ev: &[Complex]) -> f64 {
    ev.iter().map(|e| e.0.hypot(e.1)).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted(mut v: Vec<Complex>) -> Vec<Complex> {
        v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        v
    }

    #[test]
    fn roots_of_a_cubic_with_real_roots() {
        // (s − 1)(s − 2)(s − 3) = s³ − 6s² + 11s − 6.
        let r = sorted(poly_roots(&[1.0, -6.0, 11.0, -6.0]).unwrap());
        for (got, want) in r.iter().zip([1.0, 2.0, 3.0]) {
            assert!((got.0 - want).abs() < 1e-10 && got.1.abs() < 1e-10, "{r:?}");
        }
    }

    #[test]
    fn roots_of_a_quartic_with_two_complex_pairs() {
        // (s² + 2s + 5)(s² − 4s + 13): roots −1 ± 2j, 2 ± 3j.
        let c = [1.0, -2.0, 10.0, 6.0, 65.0];
        let r = sorted(poly_roots(&c).unwrap());
        let want = [(-1.0, -2.0), (-1.0, 2.0), (2.0, -3.0), (2.0, 3.0)];
        for (got, w) in r.iter().zip(want) {
            assert!(
                (got.0 - w.0).abs() < 1e-9 && (got.1 - w.1).abs() < 1e-9,
                "{r:?}"
            );
        }
    }

    #[test]
    fn eigenvalues_of_a_badly_scaled_matrix() {
        // Mass–spring–damper chain with mixed scales: compare with the characteristic polynomial.
        // x'' = −(k/m) x − (b/m) x', with k/m = 5e4, b/m = 2: roots −1 ± j·√(5e4 − 1).
        let mut m = Mat::zeros(2);
        m.set(0, 1, 1.0);
        m.set(1, 0, -5e4);
        m.set(1, 1, -2.0);
        let r = eigenvalues(&m).unwrap();
        for e in r {
            assert!((e.0 + 1.0).abs() < 1e-9);
            assert!((e.1.abs() - (5e4f64 - 1.0).sqrt()).abs() < 1e-8);
        }
    }

    #[test]
    fn eigenvalues_of_a_random_matrix_match_trace_and_determinant() {
        // A fixed 6×6 matrix: sum of eigenvalues = trace, product = determinant-free check via
        // sum of squares = trace(A²).
        let n = 6;
        let mut m = Mat::zeros(n);
        let mut seed = 12345u64;
        for v in m.a.iter_mut() {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            *v = ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0;
        }
        let ev = eigenvalues(&m).unwrap();
        let trace: f64 = (0..n).map(|i| m.get(i, i)).sum();
        let sum_re: f64 = ev.iter().map(|e| e.0).sum();
        let sum_im: f64 = ev.iter().map(|e| e.1).sum();
        assert!((trace - sum_re).abs() < 1e-10 && sum_im.abs() < 1e-10);
        let m2 = m.mul(&m);
        let trace2: f64 = (0..n).map(|i| m2.get(i, i)).sum();
        let sum_sq: f64 = ev.iter().map(|e| e.0 * e.0 - e.1 * e.1).sum();
        assert!((trace2 - sum_sq).abs() < 1e-9, "{trace2} vs {sum_sq}");
    }
}
