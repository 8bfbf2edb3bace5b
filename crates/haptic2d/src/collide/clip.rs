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

/// [`deepest_behind`] of the edge line through `e0` with outward normal `n` (a polygon's edge
/// `e`: `e0` its start, so `d = n·(v − e0)` is `edge_distance(e, v)`) over the vertices `q`,
/// where no vertex is behind it by more than both 0 and a floor (m); `None` as soon as one is
/// (then the overlap along `n` exceeds both, and the axis decides nothing in
/// [`sat_depth_above`]). `cut` is minus the larger of the floor and 0 ([`behind_cut`]): `d < cut`
/// is `d < 0 && −d > floor`. The same distances; the least is kept by `<` (no NaN can be the
/// least: it starts at `+∞` and a NaN distance compares false, as in `f64::min`; of `±0` either
/// may be kept, and the caller only compares it).
#[inline(always)]
fn deepest_behind_within(e0: Vec2, n: Vec2, q: &[Vec2], cut: f64) -> Option<f64> {
    let mut min_d = f64::INFINITY;
    for &v in q {
        let d = n.dot(v - e0);
        if d < cut {
            return None;
        }
        if d < min_d {
            min_d = d;
        }
    }
    Some(min_d)
}

/// The threshold of [`deepest_behind_within`] for `floor` (m): `d < behind_cut(floor)` exactly
/// when `d < 0 && −d > floor` (negation is exact, so `−d > floor` is `d < −floor`). A NaN floor
/// gives a NaN cut, which no distance is below, as no `−d` is above a NaN floor.
#[inline(always)]
fn behind_cut(floor: f64) -> f64 {
    -(if floor < 0.0 { 0.0 } else { floor })
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
///
/// The answer is `None` if *some* axis decides (separates the pair, or is admissible with an
/// overlap at most `floor`) and `sat_face`'s depth above `floor` otherwise, whichever axis is
/// tried first. A pile's pair without seams is almost always decided by one of `a`'s edges, so
/// those are tried here, in a loop that needs few registers, and the rest ([`sat_depth_rest`])
/// is a call.
pub fn sat_depth_above(a: &Collider, b: &Collider, floor: f64) -> Option<f64> {
    let cut = behind_cut(floor);
    let plain = a.seams == 0 && b.seams == 0;
    if plain && axes_decide(a, b, floor, cut, |_, _| true) {
        return None;
    }
    sat_depth_rest(a, b, floor, cut)
}

/// [`sat_depth_above`] past `a`'s edges for a pair without seams (`b`'s edges), or the whole
/// search for a pair with seams (where only admissible axes bound the depth), then `sat_face`.
#[inline(never)]
fn sat_depth_rest(a: &Collider, b: &Collider, floor: f64, cut: f64) -> Option<f64> {
    let decided = if a.seams == 0 && b.seams == 0 {
        axes_decide(b, a, floor, cut, |_, _| true)
    } else {
        // Along an edge normal `n` of `a`, `a` separates by moving along `−n`; of `b`, along `n`.
        axes_decide(a, b, floor, cut, |e, n| {
            !a.is_seam(e) && admissible_axis(a, b, -n)
        }) || axes_decide(b, a, floor, cut, |e, n| {
            !b.is_seam(e) && admissible_axis(a, b, n)
        })
    };
    if decided {
        return None;
    }
    sat_face(a, b).map(|f| f.depth).filter(|&d| d > floor)
}

/// Whether an edge normal of `p` decides [`sat_depth_above`]: `q` lies wholly outside the edge's
/// line (the axis separates them), or its overlap along it is at most `floor` (m) and
/// `admissible(e, n)` (edge `e`, normal `n`) holds. `cut` is [`behind_cut`]`(floor)`.
#[inline(always)]
fn axes_decide(
    p: &Collider,
    q: &Collider,
    floor: f64,
    cut: f64,
    admissible: impl Fn(usize, Vec2) -> bool,
) -> bool {
    let q = q.world_vertices();
    let edges = p.world_vertices().iter().zip(p.world_normals());
    for (e, (&e0, &n)) in edges.enumerate() {
        let Some(min_d) = deepest_behind_within(e0, n, q, cut) else {
            continue;
        };
        if min_d >= 0.0 || (-min_d <= floor && admissible(e, n)) {
            return true;
        }
    }
    false
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

    /// `sat_depth_above` is the long way, `sat_face`'s depth when it exceeds the floor, bit for
    /// bit, at every floor where an exit could tip: each axis's own overlap (the floor then ties
    /// with the axis), the floats either side of it, the depth itself, ±0, a negative floor, ∞
    /// and NaN. Seeded random pairs of boxes, triangles and hexagons crossing or resting nearly
    /// flat (a pile's contacts), and a box in a seamed floor, 300 seeds.
    #[test]
    fn sat_depth_above_is_the_reference_faces_depth_above_every_tie_floor() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
        let hexagon = |r: f64| {
            let v = (0..6).map(|i| {
                let t = std::f64::consts::PI / 3.0 * i as f64;
                Vec2::new(r * t.cos(), r * t.sin())
            });
            ConvexPolygon::new(v.collect()).unwrap()
        };
        let shape = |rng: &mut rand_chacha::ChaCha8Rng| match rng.random_range(0..3) {
            0 => ConvexPolygon::rectangle(rng.random_range(0.01..0.05), 0.02).unwrap(),
            1 => ConvexPolygon::new(vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(0.03, 0.0),
                Vec2::new(0.01, 0.02),
            ])
            .unwrap(),
            _ => hexagon(rng.random_range(0.005..0.02)),
        };
        let mut pairs = Vec::new();
        for _ in 0..300 {
            let a = Collider::new(0, false, shape(&mut rng), &Pose::new(0.0, 0.0, 0.0));
            let b_shape = shape(&mut rng);
            let pose = if rng.random_bool(0.5) {
                // Crossing anywhere.
                let (x, y) = (rng.random_range(-0.04..0.04), rng.random_range(-0.04..0.04));
                Pose::new(x, y, rng.random_range(-3.0..3.0))
            } else {
                // Resting on `a`'s top, sunk by up to 0.2 mm, turned by round-off or a little.
                let low = b_shape
                    .vertices()
                    .iter()
                    .fold(f64::INFINITY, |m, v| m.min(v.y));
                let h = a.aabb.max.y - low - rng.random_range(0.0..2e-4);
                let turn = rng.random_range(-1e-6..1e-6) * rng.random_range(0.0..1e3);
                Pose::new(rng.random_range(-0.01..0.01), h, turn)
            };
            pairs.push((a, Collider::new(1, true, b_shape, &pose)));
        }
        // A box 2 mm into the left slab of a seamed floor (`overlap.rs`'s seam test).
        let slab = |x0: f64| {
            let r = super::super::test_rect(x0, -0.05, x0 + 0.1, 0.0);
            Collider::new(0, false, r, &Pose::IDENTITY)
        };
        let mut floor_pieces = vec![slab(-0.1), slab(0.0)];
        crate::collide::mark_seams(&mut floor_pieces);
        let square = ConvexPolygon::rectangle(0.02, 0.02).unwrap();
        let boxed = Collider::new(1, true, square, &Pose::new(0.008, -0.005, 0.0));
        pairs.push((floor_pieces[0].clone(), boxed));
        let (mut above, mut ties, mut checked) = (0, 0, 0);
        for (a, b) in pairs.iter().flat_map(|(a, b)| [(a, b), (b, a)]) {
            let want = |floor: f64| sat_face(a, b).map(|f| f.depth).filter(|&d| d > floor);
            let mut floors = vec![0.0, -0.0, -1e-3, f64::INFINITY, f64::NAN];
            let axes = (0..a.len()).map(|e| deepest_behind(a, e, b));
            for min_d in axes.chain((0..b.len()).map(|e| deepest_behind(b, e, a))) {
                floors.extend([-min_d, (-min_d).next_up(), (-min_d).next_down()]);
            }
            if let Some(d) = want(f64::NEG_INFINITY) {
                floors.extend([d, d.next_up(), d.next_down()]);
            }
            for floor in floors {
                let got = sat_depth_above(a, b, floor);
                assert_eq!(
                    got.map(f64::to_bits),
                    want(floor).map(f64::to_bits),
                    "{floor}"
                );
                above += usize::from(got.is_some());
                ties += usize::from(want(f64::NEG_INFINITY) == Some(floor));
                checked += 1;
            }
        }
        assert!(
            above > 500 && ties > 200,
            "{above} above, {ties} ties of {checked}"
        );
    }

    /// Apart: no face.
    #[test]
    fn separated_pairs_have_no_reference_face() {
        let a = Collider::new(0, false, rect(0.0, 0.0, 1.0, 1.0), &Pose::default());
        let b = Collider::new(1, true, rect(1.5, 0.0, 2.5, 1.0), &Pose::default());
        assert_eq!(sat_face(&a, &b), None);
    }
}
