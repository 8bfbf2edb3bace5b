//! Small dense LCP solvers (§7.3): exact enumeration for n ≤ 6, projected Gauss–Seidel beyond.
//!
//! The problem is: find `λ ≥ 0` with `w = A·λ + b ≥ 0` and `λ_i·w_i = 0` for every `i`. In the impact
//! solver (§7.2) `A` is the Delassus matrix (1/kg, 1/(kg·m²)·m², i.e. (m/s)/(N·s)), `b` the normal
//! velocities (m/s) and `λ` the impulses (N·s). The solver is unit-agnostic; the tolerances below are
//! the spec's and assume those units.

/// Largest problem size solved by exact enumeration of the `2ⁿ` index sets (§7.3).
pub const ENUMERATION_MAX_N: usize = 6;
/// Pivots with magnitude below this are treated as singular; the index set is skipped (§7.3).
pub const PIVOT_MIN: f64 = 1e-12;
/// Enumeration accepts `λ_i ≥ −LAMBDA_TOL` (N·s) (§7.3); the accepted `λ` is then clamped to `≥ 0`.
pub const LAMBDA_TOL: f64 = 1e-12;
/// Enumeration accepts `w_i ≥ −W_TOL` (m/s) (§7.3).
pub const W_TOL: f64 = 1e-9;
/// Above [`ENUMERATION_MAX_N`] and up to this size, enumeration is the fallback when projected
/// Gauss–Seidel stops at its sweep limit (not in §7.3; see [`LcpSolver::solve`]). `2¹⁰` sets.
pub const ENUMERATION_FALLBACK_MAX_N: usize = 10;
/// Largest problem [`LcpSolver::solve_enumeration`] accepts (`2²⁰` index sets, about a second):
/// beyond it enumeration would run for ever in practice, and its `k × k` scratch is capped at this
/// size, so no input sizes an unbounded allocation here.
pub const ENUMERATION_HARD_MAX_N: usize = 20;
/// Projected Gauss–Seidel: maximum number of sweeps (§7.3).
pub const PGS_MAX_SWEEPS: usize = 200;
/// Projected Gauss–Seidel: stop when the largest `|Δλ|` of a sweep is below this (N·s) (§7.3).
pub const PGS_TOL: f64 = 1e-9;
/// Diagonal entries `A_ii` at or below this are treated as zero by projected Gauss–Seidel: such a row
/// has no mobility (e.g. both bodies fixed) and its `λ_i` stays 0.
const PGS_DIAG_MIN: f64 = 1e-300;

/// Which algorithm produced an LCP solution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LcpMethod {
    /// Nothing to solve (`n = 0`).
    Empty,
    /// Exact enumeration of index sets (`n ≤ 6`).
    Enumeration,
    /// Projected Gauss–Seidel (`n > 6`, or the fallback when enumeration finds no set within tolerance).
    Pgs,
}

/// Diagnostics of one LCP solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LcpReport {
    /// Problem size `n`.
    pub n: usize,
    /// The algorithm that produced the returned `λ`.
    pub method: LcpMethod,
    /// Enumeration: the accepted (or, if not converged, least infeasible) index set as a bit mask
    /// (bit `i` set ⇔ `i` in the active set). PGS and empty problems: 0.
    pub active_mask: u64,
    /// PGS: number of sweeps run. Enumeration: number of index sets tried.
    pub iterations: usize,
    /// False when PGS stopped at the sweep limit or stopped with some `w_i < −1e-9` (the `|Δλ|` rule
    /// met far from the solution), or when enumeration found no index set within tolerance, and no
    /// fallback (see [`LcpSolver::solve`]) did better.
    pub converged: bool,
    /// True when enumeration found no index set within tolerance and PGS was used instead.
    pub enumeration_failed: bool,
    /// True when PGS did not converge and the result came from the enumeration fallback
    /// (`6 < n ≤ 10`).
    pub pgs_failed: bool,
}

impl LcpReport {
    /// The report a solve of size `n` by `method` starts from: [`LcpMethod::Empty`] when `n = 0`,
    /// no active set, no iterations, converged, no fallback.
    #[inline]
    fn start(n: usize, method: LcpMethod) -> Self {
        LcpReport {
            n,
            method: if n == 0 { LcpMethod::Empty } else { method },
            active_mask: 0,
            iterations: 0,
            converged: true,
            enumeration_failed: false,
            pgs_failed: false,
        }
    }
}

/// Errors of [`LcpSolver::solve`]: inconsistent input sizes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LcpError {
    /// `a.len()` is not `n²` where `n = b.len()`.
    MatrixSize {
        /// `b.len()`.
        n: usize,
        /// `a.len()`.
        a_len: usize,
    },
    /// Enumeration was asked for `n > ENUMERATION_HARD_MAX_N` rows.
    TooLargeForEnumeration {
        /// `b.len()`.
        n: usize,
    },
}

impl std::fmt::Display for LcpError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LcpError::MatrixSize { n, a_len } => write!(
                f,
                "LCP matrix `a` has {a_len} entries but `b` has {n}, so `a` needs {} (row-major n×n)",
                n * n
            ),
            LcpError::TooLargeForEnumeration { n } => write!(
                f,
                "LCP of {n} rows is too large for enumeration (at most {ENUMERATION_HARD_MAX_N}); use projected Gauss–Seidel"
            ),
        }
    }
}

impl std::error::Error for LcpError {}

/// A dense LCP solver that owns its scratch buffers.
///
/// Buffers are preallocated for a capacity and grow only when a larger problem arrives, so repeated
/// solves of problems up to the largest size seen so far do not allocate.
#[derive(Clone, Debug)]
pub struct LcpSolver {
    /// Current capacity (largest `n` solvable without allocation).
    cap: usize,
    /// Solution `λ` of the last solve (N·s); length `cap`, first `n` valid.
    lambda: Vec<f64>,
    /// `w = A·λ + b` of the last solve (m/s); length `cap`, first `n` valid.
    w: Vec<f64>,
    /// Enumeration: the reduced matrix `A_SS` (row-major, `cap × cap`), reduced in place.
    m: Vec<f64>,
    /// Enumeration: right-hand side `−b_S`, then the solution `λ_S`.
    rhs: Vec<f64>,
    /// Enumeration: the indices of the current set `S`.
    idx: Vec<usize>,
    /// Size of the last problem.
    n: usize,
}

impl Default for LcpSolver {
    fn default() -> Self {
        Self::new()
    }
}

impl LcpSolver {
    /// A solver with buffers for problems up to `n = 8` without allocation.
    pub fn new() -> Self {
        Self::with_capacity(8)
    }

    /// A solver with buffers for problems up to `n = capacity` without allocation.
    pub fn with_capacity(capacity: usize) -> Self {
        let mut s = Self {
            cap: 0,
            lambda: Vec::new(),
            w: Vec::new(),
            m: Vec::new(),
            rhs: Vec::new(),
            idx: Vec::new(),
            n: 0,
        };
        s.reserve(capacity);
        s
    }

    /// Largest problem size solvable without allocating.
    pub fn capacity(&self) -> usize {
        self.cap
    }

    /// Grows the buffers to hold problems of size `n` (no-op if they already do).
    pub fn reserve(&mut self, n: usize) {
        if n <= self.cap {
            return;
        }
        self.lambda.resize(n, 0.0);
        self.w.resize(n, 0.0);
        // Only enumeration uses `m` (its k × k active-set system, k ≤ n ≤ ENUMERATION_HARD_MAX_N).
        let k = n.min(ENUMERATION_HARD_MAX_N);
        if self.m.len() < k * k {
            self.m.resize(k * k, 0.0);
        }
        self.rhs.resize(n, 0.0);
        self.idx.resize(n, 0);
        self.cap = n;
    }

    /// The solution `λ` of the last solve (N·s), all entries `≥ 0`.
    pub fn lambda(&self) -> &[f64] {
        &self.lambda[..self.n]
    }

    /// `w = A·λ + b` of the last solve (m/s).
    pub fn w(&self) -> &[f64] {
        &self.w[..self.n]
    }

    /// Solves the LCP for the row-major `n × n` matrix `a` and the vector `b` (`n = b.len()`), choosing
    /// enumeration for `n ≤ 6` and projected Gauss–Seidel otherwise (§7.3). The result is read with
    /// [`Self::lambda`] and [`Self::w`].
    ///
    /// Fallbacks (beyond §7.3, reported in [`LcpReport`]); when both methods fail, the result with the
    /// smaller `max(0, −min w)` is kept:
    /// - if enumeration finds no index set within tolerance (ill-conditioned `A`), PGS is tried;
    /// - if PGS does not converge for `6 < n ≤ 10` (sweep limit, or a final `w_i < −1e-9`),
    ///   enumeration is tried. PGS converges very slowly on Delassus matrices of nearly redundant contacts (strongly
    ///   coupled rows, diagonal spread of 30×); 200 sweeps can leave `w_i ≈ −0.1 m/s`.
    pub fn solve(&mut self, a: &[f64], b: &[f64]) -> Result<LcpReport, LcpError> {
        let n = b.len();
        if n <= ENUMERATION_MAX_N {
            let e = self.solve_enumeration(a, b)?;
            if e.converged || n == 0 {
                return Ok(e);
            }
            let e_viol = self.violation();
            let mut p = self.solve_pgs(a, b)?;
            p.enumeration_failed = true;
            p.iterations += e.iterations;
            if p.converged || self.violation() <= e_viol {
                return Ok(p);
            }
            // Both failed and the least infeasible index set beats the PGS iterate.
            let _ = self.eval_set(a, b, n, e.active_mask);
            Ok(LcpReport {
                enumeration_failed: true,
                iterations: p.iterations,
                ..e
            })
        } else {
            let p = self.solve_pgs(a, b)?;
            if p.converged || n > ENUMERATION_FALLBACK_MAX_N {
                return Ok(p);
            }
            let p_viol = self.violation();
            // Polish: PGS usually finds the right active set long before its iterate converges (stacked
            // contacts make A badly conditioned). Solve that index set exactly; accept it if it
            // satisfies the §7.3 tolerances, before paying for the full enumeration.
            let support = (0..n).fold(0u64, |m, i| {
                if self.lambda[i] > LAMBDA_TOL {
                    m | (1u64 << i)
                } else {
                    m
                }
            });
            if let Some((true, _)) = self.eval_set(a, b, n, support) {
                return Ok(LcpReport {
                    method: LcpMethod::Enumeration,
                    active_mask: support,
                    pgs_failed: true,
                    iterations: p.iterations + 1,
                    converged: true,
                    ..p
                });
            }
            let mut e = self.solve_enumeration(a, b)?;
            e.pgs_failed = true;
            e.iterations += p.iterations;
            if e.converged || self.violation() < p_viol {
                Ok(e)
            } else {
                // Neither converged and PGS is less infeasible: restore the PGS iterate.
                let iterations = e.iterations;
                let mut p = self.solve_pgs(a, b)?;
                p.iterations = iterations;
                p.pgs_failed = true;
                Ok(p)
            }
        }
    }

    /// `max(0, −min_i w_i)` of the buffers (m/s).
    fn violation(&self) -> f64 {
        let m = self.w[..self.n].iter().copied().fold(0.0, f64::min);
        -m
    }

    fn prepare(&mut self, a: &[f64], b: &[f64]) -> Result<usize, LcpError> {
        let n = b.len();
        if a.len() != n * n {
            return Err(LcpError::MatrixSize { n, a_len: a.len() });
        }
        self.reserve(n);
        self.n = n;
        Ok(n)
    }

    /// Exact enumeration of the `2ⁿ` index sets in increasing bit-mask order (§7.3). Intended for
    /// `n ≤ 6`; works for any `n ≤ ENUMERATION_HARD_MAX_N` (an error beyond) at a cost of `O(2ⁿ n³)`. If no set is accepted (possible
    /// only for ill-conditioned `A`), `converged` is false and the buffers hold the least infeasible
    /// nonsingular set (smallest `max(0, −min w)`, `λ` clamped to `≥ 0`), named by `active_mask`.
    pub fn solve_enumeration(&mut self, a: &[f64], b: &[f64]) -> Result<LcpReport, LcpError> {
        if b.len() > ENUMERATION_HARD_MAX_N {
            return Err(LcpError::TooLargeForEnumeration { n: b.len() });
        }
        let n = self.prepare(a, b)?;
        let mut report = LcpReport::start(n, LcpMethod::Enumeration);
        if n == 0 {
            return Ok(report);
        }
        let n_sets: u64 = if n >= 64 { u64::MAX } else { 1u64 << n };
        let mut best = (f64::INFINITY, 0u64);
        for mask in 0..n_sets {
            report.iterations += 1;
            match self.eval_set(a, b, n, mask) {
                Some((true, _)) => {
                    report.active_mask = mask;
                    return Ok(report);
                }
                Some((false, v)) if v < best.0 => best = (v, mask),
                _ => {}
            }
        }
        // No set accepted: leave the least infeasible set (λ clamped to ≥ 0) in the buffers.
        report.converged = false;
        report.active_mask = best.1;
        if self.eval_set(a, b, n, best.1).is_none() {
            self.lambda[..n].fill(0.0);
            self.w[..n].copy_from_slice(b);
        }
        Ok(report)
    }

    /// Evaluates index set `mask`: solves `A_SS·λ_S = −b_S`, clamps `λ ≥ 0`, computes `w = A·λ + b`
    /// and leaves both in the buffers. Returns `None` if `A_SS` has a pivot below [`PIVOT_MIN`], else
    /// `(accepted, violation)`: `accepted` when `λ_S ≥ −1e-12` and `w ≥ −1e-9` (§7.3), and
    /// `violation = max(0, −min_i w_i)` (m/s) for the fallback's choice of the least bad set.
    fn eval_set(&mut self, a: &[f64], b: &[f64], n: usize, mask: u64) -> Option<(bool, f64)> {
        // Gather S.
        let mut k = 0;
        for i in 0..n {
            if mask & (1u64 << i) != 0 {
                self.idx[k] = i;
                k += 1;
            }
        }
        // Build A_SS (row-major k×k, stride k) and −b_S.
        for r in 0..k {
            let ir = self.idx[r];
            for c in 0..k {
                self.m[r * k + c] = a[ir * n + self.idx[c]];
            }
            self.rhs[r] = -b[ir];
        }
        if !gauss_solve(&mut self.m[..k * k], &mut self.rhs[..k], k) {
            return None;
        }
        // λ: zero outside S, sign check inside S, then clamped.
        let mut accepted = true;
        self.lambda[..n].fill(0.0);
        for r in 0..k {
            let l = self.rhs[r];
            if !l.is_finite() {
                return None;
            }
            accepted &= l >= -LAMBDA_TOL;
            self.lambda[self.idx[r]] = l.max(0.0);
        }
        // w = A·λ + b.
        let mut w_min = f64::INFINITY;
        for i in 0..n {
            let mut s = b[i];
            for r in 0..k {
                let j = self.idx[r];
                s += a[i * n + j] * self.lambda[j];
            }
            if !s.is_finite() {
                return None;
            }
            self.w[i] = s;
            w_min = w_min.min(s);
        }
        accepted &= w_min >= -W_TOL;
        Some((accepted, (-w_min).max(0.0)))
    }

    /// Projected Gauss–Seidel from `λ = 0` (§7.3): `λ_i ← max(0, λ_i − (A_i·λ + b_i)/A_ii)`, up to
    /// [`PGS_MAX_SWEEPS`] sweeps, stopping when the largest `|Δλ|` of a sweep is below [`PGS_TOL`].
    /// Rows with `A_ii ≈ 0` keep `λ_i = 0`.
    pub fn solve_pgs(&mut self, a: &[f64], b: &[f64]) -> Result<LcpReport, LcpError> {
        let n = self.prepare(a, b)?;
        let mut report = LcpReport::start(n, LcpMethod::Pgs);
        let lam = &mut self.lambda[..n];
        lam.fill(0.0);
        if n > 0 {
            report.converged = false;
            for _ in 0..PGS_MAX_SWEEPS {
                report.iterations += 1;
                let mut max_d: f64 = 0.0;
                for i in 0..n {
                    let aii = a[i * n + i];
                    if aii <= PGS_DIAG_MIN {
                        continue;
                    }
                    let row = &a[i * n..(i + 1) * n];
                    let wi = row.iter().zip(lam.iter()).map(|(x, l)| x * l).sum::<f64>() + b[i];
                    let new = (lam[i] - wi / aii).max(0.0);
                    max_d = max_d.max((new - lam[i]).abs());
                    lam[i] = new;
                }
                if max_d < PGS_TOL {
                    report.converged = true;
                    break;
                }
            }
        }
        for i in 0..n {
            let row = &a[i * n..(i + 1) * n];
            let wi = row.iter().zip(lam.iter()).map(|(x, l)| x * l).sum::<f64>() + b[i];
            self.w[i] = wi;
            // The |Δλ| rule detects stagnation, not optimality: on strongly coupled rows PGS can
            // creep by < 1e-9 N·s per sweep far from the solution. Check feasibility of w too.
            if wi.is_nan() || wi < -W_TOL {
                report.converged = false;
            }
        }
        Ok(report)
    }
}

/// Solves `m·x = rhs` in place (row-major `k × k`; the solution replaces `rhs`) by Gaussian
/// elimination with partial pivoting. Returns false if a pivot has magnitude below [`PIVOT_MIN`].
pub(crate) fn gauss_solve(m: &mut [f64], rhs: &mut [f64], k: usize) -> bool {
    for col in 0..k {
        // Partial pivoting: largest |m[r][col]| for r ≥ col.
        let mut p = col;
        let mut best = m[col * k + col].abs();
        for r in col + 1..k {
            let v = m[r * k + col].abs();
            if v > best {
                best = v;
                p = r;
            }
        }
        if best < PIVOT_MIN || !best.is_finite() {
            return false;
        }
        if p != col {
            for c in 0..k {
                m.swap(col * k + c, p * k + c);
            }
            rhs.swap(col, p);
        }
        let piv = m[col * k + col];
        for r in col + 1..k {
            let f = m[r * k + col] / piv;
            if f != 0.0 {
                for c in col..k {
                    m[r * k + c] -= f * m[col * k + c];
                }
                rhs[r] -= f * rhs[col];
            }
        }
    }
    // Back substitution.
    for r in (0..k).rev() {
        let mut s = rhs[r];
        for c in r + 1..k {
            s -= m[r * k + c] * rhs[c];
        }
        rhs[r] = s / m[r * k + r];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn check_lcp(a: &[f64], b: &[f64], lam: &[f64], w: &[f64], tol: f64) {
        let n = b.len();
        for i in 0..n {
            let wi: f64 = (0..n).map(|j| a[i * n + j] * lam[j]).sum::<f64>() + b[i];
            assert!((wi - w[i]).abs() < 1e-12, "w[{i}] inconsistent");
            assert!(lam[i] >= 0.0, "λ[{i}] = {} < 0", lam[i]);
            assert!(w[i] >= -tol, "w[{i}] = {} < 0", w[i]);
            assert!((lam[i] * w[i]).abs() < tol, "complementarity {i}");
        }
    }

    /// Random SPD matrix `LᵀL + εI` (row-major) and a random `b`.
    fn random_spd(rng: &mut ChaCha8Rng, n: usize) -> (Vec<f64>, Vec<f64>) {
        let l: Vec<f64> = (0..n * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|k| l[k * n + i] * l[k * n + j]).sum::<f64>();
            }
            a[i * n + i] += 0.1;
        }
        let b = (0..n).map(|_| rng.random_range(-2.0..1.0)).collect();
        (a, b)
    }

    #[test]
    fn empty_problem() {
        let mut s = LcpSolver::new();
        let r = s.solve(&[], &[]).unwrap();
        assert_eq!(r.method, LcpMethod::Empty);
        assert!(s.lambda().is_empty());
    }

    #[test]
    fn size_mismatch_is_an_error() {
        let mut s = LcpSolver::new();
        assert!(s.solve(&[1.0, 2.0], &[1.0]).is_err());
    }

    #[test]
    fn enumeration_two_by_two() {
        // Symmetric flat-face case of I1: λ = V/4 on both rows.
        let a = [3.2, 0.8, 0.8, 3.2];
        let b = [-1.0, -1.0];
        let mut s = LcpSolver::new();
        let r = s.solve(&a, &b).unwrap();
        assert_eq!(r.method, LcpMethod::Enumeration);
        assert_eq!(r.active_mask, 0b11);
        assert!((s.lambda()[0] - 0.25).abs() < 1e-15);
        assert!((s.lambda()[1] - 0.25).abs() < 1e-15);
        // One separating row: only the other one is active.
        let b = [-1.0, 5.0];
        s.solve(&a, &b).unwrap();
        assert!((s.lambda()[0] - 1.0 / 3.2).abs() < 1e-15);
        assert_eq!(s.lambda()[1], 0.0);
        // Nothing approaching: λ = 0 (mask 0 is tried first).
        let r = s.solve(&a, &[0.0, 1.0]).unwrap();
        assert_eq!(r.active_mask, 0);
        assert_eq!(s.lambda(), &[0.0, 0.0]);
    }

    /// Three collinear contacts of one free body on a fixed wall: `G` has rank 2, so `A` (3×3) is
    /// singular and the impulses are not unique; the post-impact velocities `w` are.
    #[test]
    fn singular_three_collinear_contacts() {
        // Body m = 0.5, I = 8.333e-5, wall normal n = (1, 0), contacts at y = −0.01, 0, 0.01 on the
        // face x = −0.02. Rows of G: (n, r×n) with r×n = −r_y.
        let (m, i) = (0.5, 0.5 * (0.04f64.powi(2) + 0.02f64.powi(2)) / 12.0);
        let ys = [-0.01, 0.0, 0.01];
        let g: Vec<[f64; 3]> = ys.iter().map(|y| [1.0, 0.0, -y]).collect();
        let minv = [1.0 / m, 1.0 / m, 1.0 / i];
        let mut a = [0.0; 9];
        for p in 0..3 {
            for q in 0..3 {
                a[p * 3 + q] = (0..3).map(|k| g[p][k] * minv[k] * g[q][k]).sum();
            }
        }
        // Pre-impact twist: v = (−1, 0.3), ω = 2 → b = G·u.
        let u = [-1.0, 0.3, 2.0];
        let b: Vec<f64> = g
            .iter()
            .map(|r| (0..3).map(|k| r[k] * u[k]).sum())
            .collect();
        let mut post = Vec::new();
        for pgs in [false, true] {
            let mut s = LcpSolver::new();
            let r = if pgs {
                s.solve_pgs(&a, &b).unwrap()
            } else {
                s.solve(&a, &b).unwrap()
            };
            assert!(r.converged, "{r:?}");
            check_lcp(&a, &b, s.lambda(), s.w(), 1e-8);
            // Post-impact twist u + M⁻¹Gᵀλ.
            let mut up = u;
            for (p, row) in g.iter().enumerate() {
                for k in 0..3 {
                    up[k] += minv[k] * row[k] * s.lambda()[p];
                }
            }
            post.push((up, s.w().to_vec()));
        }
        let (u_enum, w_enum) = &post[0];
        let (u_pgs, w_pgs) = &post[1];
        for k in 0..3 {
            assert!((u_enum[k] - u_pgs[k]).abs() < 1e-7, "u[{k}]");
            assert!((w_enum[k] - w_pgs[k]).abs() < 1e-7, "w[{k}]");
        }
        // The body stops in x and rotation about the contact line (all three w are 0).
        assert!(w_enum.iter().all(|w| w.abs() < 1e-12), "{w_enum:?}");
        assert!(u_enum[0].abs() < 1e-12 && u_enum[2].abs() < 1e-9);
    }

    #[test]
    fn pgs_agrees_with_enumeration_on_random_spd() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut e = LcpSolver::with_capacity(2);
        let mut p = LcpSolver::with_capacity(2);
        for _ in 0..300 {
            let n = rng.random_range(1..=6);
            let (a, b) = random_spd(&mut rng, n);
            let re = e.solve(&a, &b).unwrap();
            assert_eq!(re.method, LcpMethod::Enumeration);
            assert!(re.converged);
            check_lcp(&a, &b, e.lambda(), e.w(), 1e-9);
            let rp = p.solve_pgs(&a, &b).unwrap();
            if rp.converged {
                check_lcp(&a, &b, p.lambda(), p.w(), 1e-6);
                // SPD ⇒ unique solution.
                for i in 0..n {
                    assert!(
                        (e.lambda()[i] - p.lambda()[i]).abs() < 1e-6,
                        "n={n} i={i}: {} vs {}",
                        e.lambda()[i],
                        p.lambda()[i]
                    );
                }
            }
        }
        assert!(e.capacity() >= 6);
    }

    #[test]
    fn large_problem_uses_pgs() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let n = 10;
        // Diagonally dominant SPD: PGS converges quickly.
        let (mut a, b) = random_spd(&mut rng, n);
        for i in 0..n {
            a[i * n + i] += n as f64;
        }
        let mut s = LcpSolver::new();
        let r = s.solve(&a, &b).unwrap();
        assert_eq!(r.method, LcpMethod::Pgs);
        assert!(r.converged && r.iterations < PGS_MAX_SWEEPS);
        check_lcp(&a, &b, s.lambda(), s.w(), 1e-8);
        // Enumeration on the same problem (n = 10 is still cheap) finds the same unique solution.
        let lp = s.lambda().to_vec();
        s.solve_enumeration(&a, &b).unwrap();
        for (l, le) in lp.iter().zip(s.lambda()) {
            assert!((l - le).abs() < 1e-8);
        }
    }

    /// Delassus-like matrices of 7–8 rows on 3 DOF (rank 3, strongly coupled rows): PGS often
    /// stagnates (`|Δλ| < 1e-9` far from the solution) or hits its sweep limit, and the enumeration
    /// fallback must then deliver a solution within the §7.3 tolerances.
    #[test]
    fn pgs_stagnation_falls_back_to_enumeration() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut s = LcpSolver::new();
        let mut fallbacks = 0;
        for _ in 0..300 {
            let n = rng.random_range(7..=8);
            let g: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let ang: f64 = rng.random_range(-3.2..3.2);
                    let r = rng.random_range(-0.05..0.05);
                    [ang.cos(), ang.sin(), r]
                })
                .collect();
            let minv = [2.0, 2.0, 4000.0];
            let mut a = vec![0.0; n * n];
            for p in 0..n {
                for q in 0..n {
                    a[p * n + q] = (0..3).map(|k| g[p][k] * minv[k] * g[q][k]).sum();
                }
            }
            let u = [
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-20.0..20.0),
            ];
            let b: Vec<f64> = g
                .iter()
                .map(|r| (0..3).map(|k| r[k] * u[k]).sum())
                .collect();
            let r = s.solve(&a, &b).unwrap();
            fallbacks += r.pgs_failed as usize;
            assert!(r.converged, "{r:?}");
            check_lcp(&a, &b, s.lambda(), s.w(), 1e-8);
        }
        assert!(fallbacks > 0);
    }

    #[test]
    fn no_reallocation_within_capacity() {
        let mut s = LcpSolver::with_capacity(6);
        let ptr = s.lambda.as_ptr();
        let a = [2.0, 0.5, 0.5, 2.0];
        for _ in 0..10 {
            s.solve(&a, &[-1.0, 0.5]).unwrap();
        }
        assert_eq!(s.lambda.as_ptr(), ptr);
        assert_eq!(s.capacity(), 6);
    }
}
