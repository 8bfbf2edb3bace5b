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
//! **How far a `q` can move.** Let `D_A`, `D_B` (m) bound the motion of every point of bodies A
//! and B since the scan (the world's odometers, `|Δp| + |Δθ|·ρ` summed over samples, `ρ` the
//! body's vertex radius). A box bound moves by at most the motion of its polygon's vertices,
//! `D_B`, and the vertex by `D_A`. A line quantity `q = n·(V − E0)` (or with `t`) changes by
//!
//! ```text
//! |Δq| ≤ |ΔV| + |ΔE0| + |Δn|·|V' − E0'| ≤ D_A + D_B + (D_B/r_B)·(diag_B + δ_c)
//! ```
//!
//! because `|Δn| ≤ |Δθ_B| ≤ D_B/ρ_B ≤ D_B/r_B` (`r_B` the vertex radius of B's polygon, at most
//! its body's) and both `V` and `E0` lie in B's grown box (`diag_B` its diagonal) at the scan,
//! each moving less than `δ_c` since (below). The scan of B's vertices against A is the same with
//! the roles swapped, so every `q` of the pair moves by less than
//!
//! ```text
//! Δ = k_A·D_A + k_B·D_B,   k_X = 1 + (diag_X + δ_c)/r_X.
//! ```
//!
//! The scan is reused while `Δ < σ = min(slacks, δ_c) − guard` (so `D_A + D_B < δ_c` as used
//! above); the guard (1 µm) covers round-off in the slacks and odometers.
//!
//! **What is not reused.** A vertex within `δ_c` of two lines (the corner-on-corner rule decides by
//! orientation there), equal line distances (no slack), more candidates than a slot holds, or a
//! polygon without a vertex radius: the pair is scanned every sample as before. The reused pair
//! must also stay penetrating: its largest depth `−max_j d_j` over the inside vertices is a slack
//! too. A change of `δ_c` or `ε_s` drops every reused scan.

use super::{Collider, VeCandidate};
use crate::geom::Vec2;

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
        self.decided = self.decided.min(slack);
    }

    /// The scan's certificate: `σ` (m) and `k_A`, `k_B` of the module docs, or `None` if the scan
    /// must run every sample.
    pub fn certificate(
        &self,
        a: &Collider,
        b: &Collider,
        delta_c: f64,
        eps_s: f64,
        guard: f64,
    ) -> Option<(f64, f64, f64)> {
        let sigma = self.decided.min(self.inside).min(delta_c) - guard;
        let (k_a, k_b) = (
            motion_factor(a, delta_c, eps_s),
            motion_factor(b, delta_c, eps_s),
        );
        (sigma > 0.0 && k_a.is_finite() && k_b.is_finite()).then_some((sigma, k_a, k_b))
    }
}

/// `k = 1 + (diag + δ_c)/r` of collider `c` (module docs): `diag` the diagonal of its box grown by
/// `δ_c + ε_s`, `r` its vertex radius (m, about its body's origin). Infinite without a radius.
fn motion_factor(c: &Collider, delta_c: f64, eps_s: f64) -> f64 {
    let grown = 2.0 * (delta_c + eps_s);
    let diag = (c.aabb.max - c.aabb.min + Vec2::splat(grown)).length();
    let r = c
        .local
        .vertices()
        .iter()
        .map(|v| v.length())
        .fold(0.0, f64::max);
    if r > 0.0 {
        1.0 + (diag + delta_c) / r
    } else {
        f64::INFINITY
    }
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

    /// Whether the candidates did not fit.
    #[inline]
    pub fn overflows(&self) -> bool {
        self.len == u8::MAX
    }

    /// The candidates (none if they overflowed).
    #[inline]
    pub fn get(&self) -> &[VeCandidate] {
        self.candidates.get(..self.len as usize).unwrap_or(&[])
    }
}
