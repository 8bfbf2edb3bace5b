//! Seams: the internal edges of a body made of several convex pieces (issue 35).
//!
//! A wall built from pieces (a floor slab and a wall slab meeting at a joint) has edges that lie
//! inside the body: the wall slab's bottom edge is covered by the floor slab's top edge. Such an
//! edge is no surface of the body, so it is never a contact normal: a vertex 35 mm inside the
//! wall slab and 0.1 mm above the floor slab is nearest to the wall slab's *bottom* line, and
//! measured against it would be pushed along the joint (down, into the floor) instead of out of
//! the wall, and slide through the wall at the joint (`corner-seam-tunnel.toml`: a 3.6 kg polygon
//! at 4 m/s ended 8.65 m below the container). Box2D's chain shapes solve the same problem with
//! ghost vertices (only the chain's outer side is a surface).
//!
//! An edge `e` of piece `P` is a **seam** when the edges of the body's other pieces that lie on
//! its line with the opposite normal (antiparallel within [`SEAM_ANGLE`], the line within
//! [`SEAM_DISTANCE`]) cover all of it, up to `SEAM_DISTANCE` at either end. A partly covered
//! edge (the floor slab's top edge, covered only under the walls) stays a surface: its exposed
//! part is one. The vertex scan (`local.rs`), [`nearest_line`](super::nearest_line),
//! [`sat_depth`](super::sat_depth), the swept test's depth and the crossed-edge rule skip seams.
//!
//! **Across a seam.** The partly covered edge's covered part is no surface either: a vertex in
//! the floor slab just *under* the wall slab is at the body's concave corner, whose surfaces are
//! the floor's exposed top and the wall slab's face. Measured against the floor alone it was
//! pushed up, into the wall slab, and nothing held it from sliding further under the wall (seeds
//! 11574, 10010, 11996 of the long passivity suite hid 31.0, 12.1 and 10.6 mm beyond their
//! allowance). So a seam that faces a partly covered edge ([`seam_reach`],
//! [`Collider::across`]) lets the vertex scan hold a vertex across it, up to the covering
//! pieces' extent beyond it (the *reach*) and inside the piece's other lines, on the piece's
//! nearest surface line, whose edge range runs on across the seam by the reach
//! ([`Collider::edge_range`]). The floor's top keeps holding it from below: two records, one per
//! face of the concave corner, as a chain shape's two segments would give. Between two pieces
//! whose facing edges are both seams nothing changes (each piece's own surfaces hold a vertex
//! inside it). (Skipping the covered part as a contact normal instead, the rule of whole seams,
//! left the vertex to the floor's far faces or to nothing: the long suite then hid up to 56 mm in
//! 28 scenes, and with the covered axis left out of the separating-axis test a scene created
//! 6.6 J.)

use super::Collider;
use crate::geom::{ConvexPolygon, Vec2};

/// Largest angle (rad, from antiparallel) between two edges that join at a seam.
pub const SEAM_ANGLE: f64 = 1e-6;
/// Largest distance (m) between the lines of two edges that join at a seam, and the gap left
/// uncovered at either end of a seam.
pub const SEAM_DISTANCE: f64 = 1e-7;

/// Edges beyond this index are never marked as seams (the scene files allow 128 vertices).
pub const SEAM_MAX_EDGES: usize = 128;

/// The seam mask of `piece` among `others` (the other pieces of the same body, all in the body
/// frame): bit `e` set when edge `e` is a seam (module docs).
pub fn seam_mask<'a>(
    piece: &ConvexPolygon,
    others: impl Iterator<Item = &'a ConvexPolygon> + Clone,
) -> u128 {
    let cos = SEAM_ANGLE.cos();
    let (v, n, t, len) = (
        piece.vertices(),
        piece.normals(),
        piece.tangents(),
        piece.lengths(),
    );
    let mut mask = 0u128;
    let mut cover: Vec<(f64, f64)> = Vec::new();
    for e in 0..piece.len().min(SEAM_MAX_EDGES) {
        cover.clear();
        for q in others.clone() {
            for f in 0..q.len() {
                let (f0, f1) = (q.vertices()[f], q.vertices()[q.next(f)]);
                let on_line = n[e].dot(f0 - v[e]).abs() <= SEAM_DISTANCE
                    && n[e].dot(f1 - v[e]).abs() <= SEAM_DISTANCE;
                if n[e].dot(q.normals()[f]) > -cos || !on_line {
                    continue;
                }
                let (s0, s1) = (t[e].dot(f0 - v[e]), t[e].dot(f1 - v[e]));
                cover.push((s0.min(s1), s0.max(s1)));
            }
        }
        cover.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Covered from 0 up to `reach`.
        let mut reach = 0.0f64;
        for &(lo, hi) in &cover {
            if lo > reach + SEAM_DISTANCE {
                break;
            }
            reach = reach.max(hi);
        }
        if !cover.is_empty() && reach >= len[e] - SEAM_DISTANCE && cover[0].0 <= SEAM_DISTANCE {
            mask |= 1u128 << e;
        }
    }
    mask
}

/// Marks the seams of every collider (`Collider::seams`) from the other pieces of its body.
pub fn mark_seams(colliders: &mut [Collider]) {
    let masks: Vec<u128> = (0..colliders.len())
        .map(|i| {
            let body = colliders[i].body;
            let others = colliders
                .iter()
                .enumerate()
                .filter(move |&(j, c)| j != i && c.body == body)
                .map(|(_, c)| &c.local);
            seam_mask(&colliders[i].local, others)
        })
        .collect();
    for (c, m) in colliders.iter_mut().zip(masks) {
        c.seams = m;
    }
    // The reach of each seam that faces a partly covered edge (`Collider::across`).
    let reaches: Vec<Vec<(u32, f64)>> = (0..colliders.len())
        .map(|i| seam_reach(colliders, i))
        .collect();
    for (c, r) in colliders.iter_mut().zip(reaches) {
        c.across = r.iter().fold(0u128, |m, &(e, _)| m | 1u128 << e);
        c.reach = r;
    }
}

/// The seams of collider `i` that face a partly covered edge of another piece of its body (an
/// edge on the seam's line, antiparallel, that is no seam itself), each with its reach: the
/// least extent behind the seam's line of the pieces with such an edge (m). Between two pieces
/// whose facing edges are both seams (equal boxes stacked into one body) there is none: each
/// piece's own surfaces hold a vertex inside it.
pub fn seam_reach(colliders: &[Collider], i: usize) -> Vec<(u32, f64)> {
    let c = &colliders[i];
    let cos = SEAM_ANGLE.cos();
    let (v, n) = (c.local.vertices(), c.local.normals());
    let mut out = Vec::new();
    for e in (0..c.len().min(SEAM_MAX_EDGES)).filter(|&e| c.is_seam(e)) {
        let mut reach = f64::INFINITY;
        for (j, q) in colliders.iter().enumerate() {
            if j == i || q.body != c.body {
                continue;
            }
            let ql = &q.local;
            for f in 0..ql.len() {
                let (f0, f1) = (ql.vertices()[f], ql.vertices()[ql.next(f)]);
                let on_line = n[e].dot(f0 - v[e]).abs() <= SEAM_DISTANCE
                    && n[e].dot(f1 - v[e]).abs() <= SEAM_DISTANCE;
                if !on_line || n[e].dot(ql.normals()[f]) > -cos || q.is_seam(f) {
                    continue;
                }
                // The piece's extent beyond the seam's line (along the seam's outward normal).
                let extent = ql
                    .vertices()
                    .iter()
                    .map(|&w| n[e].dot(w - v[e]))
                    .fold(0.0f64, f64::max);
                reach = reach.min(extent);
            }
        }
        if reach.is_finite() && reach > SEAM_DISTANCE {
            out.push((e as u32, reach));
        }
    }
    out
}

/// Whether moving a body relative to `c` along `u` has a component out through a seam of `c`
/// (`n_s·u > 0` for a seam `s`, beyond round-off).
#[inline]
pub(crate) fn through_seam(c: &Collider, u: Vec2) -> bool {
    c.seams != 0
        && c.world_normals()
            .iter()
            .enumerate()
            .any(|(e, n)| c.is_seam(e) && n.dot(u) > 1e-12)
}

#[cfg(test)]
mod tests {
    use super::super::test_rect as rect;
    use super::*;
    use crate::geom::{Pose, Vec2};

    /// The container of `corner-seam-tunnel.toml` (floor, left wall, right wall, ceiling; edges
    /// run from vertex i to i + 1: bottom, right, top, left), its seams marked.
    fn container() -> Vec<Collider> {
        let pieces = [
            rect(-0.1, -0.1, 0.5, 0.0),
            rect(-0.1, 0.0, 0.0, 0.4),
            rect(0.4, 0.0, 0.5, 0.4),
            rect(-0.1, 0.4, 0.5, 0.5),
        ];
        let mut cols: Vec<Collider> = pieces
            .iter()
            .map(|p| Collider::new(0, false, p.clone(), &Pose::default()))
            .collect();
        mark_seams(&mut cols);
        cols
    }

    /// The container of `corner-seam-tunnel.toml`: each wall slab's edge on the floor (or
    /// ceiling) slab is a seam; the floor's top edge, covered only at its ends, is a surface.
    #[test]
    fn container_joints_are_seams_and_exposed_faces_are_not() {
        let cols = container();
        // Edges run from vertex i to i + 1: bottom, right, top, left.
        assert_eq!(cols[0].seams, 0, "the floor's top edge is partly exposed");
        assert_eq!(
            cols[3].seams, 0,
            "the ceiling's bottom edge is partly exposed"
        );
        assert_eq!(cols[1].seams, 0b0101, "left wall: bottom and top are seams");
        assert_eq!(
            cols[2].seams, 0b0101,
            "right wall: bottom and top are seams"
        );
        assert!(cols[2].is_seam(0) && !cols[2].is_seam(3));
    }

    /// Each wall slab's bottom seam faces the floor's partly covered top: it reaches the floor's
    /// 0.1 m beyond, and the wall's faces run on by that much below it. The top seams likewise
    /// face the ceiling. The floor and ceiling have no seam, so nothing to reach across.
    #[test]
    fn wall_seams_on_a_partly_covered_floor_reach_across_it() {
        let cols = container();
        assert_eq!((cols[0].across, cols[3].across), (0, 0));
        for c in &cols[1..3] {
            assert_eq!(c.across, 0b0101);
            assert!((c.reach(0) - 0.1).abs() < 1e-12 && (c.reach(2) - 0.1).abs() < 1e-12);
        }
        // Left wall's right face (edge 1, from (0, 0) up to (0, 0.4)).
        let (r0, r1) = cols[1].edge_range(1);
        assert!((r0 + 0.1).abs() < 1e-12 && (r1 - 0.5).abs() < 1e-12);
        // (−0.005, −0.001): in the floor under the left wall, 5 mm from its face.
        let p = Vec2::new(-0.005, -0.001);
        let d = cols[1].across_seam(p).expect("across the bottom seam");
        assert!((d + 0.005).abs() < 1e-12);
        assert_eq!(
            cols[1].across_seam(Vec2::new(-0.005, -0.2)),
            None,
            "below the floor"
        );
        assert_eq!(
            cols[1].across_seam(Vec2::new(0.005, -0.001)),
            None,
            "beside the wall"
        );
    }

    /// Two equal boxes joined into one body: each one's facing edge is a seam of the other, so
    /// neither reaches across (each box's own surfaces hold a vertex inside it).
    #[test]
    fn mutual_seams_reach_nothing() {
        let mut cols = vec![
            Collider::new(0, false, rect(0.0, 0.0, 1.0, 1.0), &Pose::default()),
            Collider::new(0, false, rect(0.0, 1.0, 1.0, 2.0), &Pose::default()),
        ];
        mark_seams(&mut cols);
        assert_eq!((cols[0].seams, cols[1].seams), (0b0100, 0b0001));
        assert_eq!((cols[0].across, cols[1].across), (0, 0));
    }

    /// Pieces of different bodies, or touching only along part of an edge, make no seam.
    #[test]
    fn other_bodies_and_partial_cover_make_no_seam() {
        let mut cols = vec![
            Collider::new(0, false, rect(0.0, 0.0, 1.0, 1.0), &Pose::default()),
            Collider::new(1, false, rect(0.0, 1.0, 1.0, 2.0), &Pose::default()),
            Collider::new(2, false, rect(0.0, 0.0, 1.0, 1.0), &Pose::default()),
            Collider::new(2, false, rect(0.0, 1.0, 0.5, 2.0), &Pose::default()),
        ];
        mark_seams(&mut cols);
        assert_eq!(cols[0].seams, 0);
        assert_eq!(cols[1].seams, 0);
        assert_eq!(cols[2].seams, 0, "top edge only half covered");
        assert_eq!(
            cols[3].seams, 0b0001,
            "bottom edge fully on the lower piece"
        );
    }
}
