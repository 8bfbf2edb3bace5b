//! The mixed LCP of one frictional impact phase, solved exactly by enumeration (issue 16,
//! docs/MODELS.md "Frictional impacts", §E.3).
//!
//! Unknowns: per contact `i` a normal impulse `p_n,i` and a tangential impulse `p_t,i` (N·s), stacked
//! as `x = (p_n,0, p_t,0, p_n,1, p_t,1, …)`. Velocities after the phase: `w = A·x + b` (m/s), with `A`
//! the `2n × 2n` Delassus matrix `G M⁻¹ Gᵀ` of the normal and tangent rows and `b` the velocities at
//! the start of the phase. In 2-D the Coulomb cone is the exact interval `|p_t| ≤ μ·p_n`, so every
//! contact is in one of four modes, each giving two linear equations and some sign conditions:
//!
//! | mode      | equations                      | conditions                        |
//! |-----------|--------------------------------|-----------------------------------|
//! | separate  | `p_n = 0`, `p_t = 0`           | `w_n ≥ 0`                         |
//! | stick     | `w_n = 0`, `w_t = 0`           | `p_n ≥ 0`, `|p_t| ≤ μ·p_n`        |
//! | slide +   | `w_n = 0`, `p_t = −μ·p_n`      | `p_n ≥ 0`, `w_t ≥ 0`              |
//! | slide −   | `w_n = 0`, `p_t = +μ·p_n`      | `p_n ≥ 0`, `w_t ≤ 0`              |
//!
//! In the restitution phase the normal impulse is prescribed (`p_n = P_i`, Poisson) and only the
//! three tangential modes are enumerated. The union of the conditions is exactly the complementarity
//! problem `0 ≤ p_n ⟂ w_n ≥ 0`, `p_t ∈ −μ·p_n·∂|w_t|` (maximal dissipation); enumerating the `4ⁿ`
//! (or `3ⁿ`) mode vectors therefore finds every solution. A frictional LCP can have several (the
//! Delassus matrix with friction is not symmetric in the mixed form): the one kept is the one with
//! the smallest kinetic energy after the phase, `ΔT = bᵀx + ½·xᵀA·x` (ties: the first in mode order),
//! which is deterministic and the most dissipative choice.

use super::lcp::{gauss_solve, LAMBDA_TOL, W_TOL};

/// Largest contact count solved by enumeration (`4⁴ = 256` mode vectors of an `8 × 8` system).
pub const MLCP_ENUMERATION_MAX: usize = 4;

/// Which phase of the impact the mixed LCP describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImpactPhase {
    /// Normal impulses free (`0 ≤ p_n ⟂ w_n ≥ 0`); also the plastic correction.
    Compression,
    /// Normal impulses prescribed (Poisson: `P_i = e_i·p_n,i` of compression).
    Restitution,
}

/// Enumeration solver of the mixed LCP with its own scratch (grows only for a larger set).
#[derive(Clone, Debug, Default)]
pub struct MixedLcp {
    m: Vec<f64>,
    rhs: Vec<f64>,
    best: Vec<f64>,
    modes: Vec<u8>,
}

impl MixedLcp {
    /// Scratch for up to `n` contacts (capped at [`MLCP_ENUMERATION_MAX`]).
    pub fn with_capacity(n: usize) -> Self {
        let mut s = Self::default();
        s.reserve(n);
        s
    }

    /// Grows the scratch for `n` contacts.
    pub fn reserve(&mut self, n: usize) {
        let k = 2 * n.min(MLCP_ENUMERATION_MAX);
        if self.m.len() < k * k {
            self.m.resize(k * k, 0.0);
        }
        if self.rhs.len() < k {
            self.rhs.resize(k, 0.0);
            self.best.resize(k, 0.0);
            self.modes.resize(k / 2, 0);
        }
    }

    /// The accepted solution `x` of the last successful [`solve`](Self::solve) (`2n` entries).
    pub fn solution(&self, n: usize) -> &[f64] {
        &self.best[..2 * n]
    }

    /// Solves the mixed LCP of one phase for `n = b.len()/2 ≤ MLCP_ENUMERATION_MAX` contacts with
    /// friction coefficient `mu` (`A` row-major `2n × 2n`). `fixed` holds the prescribed normal
    /// impulses for [`ImpactPhase::Restitution`] (ignored for compression). Returns the number of mode
    /// vectors tried when a solution within tolerance was found (read it with
    /// [`solution`](Self::solution)), `None` when none was (the caller then iterates).
    // Contact `i` indexes its two rows, its mode and its prescribed impulse together.
    #[allow(clippy::needless_range_loop)]
    pub fn solve(
        &mut self,
        a: &[f64],
        b: &[f64],
        mu: f64,
        phase: ImpactPhase,
        fixed: &[f64],
    ) -> Option<usize> {
        let k = b.len();
        let n = k / 2;
        if n == 0 || n > MLCP_ENUMERATION_MAX || a.len() != k * k {
            return None;
        }
        self.reserve(n);
        // Compression: modes 0 = separate, 1 = stick, 2 = slide +, 3 = slide −.
        // Restitution: modes 1..=3 only (the normal impulse is prescribed).
        let (first, radix) = match phase {
            ImpactPhase::Compression => (0u8, 4usize),
            ImpactPhase::Restitution => (1u8, 3usize),
        };
        let combos = radix.pow(n as u32);
        let mut best_de = f64::INFINITY;
        let mut found = false;
        for combo in 0..combos {
            let mut c = combo;
            for i in 0..n {
                self.modes[i] = first + (c % radix) as u8;
                c /= radix;
            }
            // Assemble the 2n equations of this mode vector.
            let m = &mut self.m[..k * k];
            m.fill(0.0);
            let rhs = &mut self.rhs[..k];
            for i in 0..n {
                let (rn, rt) = (2 * i, 2 * i + 1);
                let mode = self.modes[i];
                // Normal equation.
                if mode == 0 {
                    m[rn * k + rn] = 1.0;
                    rhs[rn] = 0.0;
                } else if phase == ImpactPhase::Restitution {
                    m[rn * k + rn] = 1.0;
                    rhs[rn] = fixed[i];
                } else {
                    m[rn * k..rn * k + k].copy_from_slice(&a[rn * k..rn * k + k]);
                    rhs[rn] = -b[rn];
                }
                // Tangential equation.
                match mode {
                    0 => {
                        m[rt * k + rt] = 1.0;
                        rhs[rt] = 0.0;
                    }
                    1 => {
                        m[rt * k..rt * k + k].copy_from_slice(&a[rt * k..rt * k + k]);
                        rhs[rt] = -b[rt];
                    }
                    _ => {
                        // p_t + s·μ·p_n = 0 with s = +1 (slide +, w_t > 0) or −1 (slide −).
                        let s = if mode == 2 { 1.0 } else { -1.0 };
                        m[rt * k + rt] = 1.0;
                        m[rt * k + rn] = s * mu;
                        rhs[rt] = 0.0;
                    }
                }
            }
            if !gauss_solve(m, rhs, k) {
                continue;
            }
            let x = &self.rhs[..k];
            if !x.iter().all(|v| v.is_finite()) {
                continue;
            }
            // Sign conditions of each mode, with the LCP tolerances of §7.3.
            let mut ok = true;
            for i in 0..n {
                let (rn, rt) = (2 * i, 2 * i + 1);
                let w = |r: usize| -> f64 {
                    let mut s = b[r];
                    for (c, xc) in x.iter().enumerate() {
                        s += a[r * k + c] * xc;
                    }
                    s
                };
                let (pn, pt) = (x[rn], x[rt]);
                ok &= match self.modes[i] {
                    0 => w(rn) >= -W_TOL,
                    1 => pn >= -LAMBDA_TOL && pt.abs() <= mu * pn.max(0.0) + LAMBDA_TOL,
                    2 => pn >= -LAMBDA_TOL && w(rt) >= -W_TOL,
                    _ => pn >= -LAMBDA_TOL && w(rt) <= W_TOL,
                };
                if !ok {
                    break;
                }
            }
            if !ok {
                continue;
            }
            // Kinetic-energy change of the phase: ΔT = bᵀx + ½·xᵀA·x (A = G M⁻¹ Gᵀ, b = G u).
            let mut de = 0.0;
            for r in 0..k {
                let mut ax = 0.0;
                for (c, xc) in x.iter().enumerate() {
                    ax += a[r * k + c] * xc;
                }
                de += x[r] * (b[r] + 0.5 * ax);
            }
            if de < best_de {
                best_de = de;
                found = true;
                self.best[..k].copy_from_slice(x);
            }
        }
        if !found {
            return None;
        }
        // Clamp the tolerance-accepted negatives of p_n to zero and p_t into its interval.
        for i in 0..n {
            let pn = self.best[2 * i].max(0.0);
            self.best[2 * i] = pn;
            let bound = mu * pn;
            self.best[2 * i + 1] = self.best[2 * i + 1].clamp(-bound, bound);
        }
        Some(combos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The solution `(p_n, p_t)` (N·s) for a particle of 1 kg on the ground (`A = I`) with start
    /// velocities `b` (m/s), friction `mu` and, in restitution, the prescribed normal impulse.
    fn particle(b: [f64; 2], mu: f64, phase: ImpactPhase, target: &[f64]) -> [f64; 2] {
        let a = [1.0, 0.0, 0.0, 1.0];
        let mut s = MixedLcp::with_capacity(1);
        assert!(s.solve(&a, &b, mu, phase, target).is_some());
        let x = s.solution(1);
        [x[0], x[1]]
    }

    /// A particle (m = 1 kg) on the ground: A = I. Approaching at (v_n, v_t) = (−1, 0.3) with μ = 0.5:
    /// sliding would need |p_t| = 0.5 ≥ 0.3, so it sticks: p = (1, −0.3).
    #[test]
    fn particle_sticks_when_the_cone_holds_it() {
        let x = particle([-1.0, 0.3], 0.5, ImpactPhase::Compression, &[]);
        assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] + 0.3).abs() < 1e-12);
    }

    /// Same particle, v_t = 2: it slides, p = (1, −0.5), and keeps v_t = 1.5.
    #[test]
    fn particle_slides_outside_the_cone() {
        let x = particle([-1.0, 2.0], 0.5, ImpactPhase::Compression, &[]);
        assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] + 0.5).abs() < 1e-12);
    }

    /// Restitution with a prescribed P = 0.5 and v_t = 0.1: sticking needs 0.1 ≤ μ·P = 0.25.
    #[test]
    fn restitution_keeps_the_prescribed_normal_impulse() {
        let x = particle([0.0, 0.1], 0.5, ImpactPhase::Restitution, &[0.5]);
        assert!((x[0] - 0.5).abs() < 1e-12 && (x[1] + 0.1).abs() < 1e-12);
    }
}
