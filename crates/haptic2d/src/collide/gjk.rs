//! GJK distance between two convex polygons (§9.2), with Cameron's two enhancements.
//!
//! # The algorithm
//!
//! The distance between convex sets A and B is the distance of the origin from the
//! configuration-space obstacle `C = A ⊖ B = {a − b}`. GJK never builds `C`: it only needs its
//! support mapping
//!
//! ```text
//! s_C(d) = s_A(d) − s_B(−d),      s_X(d) = argmax_{x ∈ vertices(X)} x·d
//! ```
//!
//! and keeps a simplex `W` of 1–3 points of `C` (each stored with the indices of its A and B
//! vertices). Each iteration takes the point `v` of `conv(W)` closest to the origin, asks for the
//! support point `w = s_C(−v)` in the direction of the origin and adds it to `W`:
//!
//! ```text
//! loop (≤ 32 iterations):
//!     w ← s_C(−v)
//!     if |v|² − v·w ≤ ε_rel²·|v|²  or  |v|² ≤ ε_abs²:  stop, dist = |v|
//!     W ← W ∪ {w};  (v, W) ← closest point of conv(W), W reduced to the supporting subset
//!     if |W| == 3: the origin is inside the triangle → overlap, dist = 0
//! ```
//!
//! `v·w/|v|` is a lower bound and `|v|` an upper bound of the distance, so the first test stops
//! when the two agree to `ε_rel²` relative. For polygons `C` has finitely many vertices, so GJK
//! also stops exactly when `w` is already in `W` (checked by vertex indices, which is robust to
//! round-off). The witness points are `p_A = Σ λ_i a_i`, `p_B = Σ λ_i b_i` with the barycentric
//! weights `λ_i` of `v` in `W`.
//!
//! # Cameron's enhancements
//!
//! 1. **Hill-climbing support.** On a convex polygon `x·d` is unimodal around the boundary, so
//!    the maximiser is found by walking from a cached vertex towards the neighbour that increases
//!    `x·d`. The walk compares two adjacent vertices with one dot product of their edge vector,
//!    `(x_{i+1} − x_i)·d`: the cached vertex `i` is the support iff `(x_{i+1} − x_i)·d ≤ 0` and
//!    `(x_i − x_{i−1})·d ≥ 0`, which costs 2 evaluations, and every step along the boundary costs
//!    one more. [`GjkOutput::support_evals`] counts these dot products; a query that makes `k`
//!    comparisons reads `k + 1` distinct vertices (the cached one and its two neighbours when it
//!    is still the support).
//! 2. **Warm start.** The final simplex (vertex indices) is kept in a [`GjkCache`] and re-evaluated
//!    at the current poses at the next call; under coherent motion the first support point is
//!    already in the simplex and GJK stops after one iteration.
//!
//! The closest point of a simplex follows Johnson's sub-algorithm in the barycentric/Voronoi form
//! used by Box2D (`b2SolveSimplex2`, `b2SolveSimplex3`), with a guard for degenerate triangles.

use crate::geom::{cross, Vec2};

/// Relative termination tolerance `ε_rel` of §9.2 (dimensionless).
pub const GJK_EPS_REL: f64 = 1e-6;
/// Absolute termination tolerance `ε_abs` of §9.2 (m): `|v| ≤ ε_abs` counts as touching.
pub const GJK_EPS_ABS: f64 = 1e-9;
/// Iteration limit of §9.2.
pub const GJK_MAX_ITERATIONS: u32 = 32;

/// Warm-start state of GJK for one pair of polygons: the last simplex (vertex indices) and the last
/// support vertices (hill-climbing hints). Small and `Copy` (36 bytes); keep one per pair.
///
/// It holds no work counters: the global stage keeps one cache per AABB pair and the local
/// stage one per tracked pair, and both stream through them every update (issue 17: counters
/// made it 72 bytes). Each call's counts are in its [`GjkOutput`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GjkCache {
    /// Number of simplex points stored (0 = cold).
    count: u8,
    /// A-vertex index of each simplex point.
    index_a: [u32; 3],
    /// B-vertex index of each simplex point.
    index_b: [u32; 3],
    /// Last support vertex of A (start of the next hill climb).
    hint_a: u32,
    /// Last support vertex of B.
    hint_b: u32,
}

impl GjkCache {
    /// An empty (cold) cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets the simplex and hints, so the next call starts cold.
    pub fn reset(&mut self) {
        self.count = 0;
        self.hint_a = 0;
        self.hint_b = 0;
    }
}

/// Result of [`gjk_distance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GjkOutput {
    /// Distance between the polygons (m); `0` when they overlap.
    pub distance: f64,
    /// Witness point on A (m, world frame). On overlap, a point common to both polygons.
    pub point_a: Vec2,
    /// Witness point on B (m, world frame).
    pub point_b: Vec2,
    /// True if the origin was found inside `A ⊖ B` (the polygons overlap).
    pub overlap: bool,
    /// Number of points in the final simplex (1–3).
    pub simplex_count: usize,
    /// A-vertex indices of the final simplex points (first `simplex_count` are valid).
    pub index_a: [u32; 3],
    /// B-vertex indices of the final simplex points.
    pub index_b: [u32; 3],
    /// Barycentric weights `λ_i` of the closest point in the final simplex (sum to 1).
    pub weights: [f64; 3],
    /// Iterations used by this call (support points requested from `C`; each one queries the
    /// support of A and of B).
    pub iterations: u32,
    /// Support-function evaluations of this call: one dot product `(x_j − x_i)·d` per comparison
    /// of two adjacent vertices during hill climbing.
    pub support_evals: u32,
}

/// One simplex point: `w = a − b`, its vertices and its barycentric weight.
#[derive(Clone, Copy, Debug, Default)]
struct SimplexVertex {
    wa: Vec2,
    wb: Vec2,
    w: Vec2,
    lambda: f64,
    ia: u32,
    ib: u32,
}

impl SimplexVertex {
    #[inline]
    fn new(a: &[Vec2], b: &[Vec2], ia: usize, ib: usize) -> Self {
        Self {
            wa: a[ia],
            wb: b[ib],
            w: a[ia] - b[ib],
            lambda: 1.0,
            ia: ia as u32,
            ib: ib as u32,
        }
    }
}

/// Hill-climbing support `argmax_i x_i·d` on a CCW convex polygon, starting at vertex `hint`
/// (Cameron's enhancement 1). Adds the number of dot products used to `evals`.
///
/// `x·d` is unimodal around a strictly convex polygon, so the local maximum found by the walk is
/// the global one. The walk is bounded by `n` steps so that a NaN direction cannot loop forever.
#[inline]
pub fn support_hill_climb(verts: &[Vec2], d: Vec2, hint: usize, evals: &mut u64) -> usize {
    let n = verts.len();
    let next = |i: usize| if i + 1 == n { 0 } else { i + 1 };
    let prev = |i: usize| if i == 0 { n - 1 } else { i - 1 };
    let mut i = if hint < n { hint } else { 0 };
    // Forward edge i → i+1: climb counter-clockwise while it goes uphill.
    *evals += 1;
    if (verts[next(i)] - verts[i]).dot(d) > 0.0 {
        i = next(i);
        for _ in 0..n {
            *evals += 1;
            if (verts[next(i)] - verts[i]).dot(d) > 0.0 {
                i = next(i);
            } else {
                break;
            }
        }
        return i;
    }
    // Backward edge i−1 → i: climb clockwise while the previous vertex is higher.
    *evals += 1;
    if (verts[i] - verts[prev(i)]).dot(d) < 0.0 {
        i = prev(i);
        for _ in 0..n {
            *evals += 1;
            if (verts[i] - verts[prev(i)]).dot(d) < 0.0 {
                i = prev(i);
            } else {
                break;
            }
        }
    }
    i
}

/// The simplex of GJK (1–3 points).
#[derive(Clone, Copy, Debug, Default)]
struct Simplex {
    v: [SimplexVertex; 3],
    count: usize,
}

impl Simplex {
    /// The point `Σ λ_i w_i` of the simplex closest to the origin (after `solve`).
    fn closest(&self) -> Vec2 {
        match self.count {
            1 => self.v[0].w,
            2 => self.v[0].w * self.v[0].lambda + self.v[1].w * self.v[1].lambda,
            _ => Vec2::ZERO,
        }
    }

    /// Witness points `(Σ λ_i a_i, Σ λ_i b_i)`.
    fn witnesses(&self) -> (Vec2, Vec2) {
        let mut pa = Vec2::ZERO;
        let mut pb = Vec2::ZERO;
        for k in 0..self.count {
            pa += self.v[k].wa * self.v[k].lambda;
            pb += self.v[k].wb * self.v[k].lambda;
        }
        (pa, pb)
    }

    /// Reduces the simplex to the supporting subset of its closest point to the origin and sets the
    /// barycentric weights (Johnson's sub-algorithm).
    fn solve(&mut self) {
        match self.count {
            1 => self.v[0].lambda = 1.0,
            2 => self.solve2(),
            3 => self.solve3(),
            _ => {}
        }
    }

    /// Segment `[w1, w2]`: `t = clamp(−w1·e12/|e12|², 0, 1)`, written with the unnormalised
    /// barycentric coordinates `u1 = w2·e12` (weight of `w1`) and `u2 = −w1·e12` (weight of `w2`).
    fn solve2(&mut self) {
        let w1 = self.v[0].w;
        let w2 = self.v[1].w;
        let e12 = w2 - w1;
        let u2 = -w1.dot(e12);
        if u2 <= 0.0 {
            // Vertex region of w1.
            self.v[0].lambda = 1.0;
            self.count = 1;
            return;
        }
        let u1 = w2.dot(e12);
        if u1 <= 0.0 {
            // Vertex region of w2.
            self.v[1].lambda = 1.0;
            self.v[0] = self.v[1];
            self.count = 1;
            return;
        }
        let inv = 1.0 / (u1 + u2);
        self.v[0].lambda = u1 * inv;
        self.v[1].lambda = u2 * inv;
    }

    /// Triangle `[w1, w2, w3]`: Voronoi regions of the origin with respect to the vertices, edges and
    /// interior, tested with barycentric coordinates (edge `ij`: `u_ij`, `v_ij`; triangle: signed
    /// sub-areas `n123·(wj × wk)`).
    fn solve3(&mut self) {
        let w1 = self.v[0].w;
        let w2 = self.v[1].w;
        let w3 = self.v[2].w;

        let e12 = w2 - w1;
        let d12_1 = w2.dot(e12);
        let d12_2 = -w1.dot(e12);
        let e13 = w3 - w1;
        let d13_1 = w3.dot(e13);
        let d13_2 = -w1.dot(e13);
        let e23 = w3 - w2;
        let d23_1 = w3.dot(e23);
        let d23_2 = -w2.dot(e23);

        let n123 = cross(e12, e13);
        let d123_1 = n123 * cross(w2, w3);
        let d123_2 = n123 * cross(w3, w1);
        let d123_3 = n123 * cross(w1, w2);

        if d12_2 <= 0.0 && d13_2 <= 0.0 {
            self.v[0].lambda = 1.0;
            self.count = 1;
            return;
        }
        if d12_1 > 0.0 && d12_2 > 0.0 && d123_3 <= 0.0 {
            let inv = 1.0 / (d12_1 + d12_2);
            self.v[0].lambda = d12_1 * inv;
            self.v[1].lambda = d12_2 * inv;
            self.count = 2;
            return;
        }
        if d13_1 > 0.0 && d13_2 > 0.0 && d123_2 <= 0.0 {
            let inv = 1.0 / (d13_1 + d13_2);
            self.v[0].lambda = d13_1 * inv;
            self.v[2].lambda = d13_2 * inv;
            self.v[1] = self.v[2];
            self.count = 2;
            return;
        }
        if d12_1 <= 0.0 && d23_2 <= 0.0 {
            self.v[1].lambda = 1.0;
            self.v[0] = self.v[1];
            self.count = 1;
            return;
        }
        if d13_1 <= 0.0 && d23_1 <= 0.0 {
            self.v[2].lambda = 1.0;
            self.v[0] = self.v[2];
            self.count = 1;
            return;
        }
        if d23_1 > 0.0 && d23_2 > 0.0 && d123_1 <= 0.0 {
            let inv = 1.0 / (d23_1 + d23_2);
            self.v[1].lambda = d23_1 * inv;
            self.v[2].lambda = d23_2 * inv;
            self.v[0] = self.v[2];
            self.count = 2;
            return;
        }
        let sum = d123_1 + d123_2 + d123_3;
        if sum > 0.0 && sum.is_finite() {
            // Interior: the origin is inside the triangle.
            let inv = 1.0 / sum;
            self.v[0].lambda = d123_1 * inv;
            self.v[1].lambda = d123_2 * inv;
            self.v[2].lambda = d123_3 * inv;
            self.count = 3;
            return;
        }
        // Degenerate (collinear) triangle that no region test claimed: keep the best of its edges.
        let mut best = *self;
        let mut best_d2 = f64::INFINITY;
        for (i, j) in [(0usize, 1usize), (0, 2), (1, 2)] {
            let mut s = Simplex {
                v: [self.v[i], self.v[j], self.v[j]],
                count: 2,
            };
            s.solve2();
            let d2 = s.closest().length_squared();
            if d2 < best_d2 {
                best_d2 = d2;
                best = s;
            }
        }
        *self = best;
    }

    fn contains(&self, ia: u32, ib: u32) -> bool {
        (0..self.count).any(|k| self.v[k].ia == ia && self.v[k].ib == ib)
    }
}

/// GJK distance between two convex polygons given by their world-frame CCW vertex lists `a` and `b`
/// (m), warm-started from and saving into `cache` (§9.2).
///
/// Returns the distance (0 on overlap), the witness points and the final simplex (vertex indices:
/// the feature information used to initialise the closest-feature tracker). No allocation. An empty
/// vertex list gives an infinite distance and an empty simplex.
pub fn gjk_distance(a: &[Vec2], b: &[Vec2], cache: &mut GjkCache) -> GjkOutput {
    let (na, nb) = (a.len(), b.len());
    if na == 0 || nb == 0 {
        return GjkOutput {
            distance: f64::INFINITY,
            point_a: Vec2::ZERO,
            point_b: Vec2::ZERO,
            overlap: false,
            simplex_count: 0,
            index_a: [0; 3],
            index_b: [0; 3],
            weights: [0.0; 3],
            iterations: 0,
            support_evals: 0,
        };
    }

    // Warm start (Cameron 2): re-evaluate the cached simplex at the current poses.
    let mut simplex = Simplex::default();
    for k in 0..cache.count as usize {
        let (ia, ib) = (cache.index_a[k], cache.index_b[k]);
        if (ia as usize) < na && (ib as usize) < nb && !simplex.contains(ia, ib) {
            simplex.v[simplex.count] = SimplexVertex::new(a, b, ia as usize, ib as usize);
            simplex.count += 1;
        }
    }
    if simplex.count == 0 {
        // Cold start: any point of C.
        let ia = (cache.hint_a as usize).min(na - 1);
        let ib = (cache.hint_b as usize).min(nb - 1);
        simplex.v[0] = SimplexVertex::new(a, b, ia, ib);
        simplex.count = 1;
    }
    // Equal weights as a start; `solve` sets the real ones.
    let w0 = 1.0 / simplex.count as f64;
    for k in 0..simplex.count {
        simplex.v[k].lambda = w0;
    }
    simplex.solve();

    let mut hint_a = cache.hint_a as usize;
    let mut hint_b = cache.hint_b as usize;
    let mut iterations = 0u32;
    let mut support_evals = 0u64;
    let mut overlap = simplex.count == 3;
    while !overlap && iterations < GJK_MAX_ITERATIONS {
        let v = simplex.closest();
        let vv = v.length_squared();
        if vv <= GJK_EPS_ABS * GJK_EPS_ABS {
            // The origin is on the simplex: touching (distance ≤ ε_abs).
            break;
        }
        // w = s_C(−v) = s_A(−v) − s_B(v).
        iterations += 1;
        hint_a = support_hill_climb(a, -v, hint_a, &mut support_evals);
        hint_b = support_hill_climb(b, v, hint_b, &mut support_evals);
        let w = a[hint_a] - b[hint_b];
        if vv - v.dot(w) <= GJK_EPS_REL * GJK_EPS_REL * vv {
            break;
        }
        if simplex.contains(hint_a as u32, hint_b as u32) {
            // No new support point: v is the closest point of C (exact for polytopes).
            break;
        }
        let saved = simplex;
        simplex.v[simplex.count] = SimplexVertex::new(a, b, hint_a, hint_b);
        simplex.count += 1;
        simplex.solve();
        if simplex.count == 3 {
            overlap = true;
            break;
        }
        if simplex.closest().length_squared() >= vv {
            // No progress (round-off): keep the previous, better simplex.
            simplex = saved;
            break;
        }
    }

    // Save the warm-start state.
    cache.count = simplex.count as u8;
    let mut out = GjkOutput {
        distance: 0.0,
        point_a: Vec2::ZERO,
        point_b: Vec2::ZERO,
        overlap,
        simplex_count: simplex.count,
        index_a: [0; 3],
        index_b: [0; 3],
        weights: [0.0; 3],
        iterations,
        support_evals: support_evals.min(u32::MAX as u64) as u32,
    };
    for k in 0..simplex.count {
        cache.index_a[k] = simplex.v[k].ia;
        cache.index_b[k] = simplex.v[k].ib;
        out.index_a[k] = simplex.v[k].ia;
        out.index_b[k] = simplex.v[k].ib;
        out.weights[k] = simplex.v[k].lambda;
    }
    cache.hint_a = hint_a as u32;
    cache.hint_b = hint_b as u32;

    let (pa, pb) = simplex.witnesses();
    if overlap {
        out.point_a = pa;
        out.point_b = pa;
    } else {
        out.point_a = pa;
        out.point_b = pb;
        out.distance = (pa - pb).length();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(cx: f64, cy: f64, h: f64) -> Vec<Vec2> {
        vec![
            Vec2::new(cx - h, cy - h),
            Vec2::new(cx + h, cy - h),
            Vec2::new(cx + h, cy + h),
            Vec2::new(cx - h, cy + h),
        ]
    }

    #[test]
    fn separated_squares() {
        let a = square(0.0, 0.0, 1.0);
        let b = square(3.5, 0.2, 1.0);
        let mut c = GjkCache::new();
        let o = gjk_distance(&a, &b, &mut c);
        assert!((o.distance - 1.5).abs() < 1e-12);
        assert!(!o.overlap);
        // Warm start: same answer, one iteration.
        let o2 = gjk_distance(&a, &b, &mut c);
        assert!((o2.distance - 1.5).abs() < 1e-12);
        assert!(o2.iterations <= 1);
    }

    /// The cache is the warm-start state alone: 36 bytes, which the global stage keeps per AABB
    /// pair and the local stage per tracked pair (it was 72 with the counters it used to carry).
    #[test]
    fn gjk_cache_is_36_bytes() {
        assert_eq!(std::mem::size_of::<GjkCache>(), 36);
    }

    /// A call reports its own work: hill climbing from a cold hint over a 12-gon evaluates
    /// several supports, and the warm call that follows needs fewer.
    #[test]
    fn a_call_counts_its_support_evaluations() {
        let ngon = |cx: f64, n: usize| -> Vec<Vec2> {
            (0..n)
                .map(|k| {
                    let t = std::f64::consts::TAU * k as f64 / n as f64;
                    Vec2::new(cx + t.cos(), t.sin())
                })
                .collect()
        };
        let (a, b) = (ngon(0.0, 12), ngon(3.0, 12));
        let mut c = GjkCache::new();
        let cold = gjk_distance(&a, &b, &mut c);
        let warm = gjk_distance(&a, &b, &mut c);
        assert!(cold.support_evals >= 2 * cold.iterations, "{cold:?}");
        assert!(cold.support_evals > 6, "{cold:?}");
        assert!(warm.support_evals < cold.support_evals, "{warm:?}");
    }

    #[test]
    fn overlapping_squares() {
        let a = square(0.0, 0.0, 1.0);
        let b = square(1.5, 0.5, 1.0);
        let o = gjk_distance(&a, &b, &mut GjkCache::new());
        assert!(o.overlap);
        assert_eq!(o.distance, 0.0);
    }

    #[test]
    fn hill_climb_finds_support() {
        let a = square(0.0, 0.0, 1.0);
        let mut e = 0;
        assert_eq!(support_hill_climb(&a, Vec2::new(1.0, 1.0), 0, &mut e), 2);
        assert_eq!(support_hill_climb(&a, Vec2::new(-1.0, 1.0), 0, &mut e), 3);
        assert_eq!(support_hill_climb(&a, Vec2::new(1.0, -1.0), 3, &mut e), 1);
    }
}
