//! Reusing a penetrating pair's vertex scan while its bodies have not moved enough to change it
//! (issue 17): the certificate behind [`LocalStage::update_with_motion`](super::LocalStage)'s
//! `reused` pairs.
//!
//! The vertex scan of a pair (§9.4, `vertices_against` both ways) is a fixed sequence of
//! comparisons of quantities `q` against thresholds: a vertex against the box of the other
//! polygon grown by `δ_c + ε_s`, its line distances `d_j = n_j·(V − E0_j)` against `δ_c`, `−δ_c`
//! and each other (the nearest line), and the edge coordinate `s = t_j·(V − E0_j)` of the nearest
//! line against `−ε_s` and `L_j + ε_s`. Its candidates are a function of those outcomes alone.
//! While every `q` has moved by less than its distance from its threshold (its *slack*), every
//! outcome and so every candidate is the same: the scan can be skipped and its candidates reused.
//!
//! **How far a `q` can move.** Every `q` is a function of vectors `p − e` between a point `p` of
//! A and a point `e` of B (vertex minus edge start, vertex minus another polygon's box corner)
//! and, for a line quantity `n·(p − e)` or `t·(p − e)`, of B's (or A's) edge direction. With body
//! origins `P`, net rotations `Δθ` since the scan and `r` each polygon's vertex radius about its
//! body's origin, `|Δ(p − e)| ≤ |ΔP_A − ΔP_B| + |Δθ_A|·r_A + |Δθ_B|·r_B` (a translation of
//! both bodies together changes nothing), and a line quantity of B's line changes by
//!
//! ```text
//! |Δq| ≤ |Δ(p − e)| + |Δn|·|p' − e'| ≤ |ΔP_A − ΔP_B| + |Δθ_A|·r_A + |Δθ_B|·(r_B + diag_B + δ_c)
//! ```
//!
//! because `|Δn| ≤ |Δθ_B|` and both `p` and `e` lie in B's box grown by `δ_c + ε_s` (`diag_B`
//! its diagonal) at the scan, and have moved apart by less than `δ_c` since (below). The scan of
//! B's vertices against A is the same with the roles swapped, so every `q` of the pair moves by
//! less than
//!
//! ```text
//! m = |ΔP_A − ΔP_B|₁ + |Δθ_A|·l_A + |Δθ_B|·l_B,   l_X = r_X + diag_X + δ_c.
//! ```
//!
//! The scan is reused while `m < σ = min(slacks, δ_c) − guard` (so `|Δ(p − e)| < δ_c` as used
//! above); the guard (1 µm) covers round-off in the slacks and poses. A pile settling as a whole
//! sinks and creeps together: its relative motions are a small part of its absolute ones.
//!
//! **What is not reused.** A vertex within `δ_c` of two lines (the corner-on-corner rule decides by
//! orientation there), equal line distances (no slack), more candidates than a slot holds, or a
//! polygon without a vertex radius: the pair is scanned every sample as before. The reused pair
//! must also stay penetrating: its largest depth `−max_j d_j` over the inside vertices is a slack
//! too. A change of `δ_c` or `ε_s` drops every reused scan.

use super::{Collider, VeCandidate};
use crate::geom::{select_min, Vec2};

/// Candidates a reused scan can hold; a pair with more is scanned every sample.
pub(super) const SLOT: usize = 4;

/// The slack of one vertex scan (both directions of a pair), accumulated as the scan runs.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slack {
    /// Smallest distance (m) of a compared quantity from its threshold; 0 = not reusable.
    pub decided: f64,
    /// Largest depth `−max_j d_j` (m) of a vertex strictly inside the other polygon.
    pub inside: f64,
}

impl Slack {
    /// No comparison made yet.
    pub fn new() -> Self {
        Self {
            decided: f64::INFINITY,
            inside: 0.0,
        }
    }

    /// Records a comparison of a quantity `slack` (m) away from its threshold.
    #[inline(always)]
    pub fn decided(&mut self, slack: f64) {
        // A running least that is never NaN: `f64::min`'s NaN fix-up is not needed (a NaN
        // `slack` keeps it).
        self.decided = select_min(slack, self.decided);
    }

    /// The scan's certificate: `σ` (m) and the levers `l_A`, `l_B` (m/rad) of the module docs, or
    /// `None` if the scan must run every sample.
    pub fn certificate(
        &self,
        a: &Collider,
        b: &Collider,
        delta_c: f64,
        eps_s: f64,
        guard: f64,
    ) -> Option<(f64, f64, f64)> {
        let sigma = self.decided.min(self.inside).min(delta_c) - guard;
        let (l_a, l_b) = (lever(a, delta_c, eps_s), lever(b, delta_c, eps_s));
        (sigma > 0.0 && l_a.is_finite() && l_b.is_finite()).then_some((sigma, l_a, l_b))
    }
}

/// `l = r + diag + δ_c` of collider `c` (m, module docs): `r` its vertex radius about its body's
/// origin, `diag` the diagonal of its box grown by `δ_c + ε_s`.
fn lever(c: &Collider, delta_c: f64, eps_s: f64) -> f64 {
    let grown = 2.0 * (delta_c + eps_s);
    let diag = (c.aabb.max - c.aabb.min + Vec2::splat(grown)).length();
    c.local.radius() + diag + delta_c
}

/// One pair's candidates at its last tracked sample (`len ≤ SLOT`, or [`OVERFLOW`](Self::OVERFLOW)
/// for more), and whether they are the vertex scan's (`LocalStage::from_vertex_scan`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PairCandidates {
    len: u8,
    pub scan: bool,
    candidates: [VeCandidate; SLOT],
}

impl PairCandidates {
    /// No candidates.
    pub const EMPTY: PairCandidates = PairCandidates {
        len: 0,
        scan: false,
        candidates: [VeCandidate {
            vertex_collider: 0,
            vertex: 0,
            edge_collider: 0,
            edge: 0,
        }; SLOT],
    };

    /// More candidates than a slot holds (kept elsewhere, for one update).
    pub const OVERFLOW: PairCandidates = PairCandidates {
        len: u8::MAX,
        ..Self::EMPTY
    };

    /// The candidates `found` (with the flag `scan`), or `None` if there are more than a slot
    /// holds. Unused places are zero, so equal candidates compare equal.
    pub fn of(found: &[VeCandidate], scan: bool) -> Option<PairCandidates> {
        let mut r = PairCandidates::EMPTY;
        r.candidates.get_mut(..found.len())?.copy_from_slice(found);
        r.len = found.len() as u8;
        r.scan = scan;
        Some(r)
    }

    /// The candidates (none if they overflowed).
    #[inline]
    pub fn get(&self) -> &[VeCandidate] {
        self.candidates.get(..self.len as usize).unwrap_or(&[])
    }
}

#[cfg(test)]
mod tests {
    /// For a running value `x` that is a number, `select_min(y, x)`/`select_max(y, x)` (the scans'
    /// running least and greatest) give `f64::min`/`f64::max` on every `y` (as values: zeros of
    /// both signs compare equal), NaN, ±∞ and ±0 included, and a NaN `y` keeps `x`.
    #[test]
    fn running_least_and_greatest_are_min_and_max_for_a_running_number() {
        use crate::geom::{select_max, select_min};
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e-300,
        ];
        values.extend(
            (0..200).map(|_| rng.random_range(-1.0..1.0) * 10f64.powi(rng.random_range(-9..3))),
        );
        let ys = values.iter().copied().chain([f64::NAN]);
        for (x, y) in values.iter().flat_map(|&x| ys.clone().map(move |y| (x, y))) {
            assert_eq!(select_min(y, x), x.min(y), "least({x}, {y})");
            assert_eq!(select_max(y, x), x.max(y), "greatest({x}, {y})");
            if y.is_nan() {
                assert_eq!(select_min(y, x).to_bits(), x.to_bits());
                assert_eq!(select_max(y, x).to_bits(), x.to_bits());
            }
        }
    }
}
