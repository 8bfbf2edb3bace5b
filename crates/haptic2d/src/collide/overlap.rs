//! The true overlap of a world (issue 35): the largest separating-axis depth over its pairs.
//!
//! The contact records measure each penetrating vertex against one edge of the other polygon, so
//! where corners cross, or edges cross with no vertex inside, the records can be shallow while the
//! polygons share a large area (`stack-5-polygons-interpenetrate.toml`: 272 mm² shared, 1.7 mm
//! reported). The separating-axis depth ([`sat_depth`]) is the least translation that separates
//! a pair, seams left out, so it is what a report of "how far bodies sink into each other" must
//! give. Costs `O(n_a·n_b)` per pair whose boxes overlap: for reports (the CLI's summary, CSV and
//! MCAP), not the hot path.

use super::{sat_depth, Collider, PairState, TrackStatus, GJK_EPS_ABS};

/// The largest overlap of a set of pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overlap {
    /// Separating-axis depth (m), 0 if no pair overlaps.
    pub depth: f64,
    /// The pair's colliders `(a, b)` (meaningless when `depth` is 0).
    pub pair: (u32, u32),
}

/// The largest [`sat_depth`] over `pairs` (collider indices; pairs naming a missing collider,
/// or two colliders of one body, are skipped), checking only pairs whose bounding boxes overlap.
pub fn max_overlap(colliders: &[Collider], pairs: &[(u32, u32)]) -> Overlap {
    let mut best = Overlap::default();
    for &(ia, ib) in pairs {
        let (Some(a), Some(b)) = (colliders.get(ia as usize), colliders.get(ib as usize)) else {
            continue;
        };
        if a.body == b.body || !a.aabb.overlaps(&b.aabb) {
            continue;
        }
        let d = sat_depth(a, b);
        if d > best.depth {
            best = Overlap {
                depth: d,
                pair: (ia, ib),
            };
        }
    }
    best
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
        let o = max_overlap(colliders, std::slice::from_ref(&st.pair));
        if o.depth > best.depth {
            best = o;
        }
    }
    best
}
