//! The vertex scan (§9.4): every vertex of one polygon inside the other or within `δ_c` of it,
//! against its edge of least depth, with the corner-on-corner rule at a corner of two edges.

use super::{Ctx, Side};
use crate::collide::reuse::Slack;
use crate::collide::{Collider, VeCandidate};
use crate::geom::{select_max, select_min, Vec2};

impl Ctx {
    /// Penetrating pair (§9.4): every vertex of `a` inside `b` or within `δ_c` of it, against the
    /// edge of `b` whose *line is nearest* (largest `d_j`), provided that edge's range holds the
    /// vertex; or the facing edge when the vertex sits at a corner of `b` (corner-on-corner rule,
    /// [`corner_facing_edge`]). Returns a vertex of A strictly inside B (all `d_j < 0`), if any.
    ///
    /// # Why the nearest line, and why a corner vertex outside B gets nothing
    ///
    /// A record on edge `e` stores `½·K_c·d_e²` (§5.9), so its depth `−d_e` must not exceed the
    /// vertex's real depth in B, or energy appears from nothing when the record is created (the
    /// defect of issue 10: a far edge, `d = −23.5 mm`, proposed for a vertex 1.5 mm *outside* B).
    ///
    /// - *V inside B* (`d_j < 0` for all `j`): its depth is `dist(V, ∂B) = −max_j d_j`, attained
    ///   on the nearest line `j*`, and the foot of the perpendicular lies on the edge `j*` itself:
    ///   were the foot `F` outside the segment, it would be outside B (a supporting line meets B
    ///   only in its edge), so the segment `V→F` would leave B through another edge `k` at a point
    ///   `Q` with `−d_k ≤ |V − Q| < |V − F| = −d_{j*}`, contradicting `j*` nearest. So the nearest
    ///   edge always holds `V` in its range, and `d_{j*} = max_j d_j` is exactly the real depth.
    /// - *V outside B within `δ_c`* (`max_j d_j > 0`): either V is in the outer Voronoi region of
    ///   an edge `j`, whose range holds V and whose line is then the nearest (`d_j = dist(V, B) ≥
    ///   d_k` for every `k`, since B lies in each half-plane); or V is in the region of a corner
    ///   `W`, outside the range of both edges at `W` (up to `ε_s`). There no edge describes the
    ///   contact — every in-range edge is a far one, `d ≪ max_j d_j` — so no candidate is made; the
    ///   vertex gets one as soon as it reaches an edge region or enters B.
    ///
    /// The corner-on-corner rule may choose the neighbour of the nearest edge at the corner; it is
    /// limited to a neighbour whose line is within `δ_c` of the nearest one, so every candidate
    /// satisfies `d_e ≥ max_j d_j − δ_c` (the invariant the contact manager checks,
    /// [`nearest_line`](super::nearest_line)).
    ///
    /// Every comparison's distance from its threshold is recorded in `slack` (`reuse.rs`).
    pub(in crate::collide) fn vertices_against(
        &self,
        a: Side,
        b: Side,
        out: &mut Vec<VeCandidate>,
        slack: &mut Slack,
    ) -> Option<Vec2> {
        let mut inside = None;
        // A vertex farther than `δ_c + ε_s` outside B's box is farther than that from B: no
        // candidate (one needs an edge whose range holds it within `ε_s` and whose line is
        // within `δ_c`, which puts it within `δ_c + ε_s` of that edge) and not inside.
        // A piece with `across` seams also holds vertices up to its seams' reach beyond them.
        let across = b.c.across != 0;
        let far = b.c.max_reach();
        let reach = Vec2::new(
            self.delta_c + self.eps_s + far,
            self.delta_c + self.eps_s + far,
        );
        let (lo, hi) = (b.c.aabb.min - reach, b.c.aabb.max + reach);
        // B's edges as (start, normal) pairs, read without bounds checks in the loop below.
        let (b_starts, b_normals) = (b.c.world_vertices(), b.c.world_normals());
        'vertex: for (v, &p) in a.c.world_vertices().iter().enumerate() {
            if p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y {
                slack.decided((lo - p).max(p - hi).max_element());
                continue;
            }
            let mut nearest = 0usize;
            let mut max_d = f64::NEG_INFINITY;
            // The second largest line distance: the nearest line is decided by their gap.
            let mut second = f64::NEG_INFINITY;
            // Edge lines within reach of the vertex (−δ_c ≤ d ≤ δ_c): two or more only within
            // ~δ_c of a corner of B (or across a part of B thinner than 2·δ_c), where least depth
            // can be decided by round-off. Counting costs one compare per edge; the corner rule
            // itself runs only then.
            let mut near_lines = 0u32;
            // The nearest line of all, seams included: whether the vertex is inside B.
            let mut max_all = f64::NEG_INFINITY;
            // The nearest seam line: whether the vertex is across a seam.
            let mut max_seam = f64::NEG_INFINITY;
            for (e, (&e0, &n)) in b_starts.iter().zip(b_normals).enumerate() {
                // = `b.c.edge_distance(e, p)`
                let d = n.dot(p - e0);
                if d > self.delta_c {
                    // Across a seam within its reach: in the covering piece under B, where B's
                    // surface lines hold it too (`Collider::across`).
                    let r = if across { b.c.reach(e) } else { 0.0 };
                    if d <= r {
                        slack.decided((d - self.delta_c).min(r - d));
                    } else {
                        // Farther than δ_c from B's half-plane, so from B.
                        slack.decided(d - self.delta_c);
                        continue 'vertex;
                    }
                }
                max_all = select_max(d, max_all);
                if b.c.seams != 0 && b.c.is_seam(e) {
                    max_seam = select_max(d, max_seam);
                    // A seam is no surface of B's body: never the vertex's contact normal.
                    slack.decided(select_min((d + self.delta_c).abs(), self.delta_c - d));
                    continue;
                }
                if d > max_d {
                    second = max_d;
                    max_d = d;
                    nearest = e;
                } else {
                    second = select_max(d, second);
                }
                near_lines += (d >= -self.delta_c) as u32;
                slack.decided(select_min((d + self.delta_c).abs(), self.delta_c - d));
            }
            slack.decided(0.5 * (max_d - second));
            if max_all < 0.0 {
                slack.inside = slack.inside.max(-max_all);
                if inside.is_none() {
                    inside = Some(p);
                }
            }
            // Outside B only across seams that face a partly covered edge, within their reach:
            // in the piece under B, at B's concave corner with it (`Collider::across_seam`).
            let across_only =
                across && max_seam > 0.0 && max_d <= 0.0 && b.c.across_seam(p).is_some();
            if max_d == f64::NEG_INFINITY || (max_all > max_d && max_all > 0.0 && !across_only) {
                // Every edge of B is a seam, or the vertex is outside B across a seam: the
                // neighbouring pieces' surfaces hold it.
                slack.decided(max_all.abs());
                continue;
            }
            if across {
                // `across_only` is decided by the signs of `max_seam` and then `max_d` (the
                // reach tests are recorded in the loop above).
                slack.decided(max_seam.abs());
                if max_seam > 0.0 {
                    slack.decided(max_d.abs());
                }
            }
            // Nearest line first: its edge must hold the vertex (always so inside B, see above);
            // otherwise the vertex is in a corner region outside B and gets no candidate.
            let s = b.c.edge_coordinate(nearest, p);
            let (r0, r1) = b.c.edge_range(nearest);
            slack.decided((s - r0 + self.eps_s).abs().min((r1 + self.eps_s - s).abs()));
            if s < r0 - self.eps_s || s > r1 + self.eps_s {
                continue;
            }
            let mut e = nearest;
            if near_lines >= 2 {
                // Decided by orientation (the corner-on-corner rule): not reused.
                slack.decided(0.0);
                e = self.corner_edge(a.c, v, b.c, e, max_d);
            }
            out.push(VeCandidate {
                vertex_collider: a.id,
                vertex: v as u32,
                edge_collider: b.id,
                edge: e as u32,
            });
        }
        inside
    }

    /// The edge for vertex `v` of `a`, proposed against the nearest edge `e` of `b` (line
    /// distance `max_d`), when two edge lines of `b` are within `δ_c` of it: if a neighbour `e'`
    /// of `e` (sharing the corner `W`) is also within `δ_c`, no more than `δ_c` deeper than the
    /// nearest line (`d' ≥ max_d − δ_c`), and has the vertex in its range, the vertex is at `W`
    /// and the choice between `e` and `e'` is the corner-on-corner rule's
    /// ([`corner_facing_edge`]); otherwise `e`.
    fn corner_edge(&self, a: &Collider, v: usize, b: &Collider, e: usize, max_d: f64) -> usize {
        let p = a.world_vertices()[v];
        for e2 in [b.local.prev(e), b.local.next(e)] {
            if b.is_seam(e2) {
                continue;
            }
            let d = b.edge_distance(e2, p);
            let s = b.edge_coordinate(e2, p);
            let in_range = s >= -self.eps_s && s <= b.local.lengths()[e2] + self.eps_s;
            if d.abs() <= self.delta_c && d >= max_d - self.delta_c && in_range {
                if let Some(f) = corner_facing_edge(a, v, b, e, e2, self.cos_parallel) {
                    return f;
                }
            }
        }
        e
    }
}

/// Corner-on-corner rule: of two adjacent edges `e1`, `e2` of `b` (meeting at the corner `W`) that
/// vertex `v` of `a` sits at, the one that *faces* `a`, i.e. whose outward normal is antiparallel,
/// within [`NEAR_PARALLEL_ANGLE`](crate::collide::NEAR_PARALLEL_ANGLE) (`n_b·n_a < −cos_parallel`), to the normal of an edge of `a`
/// incident to `v`. `None` if neither or both do (then the position-based rules decide).
///
/// Why orientation, not position: at a stacked corner (equal boxes, upper vertex 0 on lower vertex
/// 3) the vertex is `δ ≈ m·g/(2·K_c) ≈ 1e-4 m` below the top line and on the side line to round-off
/// (`d = ±1e-19 m`), so the least-depth rule (larger `d`) and the crossed-edge rule (`d_{k−1} > 0 ≥
/// d_k`) both pick the side edge by round-off, and the record flickers between side edge and
/// release every tick. The faces in contact are known from the orientations alone: the upper box's
/// bottom normal `(sin θ, −cos θ)` is antiparallel to the lower box's top normal `(0, 1)`
/// (`n·n = −cos θ`), while its side normals are at `±90°` or parallel to the lower box's side normal
/// (`n·n ∈ {±sin θ, cos θ}`): for `|θ| < 0.1 rad` exactly one edge at `W` faces. Two boxes
/// touching diagonally corner to corner have two facing pairs (top/bottom and side/side) and are
/// left to the other rules, as is any corner without a face of `a` along an edge of `b` (a wedge
/// tip entering near a corner: the crossed edge is the constraint there, §8.3).
pub fn corner_facing_edge(
    a: &Collider,
    v: usize,
    b: &Collider,
    e1: usize,
    e2: usize,
    cos_parallel: f64,
) -> Option<usize> {
    let (na_out, na_in) = (a.world_normals()[v], a.world_normals()[a.local.prev(v)]);
    let faces = |e: usize| {
        let n = b.world_normals()[e];
        n.dot(na_out) < -cos_parallel || n.dot(na_in) < -cos_parallel
    };
    match (faces(e1), faces(e2)) {
        (true, false) => Some(e1),
        (false, true) => Some(e2),
        _ => None,
    }
}
