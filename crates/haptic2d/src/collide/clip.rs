//! The reference face of an overlapping pair and its clip contacts (issue 35, crossing corners;
//! docs/MODELS.md §9.5b): Box2D v3's `b2ClipPolygons` (`src/manifold.c`) written as vertex–edge
//! pairs.
//!
//! The separating-axis test ([`sat_face`]) gives the pair's least overlap `D` and the edge `f` of
//! one polygon, the **reference** `R`, whose normal is that axis; the other is the **incident**
//! polygon `I`, and its **incident edge** `e_I` is the edge whose normal is most antiparallel to
//! `n_f`. Box2D clips `e_I` to the side planes of `f` (the lines through `f`'s ends along `n_f`)
//! and keeps the clipped points behind `f`. Each such point is either
//!
//! - a vertex `V` of `I` behind `f`'s line inside `f`'s range: the VE pair `(V, f)`, depth
//!   `−d_f(V) ≤ D` (`D` is the deepest vertex of `I` behind `f`); here every vertex of `I` that is,
//!   not only `e_I`'s ends (a polygon with many short edges can have several);
//! - or the point `P` where `e_I` crosses a side plane, at an end `W` of `f`: the VE pair
//!   `(W, e_I)` of `R`'s corner against `I`'s edge, kept when `P` is behind `f`'s line and `W` is
//!   behind `e_I`'s line inside `e_I`'s range.
//!   Its depth is at most `D`: the clipped point `P = W − t·n_f` lies on `e_I` with `t ≤ D`, so
//!   `−d_{e_I}(W) = t·(−n_{e_I}·n_f) ≤ t ≤ D`.
//!
//! So every clip pair satisfies the overlap bound of the depth invariant (`−d_e ≤ D + δ_c`,
//! `ContactSet::step`) and pushes along (or, for `W`, nearly along) the separating axis, where the
//! vertex scan's nearest lines can be side faces whose normals hold nothing of the load.
//! Seams (`seam.rs`) are neither reference faces nor incident edges. Costs `O((n_a + n_b)²)`.

use super::{Collider, VeCandidate};
use crate::geom::Vec2;

/// How much deeper than a pair's deepest record (or, with no vertex inside, than nothing) its
/// separating-axis overlap may run before its clip pairs take over, as a fraction of `δ_c` (0.5:
/// 1 mm with the default `δ_c`). Below it the records are the vertex scan's and the crossed-edge
/// rule's (the depth invariant allows a record `δ_c` off its vertex's nearest line), so ordinary
/// contacts (a face on a face, a corner in a face) never reach it and keep their trajectories bit
/// for bit.
pub const CLIP_MARGIN: f64 = 0.5;

/// The separating-axis result of an overlapping pair with its reference face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SatFace {
    /// Least overlap `D` (m) over the admissible axes (see [`sat_depth`](super::sat_depth)).
    pub depth: f64,
    /// Unit direction in which the first collider moves (relative to the second) to separate.
    pub axis: Vec2,
    /// Whether the reference face belongs to the first collider (else to the second).
    pub reference_is_first: bool,
    /// The reference face (an edge of the reference collider).
    pub face: usize,
    /// The axis is admissible (no seam normal, no motion through a seam); false for the
    /// fallback of a piece without an admissible axis.
    pub admissible: bool,
}

/// The signed distance (m) of `q`'s deepest vertex from `p`'s edge line `e`: minus the overlap
/// along `n_e` when negative (`+∞` for a `q` without vertices).
#[inline]
fn deepest_behind(p: &Collider, e: usize, q: &Collider) -> f64 {
    q.world_vertices()
        .iter()
        .map(|&v| p.edge_distance(e, v))
        .fold(f64::INFINITY, f64::min)
}

/// [`deepest_behind`] where no vertex of `q` is behind `p`'s edge line `e` by more than both 0
/// and `floor` (m); `None` as soon as one is (then the overlap along `n_e` exceeds both, and the
/// axis decides nothing in [`sat_depth_above`]). The same distances, compared in the same order.
#[inline]
fn deepest_behind_within(p: &Collider, e: usize, q: &Collider, floor: f64) -> Option<f64> {
    let mut min_d = f64::INFINITY;
    for &v in q.world_vertices() {
        let d = p.edge_distance(e, v);
        if d < 0.0 && -d > floor {
            return None;
        }
        min_d = min_d.min(d);
    }
    Some(min_d)
}

/// The separating-axis depth of `a` and `b` with its reference face; `None` if some axis
/// separates them (or one has no edge). The same search, order and ties as
/// [`sat_depth`](super::sat_depth), which calls it.
pub fn sat_face(a: &Collider, b: &Collider) -> Option<SatFace> {
    let seams = a.seams != 0 || b.seams != 0;
    let mut best: Option<SatFace> = None;
    let mut fallback: Option<SatFace> = None;
    for (p, q, sign, first) in [(a, b, -1.0, true), (b, a, 1.0, false)] {
        for e in 0..p.len() {
            let min_d = deepest_behind(p, e, q);
            if min_d >= 0.0 {
                return None;
            }
            if seams && p.is_seam(e) {
                continue;
            }
            let u = p.world_normals()[e] * sign;
            let cand = SatFace {
                depth: -min_d,
                axis: u,
                reference_is_first: first,
                face: e,
                admissible: true,
            };
            if fallback.is_none_or(|f| -min_d < f.depth) {
                fallback = Some(SatFace {
                    admissible: false,
                    ..cand
                });
            }
            let through =
                seams && (super::seam::through_seam(b, u) || super::seam::through_seam(a, -u));
            if !through && best.is_none_or(|f| -min_d < f.depth) {
                best = Some(cand);
            }
        }
    }
    best.or(fallback)
}

/// The separating-axis depth of `a` and `b` when it exceeds `floor` (m), else `None`: the same
/// value as [`sat_depth`](super::sat_depth) where it is returned. The search stops at the first
/// admissible axis (no seam, no motion out through one) whose overlap is at most `floor`: the
/// depth, the least overlap over the admissible axes, cannot exceed it. That is how
/// [`max_overlap`](super::overlap::max_overlap) skips most of a pile's shallow contacts. On
/// each axis the scan of the other polygon's vertices stops at the first one deeper than both 0
/// and `floor` (`deepest_behind_within`): neither exit can fire on that axis then.
pub fn sat_depth_above(a: &Collider, b: &Collider, floor: f64) -> Option<f64> {
    let seams = a.seams != 0 || b.seams != 0;
    for (p, q, sign) in [(a, b, -1.0), (b, a, 1.0)] {
        for e in 0..p.len() {
            let Some(min_d) = deepest_behind_within(p, e, q, floor) else {
                continue;
            };
            if min_d >= 0.0 {
                return None;
            }
            if -min_d <= floor
                && (!seams || (!p.is_seam(e) && admissible_axis(a, b, p.world_normals()[e] * sign)))
            {
                return None;
            }
        }
    }
    sat_face(a, b).map(|f| f.depth).filter(|&d| d > floor)
}

/// Whether `u` is an admissible separating axis for moving `a` relative to `b` (no component out
/// through a seam of either, see [`sat_depth`](super::sat_depth)): only then does the overlap along
/// `u` bound the pair's separating-axis depth from above. Inlined: the clip stage asks it of every
/// record each sample, and almost every pair has no seam.
#[inline]
pub fn admissible_axis(a: &Collider, b: &Collider, u: Vec2) -> bool {
    (a.seams == 0 && b.seams == 0) || admissible_across_seams(a, b, u)
}

/// [`admissible_axis`] for a pair with a seam: `u` moves neither out through a seam.
#[inline(never)]
fn admissible_across_seams(a: &Collider, b: &Collider, u: Vec2) -> bool {
    !(super::seam::through_seam(b, u) || super::seam::through_seam(a, -u))
}

/// The edge of `i` whose outward normal is most antiparallel to `n` (the incident edge; the
/// first on a tie), seams left out; `None` if every edge is a seam.
pub fn incident_edge(i: &Collider, n: Vec2) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for e in 0..i.len() {
        if i.is_seam(e) {
            continue;
        }
        let c = i.world_normals()[e].dot(n);
        if best.is_none_or(|(_, b)| c < b) {
            best = Some((e, c));
        }
    }
    best.map(|(e, _)| e)
}

/// The clip pairs of `face` (an admissible [`SatFace`] of colliders `(ia, a)`, `(ib, b)`): the
/// vertices of the incident polygon behind the reference face's line within its range (`±eps_s`),
/// and the reference face's ends behind the incident edge's line within its range (module docs),
/// pushed to `out` in that order. Returns how many were pushed.
pub fn clip_pairs(
    (ia, a): (u32, &Collider),
    (ib, b): (u32, &Collider),
    face: &SatFace,
    eps_s: f64,
    out: &mut Vec<VeCandidate>,
) -> usize {
    let ((ir, r), (ii, i)) = if face.reference_is_first {
        ((ia, a), (ib, b))
    } else {
        ((ib, b), (ia, a))
    };
    let f = face.face;
    let len_f = r.local.lengths()[f];
    let start = out.len();
    for (v, &p) in i.world_vertices().iter().enumerate() {
        let s = r.edge_coordinate(f, p);
        if r.edge_distance(f, p) <= 0.0 && s >= -eps_s && s <= len_f + eps_s {
            out.push(VeCandidate {
                vertex_collider: ii,
                vertex: v as u32,
                edge_collider: ir,
                edge: f as u32,
            });
        }
    }
    if let Some(e_i) = incident_edge(i, r.world_normals()[f]) {
        let len_i = i.local.lengths()[e_i];
        let (i0, i1) = (
            i.world_vertices()[e_i],
            i.world_vertices()[i.local.next(e_i)],
        );
        let t_f = r.world_tangent(f);
        for w in [f, r.local.next(f)] {
            let p = r.world_vertices()[w];
            // Where e_I crosses the side plane through W (the line through W along n_f).
            let (g0, g1) = (t_f.dot(i0 - p), t_f.dot(i1 - p));
            if g0 * g1 > 0.0 || g0 == g1 {
                continue;
            }
            let cross = i0 + (i1 - i0) * (g0 / (g0 - g1));
            let s = i.edge_coordinate(e_i, p);
            if r.edge_distance(f, cross) <= 0.0
                && i.edge_distance(e_i, p) <= 0.0
                && s >= -eps_s
                && s <= len_i + eps_s
            {
                out.push(VeCandidate {
                    vertex_collider: ir,
                    vertex: w as u32,
                    edge_collider: ii,
                    edge: e_i as u32,
                });
            }
        }
    }
    out.len() - start
}

/// Crossing corners with no vertex inside (§9.5b): when the pair overlaps by more than the clip
/// margin, the reference face's clip pairs ([`clip_pairs`]) replace the vertex scan in `out[mark..]`.
/// Returns whether they did.
pub fn clip_crossing_corners(
    a: (u32, &Collider),
    b: (u32, &Collider),
    eps_s: f64,
    delta_c: f64,
    mark: usize,
    out: &mut Vec<VeCandidate>,
) -> bool {
    let Some(face) = sat_face(a.1, b.1) else {
        return false;
    };
    if !(face.admissible && face.depth > CLIP_MARGIN * delta_c) {
        return false;
    }
    let scanned = out.len();
    if clip_pairs(a, b, &face, eps_s, out) > 0 {
        replace_scanned(out, mark, scanned);
        return true;
    }
    false
}

/// Drops from `out[mark..scanned]` (a pair's vertex scan) every candidate whose vertex has a clip
/// pair in `out[scanned..]`, keeping the order: one candidate per vertex, the clip pair (a vertex
/// the scan proposes with no vertex inside is within `δ_c` outside a line; its clip pair holds it
/// along the separating axis).
fn replace_scanned(out: &mut Vec<VeCandidate>, mark: usize, scanned: usize) {
    let mut keep = mark;
    for i in mark..out.len() {
        let c = out[i];
        let clipped = i < scanned
            && out[scanned..]
                .iter()
                .any(|k| (k.vertex_collider, k.vertex) == (c.vertex_collider, c.vertex));
        if !clipped {
            out[keep] = c;
            keep += 1;
        }
    }
    out.truncate(keep);
}

#[cfg(test)]
mod tests {
    use super::super::test_rect as rect;
    use super::*;
    use crate::geom::{ConvexPolygon, Pose};

    /// A diamond whose lowest corner went through a thin shelf (no vertex of either inside the
    /// other): the shelf's top is the reference face, the depth is the corner's depth below it,
    /// and the one clip pair is that corner against the top.
    #[test]
    fn crossed_corner_clips_to_the_corner_on_the_reference_face() {
        let h = 0.02;
        let shelf = Collider::new(0, false, rect(-0.1, -0.001, 0.1, 0.0), &Pose::default());
        let diamond = ConvexPolygon::new(vec![
            Vec2::new(0.0, -h),
            Vec2::new(h, 0.0),
            Vec2::new(0.0, h),
            Vec2::new(-h, 0.0),
        ])
        .unwrap();
        let d = Collider::new(1, true, diamond, &Pose::new(0.0, h - 0.0015, 0.0));
        let f = sat_face(&shelf, &d).unwrap();
        assert!((f.depth - 0.0015).abs() < 1e-12, "{f:?}");
        assert!(f.reference_is_first && f.face == 2 && f.admissible, "{f:?}");
        assert!((f.axis - Vec2::new(0.0, -1.0)).length() < 1e-12);
        let mut out = Vec::new();
        assert_eq!(clip_pairs((0, &shelf), (1, &d), &f, 1e-4, &mut out), 1);
        let corner = VeCandidate {
            vertex_collider: 1,
            vertex: 0,
            edge_collider: 0,
            edge: 2,
        };
        assert_eq!(out, vec![corner]);
    }

    /// Box2D's clip point at a side plane as a VE pair: a box overlapping the top-right corner
    /// of a slab by 0.1 m below its top and 0.5 m inside its right side. Reference: the slab's
    /// top (depth 0.1); incident: the box's bottom. The box's bottom-left vertex is behind the
    /// top inside its range; its bottom-right one is outside the range, and the bottom edge
    /// crosses the side plane `x = 1` at `P = (1, −0.1)`, behind the top: the pair (slab corner
    /// `(1, 0)`, box bottom), depth 0.1 = `t·(−n_I·n_f)` with `t` = 0.1.
    #[test]
    fn side_plane_crossing_gives_the_reference_corner_against_the_incident_edge() {
        let slab = Collider::new(0, false, rect(-1.0, -1.0, 1.0, 0.0), &Pose::default());
        let b = Collider::new(1, true, rect(0.5, -0.1, 1.5, 0.9), &Pose::default());
        let f = sat_face(&slab, &b).unwrap();
        assert!((f.depth - 0.1).abs() < 1e-12 && f.reference_is_first && f.face == 2);
        assert_eq!(incident_edge(&b, slab.world_normals()[2]), Some(0));
        let mut out = Vec::new();
        clip_pairs((0, &slab), (1, &b), &f, 1e-4, &mut out);
        let v = |vc, v, ec, e| VeCandidate {
            vertex_collider: vc,
            vertex: v,
            edge_collider: ec,
            edge: e,
        };
        assert_eq!(out, vec![v(1, 0, 0, 2), v(0, 2, 1, 0)]);
        let depth = -b.edge_distance(0, slab.world_vertices()[2]);
        assert!((depth - 0.1).abs() < 1e-12);
    }

    /// Apart: no face.
    #[test]
    fn separated_pairs_have_no_reference_face() {
        let a = Collider::new(0, false, rect(0.0, 0.0, 1.0, 1.0), &Pose::default());
        let b = Collider::new(1, true, rect(1.5, 0.0, 2.5, 1.0), &Pose::default());
        assert_eq!(sat_face(&a, &b), None);
    }
}
