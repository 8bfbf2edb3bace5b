//! The depth invariant of [`ContactSet::step`]: the check used where a record is created or handed
//! over, the overlap bound (issue 35), and the debug-build assertion run after every step.

use super::ContactSet;
use crate::collide::{nearest_line, sat_depth, Collider, VeCandidate};

/// Round-off allowance (m) of the debug-build assertion, on distances of a few metres at most.
#[cfg(any(debug_assertions, test))]
const TOL: f64 = 1e-9;

impl ContactSet {
    /// Debug builds: every record satisfies the depth invariant of [`ContactSet::step`], and is no
    /// deeper than its pair's separating-axis depth plus `δ_c` ([`invariant_checks`]).
    #[cfg(debug_assertions)]
    pub(super) fn assert_depth_invariant(&self, colliders: &[Collider]) {
        for e in self.entries.iter().filter(|e| e.is_contact()) {
            let [near, bounded] = invariant_checks(e.key, colliders, self.delta_c);
            if near && bounded {
                continue;
            }
            let ca = &colliders[e.key.vertex_collider as usize];
            let cb = &colliders[e.key.edge_collider as usize];
            let p = ca.world_vertices()[e.key.vertex as usize];
            let d_e = cb.edge_distance(e.key.edge as usize, p);
            let (j, max_d) = nearest_line(cb, p);
            debug_assert!(
                near,
                "VE record {:?}: d = {d_e:e} m on its edge, but edge {j}'s line is at {max_d:e} m \
                 (more than δ_c = {} m nearer): its stored energy exceeds the vertex's real depth",
                e.key, self.delta_c
            );
            debug_assert!(
                bounded,
                "VE record {:?}: depth {:e} m exceeds the pair's separating-axis depth {:e} m + δ_c",
                e.key,
                -d_e,
                sat_depth(ca, cb)
            );
        }
    }
}

/// The two checks of [`ContactSet::assert_depth_invariant`] on the record `key` at the current
/// poses (distances in m), with the round-off allowance [`TOL`]: first, `d_e ≥ max_j d_j − δ_c −
/// TOL` or the overlap bound ([`overlap_ok`] with `δ_c + TOL`); second, `−d_e ≤ depth_SAT + δ_c +
/// TOL` or the vertex is across a seam of the edge collider. A vertex across a seam of `cb` (in
/// the piece under it, `Collider::across_seam`) is outside `cb`: the pair's SAT depth does not
/// see the piece that holds it.
///
/// The SAT depth costs `O((n_a + n_b)²)`, so it is computed only where a cheaper test has not
/// already decided: the overlap bound of the first check only where the nearest-line test fails,
/// and the second check's SAT depth only for a record deeper than `δ_c + TOL`. That shortcut
/// gives the full test's answer: `sat_depth ≥ 0` (never NaN: its minima start at `+∞` and
/// `f64::min` passes over NaN), and IEEE rounding is monotone, so `(depth_SAT + δ_c) + TOL ≥
/// (0 + δ_c) + TOL`. A landing pile:100 run in the dev profile spent
/// two thirds of its instructions on two eager SAT depths a record a step (docs/PERFORMANCE.md,
/// session 29).
#[cfg(any(debug_assertions, test))]
fn invariant_checks(key: VeCandidate, colliders: &[Collider], delta_c: f64) -> [bool; 2] {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let p = ca.world_vertices()[key.vertex as usize];
    let d_e = cb.edge_distance(key.edge as usize, p);
    let near =
        d_e >= nearest_line(cb, p).1 - delta_c - TOL || overlap_ok(key, colliders, delta_c + TOL);
    let bounded = -d_e <= delta_c + TOL
        || -d_e <= sat_depth(ca, cb) + delta_c + TOL
        || cb.across_seam(p).is_some();
    [near, bounded]
}

/// The depth invariant of [`ContactSet::step`] for the pair `key` at the current poses:
/// `d_e ≥ max_j d_j − δ_c` over the edge collider's surface lines `j`, or the overlap bound
/// ([`overlap_ok`]).
#[inline]
pub(super) fn depth_ok(
    key: VeCandidate,
    colliders: &[Collider],
    delta_c: f64,
    _cos_parallel: f64,
) -> bool {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let p = ca.world_vertices()[key.vertex as usize];
    cb.edge_distance(key.edge as usize, p) >= nearest_line(cb, p).1 - delta_c
        || overlap_ok(key, colliders, delta_c)
}

/// The overlap bound of the depth invariant ([`ContactSet::step`], issue 35): the record is no
/// deeper than the pair's separating-axis depth plus `δ_c` (`−d_e ≤ depth_SAT + δ_c`, seams
/// left out, [`sat_depth`]). Where corners cross, the vertex's nearest line can be far shallower
/// than the pair's overlap (two polygons sharing 272 mm² with every vertex within 1.7 mm of a
/// line of the other); a record on the edge the vertex crossed keeps pushing the overlap out,
/// within the bound, instead of being handed over to the shallow line. (Issue 10's defect, a far
/// edge 23.5 mm deep for a vertex outside B, broke this bound too.) The SAT depth costs
/// `O((n_a + n_b)²)`, so this runs only where the nearest-line test has failed.
pub(super) fn overlap_ok(key: VeCandidate, colliders: &[Collider], delta_c: f64) -> bool {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let (v, e) = (key.vertex as usize, key.edge as usize);
    !cb.is_seam(e) && -cb.edge_distance(e, ca.world_vertices()[v]) <= sat_depth(ca, cb) + delta_c
}

#[cfg(test)]
mod tests {
    use super::{invariant_checks, overlap_ok, TOL};
    use crate::collide::DEFAULT_DELTA_C;
    use crate::collide::{mark_seams, nearest_line, sat_depth, Collider, VeCandidate};
    use crate::geom::{ConvexPolygon, Pose, Vec2};

    /// The assertion's two checks as written before session 29: every test evaluated.
    fn eager_checks(key: VeCandidate, colliders: &[Collider], delta_c: f64) -> [bool; 2] {
        let ca = &colliders[key.vertex_collider as usize];
        let cb = &colliders[key.edge_collider as usize];
        let p = ca.world_vertices()[key.vertex as usize];
        let d_e = cb.edge_distance(key.edge as usize, p);
        let (_, max_d) = nearest_line(cb, p);
        let overlap = overlap_ok(key, colliders, delta_c + TOL);
        let sat = sat_depth(ca, cb);
        [
            d_e >= max_d - delta_c - TOL || overlap,
            -d_e <= sat + delta_c + TOL || cb.across_seam(p).is_some(),
        ]
    }

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> ConvexPolygon {
        let v = |x, y| Vec2::new(x, y);
        ConvexPolygon::new(vec![v(x0, y0), v(x1, y0), v(x1, y1), v(x0, y1)]).unwrap()
    }

    /// A box and a triangle thrown at 5 000 seeded random poses into and around a seamed
    /// container (`corner-seam-tunnel.toml`'s four slabs of one body): on every vertex–edge key
    /// of a moving polygon against a slab and of a slab against a moving polygon, the lazy checks
    /// answer exactly as the eager ones; each check both holds and fails, and the shortcut (a
    /// record no deeper than `δ_c + TOL`) decides many records while the SAT depth bounds many
    /// deeper ones.
    #[test]
    fn lazy_invariant_checks_answer_as_the_eager_ones() {
        let triangle = ConvexPolygon::new(vec![
            Vec2::new(-0.06, -0.03),
            Vec2::new(0.05, -0.04),
            Vec2::new(0.0, 0.07),
        ])
        .unwrap();
        let pieces = [
            rect(-0.1, -0.1, 0.5, 0.0),
            rect(-0.1, 0.0, 0.0, 0.4),
            rect(0.4, 0.0, 0.5, 0.4),
            rect(-0.1, 0.4, 0.5, 0.5),
            rect(-0.05, -0.05, 0.05, 0.05),
            triangle,
        ];
        let mut cols: Vec<Collider> = pieces
            .iter()
            .enumerate()
            .map(|(i, p)| Collider::new(i.saturating_sub(3), i > 3, p.clone(), &Pose::default()))
            .collect();
        mark_seams(&mut cols);
        assert!(
            cols[..4].iter().any(|c| c.seams != 0),
            "the slabs have seams"
        );
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64)
        };
        // Answers of each check ([holds, fails]), records the shortcut decides, deep records the
        // SAT depth bounds.
        let (mut answers, mut shallow, mut deep_bounded) = ([[0usize; 2]; 2], 0usize, 0usize);
        for _ in 0..5_000 {
            for c in &mut cols[4..] {
                let pose = Pose::new(
                    0.7 * uniform() - 0.15,
                    0.7 * uniform() - 0.15,
                    7.0 * uniform(),
                );
                c.update(&pose);
            }
            for (a, b) in (0..6).flat_map(|a| (0..6).map(move |b| (a, b))) {
                if cols[a].body == cols[b].body {
                    continue;
                }
                for (v, e) in
                    (0..cols[a].len()).flat_map(|v| (0..cols[b].len()).map(move |e| (v, e)))
                {
                    let key = VeCandidate {
                        vertex_collider: a as u32,
                        vertex: v as u32,
                        edge_collider: b as u32,
                        edge: e as u32,
                    };
                    let lazy = invariant_checks(key, &cols, DEFAULT_DELTA_C);
                    assert_eq!(lazy, eager_checks(key, &cols, DEFAULT_DELTA_C), "{key:?}");
                    for (count, ok) in answers.iter_mut().zip(lazy) {
                        count[usize::from(!ok)] += 1;
                    }
                    let depth = -cols[b].edge_distance(e, cols[a].world_vertices()[v]);
                    if depth <= DEFAULT_DELTA_C + TOL {
                        shallow += 1;
                    } else if lazy[1] {
                        deep_bounded += 1;
                    }
                }
            }
        }
        assert!(
            answers.iter().flatten().all(|&n| n > 1000),
            "[holds, fails] of each check: {answers:?}"
        );
        assert!(
            shallow > 10_000 && deep_bounded > 1000,
            "{shallow} decided by the shortcut, {deep_bounded} deep records within the SAT bound"
        );
    }
}
