//! The VE candidates of one tracked pair (§9.4–9.5; the rules are listed in
//! [`local`](super::local)'s module docs): the rule chosen by the tracker's status, one file per
//! query as parry keeps them.
//!
//! - [`closest`]: a separated pair within `δ_c`, from its closest features (§9.5), with the
//!   near-parallel faces;
//! - [`edge_edge`]: the two ends of a parallel edge–edge overlap;
//! - [`vertex_scan`]: every vertex of one polygon inside or within `δ_c` of the other (§9.4), with
//!   the corner-on-corner rule.
//!
//! Crossing corners (§9.5b) are `clip.rs`'s.

mod closest;
mod edge_edge;
mod vertex_scan;

pub use vertex_scan::corner_facing_edge;

use super::clip::clip_crossing_corners;
use super::gjk::GJK_EPS_ABS;
use super::reuse::Slack;
use super::tracker::{ClosestFeatures, Feature, TrackStatus};
use super::{Collider, VeCandidate};

/// Tolerances shared by the candidate rules.
pub(super) struct Ctx {
    pub(super) delta_c: f64,
    pub(super) eps_s: f64,
    pub(super) cos_parallel: f64,
}

/// One polygon of a pair: its collider index and its collider.
#[derive(Clone, Copy)]
pub(super) struct Side<'a> {
    pub(super) id: u32,
    pub(super) c: &'a Collider,
}

/// The (up to two) edges incident to a feature: the edge itself, or a vertex's outgoing and
/// incoming edges.
fn incident_edges(c: &Collider, f: Feature) -> [Option<usize>; 2] {
    match f {
        Feature::Edge(e) => [Some(e as usize), None],
        Feature::Vertex(v) => [Some(v as usize), Some(c.local.prev(v as usize))],
    }
}

impl Ctx {
    /// Pushes `(vertex v of pv, edge e of pe)` if `s` is in the edge range and `d ≤ δ_c`. Returns
    /// whether it was pushed.
    pub(super) fn push_if_valid(
        &self,
        pv: Side,
        v: usize,
        pe: Side,
        e: usize,
        out: &mut Vec<VeCandidate>,
    ) -> bool {
        let p = pv.c.world_vertices()[v];
        let s = pe.c.edge_coordinate(e, p);
        let l = pe.c.local.lengths()[e];
        if pe.c.is_seam(e)
            || s < -self.eps_s
            || s > l + self.eps_s
            || pe.c.edge_distance(e, p) > self.delta_c
        {
            return false;
        }
        out.push(VeCandidate {
            vertex_collider: pv.id,
            vertex: v as u32,
            edge_collider: pe.id,
            edge: e as u32,
        });
        true
    }

    /// The VE candidates of a tracked pair `a`, `b` with closest features `f` (§9.4–9.5), pushed
    /// to `out`; `under`: the pair can have a vertex across a seam (`Collider::across`). Returns
    /// whether they are the vertex scan's.
    pub(super) fn candidates(
        &self,
        a: Side,
        b: Side,
        f: &ClosestFeatures,
        under: bool,
        out: &mut Vec<VeCandidate>,
    ) -> bool {
        match f.status {
            TrackStatus::Penetrating => {
                let mark = out.len();
                let inside_a = self.vertices_against(a, b, out, &mut Slack::new());
                let inside_b = self.vertices_against(b, a, out, &mut Slack::new());
                // Crossing corners with no vertex inside (§9.5b).
                let (pa, pb) = ((a.id, a.c), (b.id, b.c));
                let none_inside = inside_a.is_none() && inside_b.is_none();
                !(none_inside && clip_crossing_corners(pa, pb, self.eps_s, self.delta_c, mark, out))
            }
            // Closer than GJK's ε_abs, "apart" is not a certificate: two equal boxes stacked
            // corner on corner overlap with every vertex of each exactly on a side line of the
            // other (signed distance 0 or ±1e-19 m), so no vertex is strictly inside, GJK stops
            // at |v| ≤ ε_abs and the walk certifies a vertex–side-edge pair at ~1e-20 m, which
            // would propose one side-edge candidate and let the boxes sink through each other.
            // The vertex scan (§9.4) proposes every touching vertex instead (at distance 0 it
            // is exact for touching pairs as well).
            TrackStatus::Separated if f.distance <= GJK_EPS_ABS => {
                self.vertices_of_both(a, b, out);
                true
            }
            TrackStatus::Separated if f.distance <= self.delta_c => {
                self.closest_feature_candidates(a, b, f, out);
                if under {
                    self.vertices_of_both(a, b, out);
                }
                false
            }
            TrackStatus::Separated if under => {
                // Only vertices across a seam within its reach can be proposed here.
                self.vertices_of_both(a, b, out);
                true
            }
            TrackStatus::Separated => false,
        }
    }

    /// The vertex scan of both polygons against each other (§9.4).
    fn vertices_of_both(&self, a: Side, b: Side, out: &mut Vec<VeCandidate>) {
        self.vertices_against(a, b, out, &mut Slack::new());
        self.vertices_against(b, a, out, &mut Slack::new());
    }
}
