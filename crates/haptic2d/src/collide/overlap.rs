//! The true overlap of a world (issue 35): the largest separating-axis depth over its pairs.
//!
//! The contact records measure each penetrating vertex against one edge of the other polygon, so
//! where corners cross, or edges cross with no vertex inside, the records can be shallow while the
//! polygons share a large area (`stack-5-polygons-interpenetrate.toml`: 272 mm² shared, 1.7 mm
//! reported). The separating-axis depth ([`sat_depth`](super::sat_depth)) is the least translation that separates
//! a pair, seams left out, so it is what a report of "how far bodies sink into each other" must
//! give. Costs `O(n_a·n_b)` per pair whose boxes overlap: for reports (the CLI's summary, CSV and
//! MCAP), not the hot path.

use super::clip::sat_depth_above;
use super::{Collider, PairState, TrackStatus, GJK_EPS_ABS};

/// The largest overlap of a set of pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overlap {
    /// Separating-axis depth (m), 0 if no pair overlaps.
    pub depth: f64,
    /// The pair's colliders `(a, b)` (meaningless when `depth` is 0).
    pub pair: (u32, u32),
}

/// The largest [`sat_depth`](super::sat_depth) over `pairs` (collider indices; pairs naming a missing collider,
/// or two colliders of one body, are skipped), checking only pairs whose bounding boxes overlap.
pub fn max_overlap(colliders: &[Collider], pairs: &[(u32, u32)]) -> Overlap {
    let mut best = Overlap::default();
    for &pair in pairs {
        if let Some(o) = deeper(colliders, pair, best.depth) {
            best = o;
        }
    }
    best
}

/// The overlap of `pair` when it is deeper than `floor` (m): `None` for a missing collider, two
/// colliders of one body, boxes apart, or a depth at most `floor` ([`sat_depth_above`]).
fn deeper(colliders: &[Collider], (ia, ib): (u32, u32), floor: f64) -> Option<Overlap> {
    let (a, b) = (colliders.get(ia as usize)?, colliders.get(ib as usize)?);
    if a.body == b.body || !a.aabb.overlaps(&b.aabb) {
        return None;
    }
    sat_depth_above(a, b, floor).map(|depth| Overlap {
        depth,
        pair: (ia, ib),
    })
}

/// [`max_overlap`] over the local stage's pairs that may overlap: those its tracker reports
/// penetrating, or apart by no more than GJK's `ε_abs` (round-off). A pair certified apart
/// farther than that has no overlap, so this gives the same result at a fraction of the cost on
/// a pile (most pairs are apart). A skipped pair keeps its last (certified) state.
pub fn max_overlap_of_states(colliders: &[Collider], states: &[PairState]) -> Overlap {
    let mut best = Overlap::default();
    for st in states {
        let f = &st.features;
        if f.status == TrackStatus::Separated && f.distance > GJK_EPS_ABS {
            continue;
        }
        if let Some(o) = deeper(colliders, st.pair, best.depth) {
            best = o;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collide::sat_depth;
    use crate::geom::{ConvexPolygon, Pose};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Boxes and triangles, many of them crossing, at seeded random poses in a 10 cm square.
    fn crowd(seed: u64, n: usize) -> Vec<Collider> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|i| {
                let shape = if i % 3 == 0 {
                    ConvexPolygon::new(vec![
                        crate::geom::Vec2::new(0.0, 0.0),
                        crate::geom::Vec2::new(0.03, 0.0),
                        crate::geom::Vec2::new(0.01, 0.02),
                    ])
                } else {
                    ConvexPolygon::rectangle(rng.random_range(0.01..0.05), 0.02)
                };
                let pose = Pose::new(
                    rng.random_range(0.0..0.1),
                    rng.random_range(0.0..0.1),
                    rng.random_range(-3.0..3.0),
                );
                Collider::new(i, true, shape.unwrap(), &pose)
            })
            .collect()
    }

    /// The brute force: every pair's full separating-axis depth (boxes overlapping, two bodies),
    /// the first largest kept.
    fn brute_force(c: &[Collider], pairs: &[(u32, u32)]) -> Overlap {
        let mut want = Overlap::default();
        for &(a, b) in pairs {
            let (ca, cb) = (&c[a as usize], &c[b as usize]);
            if ca.body == cb.body || !ca.aabb.overlaps(&cb.aabb) {
                continue;
            }
            let d = sat_depth(ca, cb);
            if d > want.depth {
                want = Overlap {
                    depth: d,
                    pair: (a, b),
                };
            }
        }
        want
    }

    #[test]
    fn sat_depth_above_gives_the_sat_depth_exactly_when_it_exceeds_the_floor() {
        let c = crowd(7, 40);
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let mut above = 0;
        for a in &c {
            for b in &c {
                if a.body == b.body {
                    continue;
                }
                let d = sat_depth(a, b);
                let floor = if rng.random_bool(0.5) {
                    0.0
                } else {
                    rng.random_range(0.0..0.02)
                };
                let got = sat_depth_above(a, b, floor);
                if d > floor {
                    above += 1;
                    assert_eq!(got.map(f64::to_bits), Some(d.to_bits()), "floor {floor}");
                } else {
                    assert_eq!(got, None, "depth {d} at floor {floor}");
                }
            }
        }
        assert!(
            above > 50,
            "the crowd must cross: {above} pairs above their floor"
        );
    }

    #[test]
    fn max_overlap_with_pruning_picks_the_same_pair_and_depth_as_every_sat_depth() {
        for seed in 0..20 {
            let c = crowd(seed, 30);
            let pairs: Vec<(u32, u32)> = (0..30u32)
                .flat_map(|a| (a + 1..30).map(move |b| (a, b)))
                .collect();
            let want = brute_force(&c, &pairs);
            assert!(want.depth > 0.0, "seed {seed}: nothing crosses");
            assert_eq!(max_overlap(&c, &pairs), want, "seed {seed}");
        }
    }

    #[test]
    fn max_overlap_with_pruning_agrees_on_a_landing_pile_with_seamed_walls() {
        // The container's walls are seamed slabs: their seam axes are never a reason to stop.
        let mut w = crate::scene::builtin("pile:60", None)
            .unwrap()
            .unwrap()
            .world;
        let n = w.colliders.len() as u32;
        let pairs: Vec<(u32, u32)> = (0..n)
            .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
            .collect();
        assert!(w.colliders.iter().any(|c| c.seams != 0), "walls with seams");
        let mut crossing = 0;
        for step in 0..600 {
            w.step();
            if step % 20 != 0 {
                continue;
            }
            let want = brute_force(&w.colliders, &pairs);
            crossing += usize::from(want.depth > 0.0);
            assert_eq!(max_overlap(&w.colliders, &pairs), want, "step {step}");
        }
        assert!(
            crossing > 20,
            "the pile must be in contact: {crossing} samples"
        );
    }

    #[test]
    fn a_seam_axis_with_a_shallow_overlap_does_not_stop_the_search() {
        // A floor in two slabs (their shared edge at x = 0 is a seam) and a box 2 mm into the left
        // slab across that seam, 15 mm below the top: the shallow axes are the seam's and the
        // box's left face, both out through the seam, so the depth is the top face's 15 mm.
        // The pieces of one body are in the body frame (here the world's).
        let slab = |x0: f64| {
            let v = |x: f64, y: f64| crate::geom::Vec2::new(x, y);
            let shape = ConvexPolygon::new(vec![
                v(x0, -0.05),
                v(x0 + 0.1, -0.05),
                v(x0 + 0.1, 0.0),
                v(x0, 0.0),
            ]);
            Collider::new(0, false, shape.unwrap(), &Pose::IDENTITY)
        };
        let mut c = vec![slab(-0.1), slab(0.0)];
        crate::collide::mark_seams(&mut c);
        assert!(
            c[0].seams != 0 && c[1].seams != 0,
            "the shared edge is a seam"
        );
        let shape = ConvexPolygon::rectangle(0.02, 0.02).unwrap();
        let boxed = Collider::new(1, true, shape, &Pose::new(0.008, -0.005, 0.0));
        let d = sat_depth(&boxed, &c[0]);
        assert!((d - 0.015).abs() < 1e-12, "depth {d}");
        assert_eq!(sat_depth_above(&boxed, &c[0], 0.005), Some(d));
        assert_eq!(
            sat_depth_above(&c[0], &boxed, 0.005),
            Some(sat_depth(&c[0], &boxed))
        );
        assert_eq!(sat_depth_above(&boxed, &c[0], 0.015), None);
    }
}
