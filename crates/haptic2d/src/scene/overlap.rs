//! Bodies that start overlapping: the separating-axis depth between every pair of convex pieces of
//! two different bodies (at least one dynamic) in a world's initial state.
//!
//! For convex polygons `A` and `B`, with `n_i` the outward unit normal of edge `i` of `A` through its
//! vertex `a_i`, the signed distance of `B` from that edge line is
//!
//! ```text
//! s_i = min_j n_i · (b_j − a_i)        (the deepest vertex of B below the line; > 0: B is outside)
//! ```
//!
//! By the separating-axis theorem the polygons are disjoint iff some edge normal of `A` or of `B`
//! separates them, i.e. `max_i s_i > 0` over the edges of both. Otherwise the smallest translation
//! that separates them has length `depth = −max_i s_i` (over both polygons' edges), which is the
//! depth reported here. A pair touching along an edge has depth 0.
//!
//! Pairs are found by sweep and prune on the pieces' bounding boxes (sorted by `min.x`), so a scene
//! with thousands of separated bodies costs `O(n log n)`; the search stops after
//! [`MAX_REPORTED`] overlapping pairs so that a pathological pile cannot take quadratic time.

use crate::geom::Vec2;
use crate::world::World;

/// At most this many overlapping body pairs are collected (the report says when there are more).
pub const MAX_REPORTED: usize = 1000;

/// Two bodies whose pieces overlap at the start.
#[derive(Clone, Debug, PartialEq)]
pub struct Overlap {
    /// Names of the two bodies (in body order).
    pub bodies: (String, String),
    /// Separating-axis depth of their deepest overlapping piece pair (m), > `min_depth`.
    pub depth: f64,
}

impl std::fmt::Display for Overlap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "bodies \"{}\" and \"{}\" overlap by {:.3} mm",
            self.bodies.0,
            self.bodies.1,
            self.depth * 1e3
        )
    }
}

/// Separating-axis depth of two convex polygons given by their counter-clockwise world vertices and
/// outward unit normals (m): `−max s_i` over both polygons' edges (see the module doc). Positive:
/// they overlap by that much; zero or negative: they touch or are apart (by `−depth` along the best
/// separating axis found, a lower bound of the distance).
pub fn sat_depth(va: &[Vec2], na: &[Vec2], vb: &[Vec2], nb: &[Vec2]) -> f64 {
    let mut best = f64::NEG_INFINITY;
    for (verts, normals, other) in [(va, na, vb), (vb, nb, va)] {
        for (a, n) in verts.iter().zip(normals) {
            let s = other
                .iter()
                .map(|b| n.dot(*b - *a))
                .fold(f64::INFINITY, f64::min);
            best = best.max(s);
            if best > 0.0 {
                return -best; // a separating axis: no need to look further
            }
        }
    }
    -best
}

/// Every pair of bodies of `world` (at least one dynamic) whose pieces overlap by more than
/// `min_depth` (m) in the current poses, deepest piece pair per body pair, deepest first; at most
/// [`MAX_REPORTED`] pairs. The second value is true when the search stopped at that cap.
pub fn overlaps(world: &World, min_depth: f64) -> (Vec<Overlap>, bool) {
    let cols = &world.colliders;
    let mut order: Vec<usize> = (0..cols.len()).collect();
    order.sort_by(|&i, &j| cols[i].aabb.min.x.total_cmp(&cols[j].aabb.min.x));
    // (body_a, body_b) → deepest depth, kept sorted at the end.
    let mut found: std::collections::BTreeMap<(usize, usize), f64> = Default::default();
    let mut capped = false;
    'sweep: for (k, &i) in order.iter().enumerate() {
        let ci = &cols[i];
        for &j in &order[k + 1..] {
            let cj = &cols[j];
            if cj.aabb.min.x > ci.aabb.max.x {
                break;
            }
            if ci.body == cj.body || !(ci.dynamic || cj.dynamic) || !ci.aabb.overlaps(&cj.aabb) {
                continue;
            }
            let d = sat_depth(
                ci.world_vertices(),
                ci.world_normals(),
                cj.world_vertices(),
                cj.world_normals(),
            );
            if d > min_depth {
                let key = (ci.body.min(cj.body), ci.body.max(cj.body));
                let e = found.entry(key).or_insert(d);
                *e = e.max(d);
                if found.len() >= MAX_REPORTED {
                    capped = true;
                    break 'sweep;
                }
            }
        }
    }
    // Deepest first; ties in body order (the map's order), so the report is deterministic.
    let mut list: Vec<Overlap> = found
        .into_iter()
        .map(|((a, b), depth)| Overlap {
            bodies: (world.bodies[a].name.clone(), world.bodies[b].name.clone()),
            depth,
        })
        .collect();
    list.sort_by(|x, y| y.depth.total_cmp(&x.depth));
    (list, capped)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(cx: f64, cy: f64, h: f64) -> (Vec<Vec2>, Vec<Vec2>) {
        let v = vec![
            Vec2::new(cx - h, cy - h),
            Vec2::new(cx + h, cy - h),
            Vec2::new(cx + h, cy + h),
            Vec2::new(cx - h, cy + h),
        ];
        let n = vec![
            Vec2::new(0.0, -1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(-1.0, 0.0),
        ];
        (v, n)
    }

    #[test]
    fn sat_depth_of_two_squares_is_the_smallest_overlap() {
        let (va, na) = square(0.0, 0.0, 0.5);
        // Overlap 0.2 in x and 0.9 in y: the separating translation is 0.2.
        let (vb, nb) = square(0.8, 0.1, 0.5);
        assert!((sat_depth(&va, &na, &vb, &nb) - 0.2).abs() < 1e-12);
        // Apart by 0.3 in x.
        let (vc, nc) = square(1.3, 0.0, 0.5);
        assert!(sat_depth(&va, &na, &vc, &nc) < 0.0);
        // Touching along an edge.
        let (vd, nd) = square(1.0, 0.0, 0.5);
        assert!(sat_depth(&va, &na, &vd, &nd).abs() < 1e-12);
    }
}
