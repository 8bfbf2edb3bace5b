//! Two-level collision detection (§9): a global proximity stage every `N_g` ticks (AABBs with
//! sort-and-sweep, then GJK distance) and a local stage every tick for proximate pairs
//! (closest-feature tracking, signed distances, VE candidates).
//!
//! - [`gjk_distance`] (`gjk.rs`): GJK distance with hill-climbing support and warm start (§9.2);
//! - [`BroadPhase`] (`broad/`): inflated AABBs, sort-and-sweep, GJK → proximity set (§9.1);
//! - [`FeatureTracker`] (`tracker.rs`): Lin–Canny closest features per pair (§9.3);
//! - [`LocalStage`] (`local.rs`): one tracker per proximate pair, VE candidates (§9.4–9.5);
//! - [`sat_face`], [`clip_pairs`] (`clip.rs`): the reference face of an overlapping pair and its
//!   clip contacts (Box2D's polygon clipping as vertex–edge pairs, crossing corners);
//! - [`mark_seams`] (`seam.rs`): the internal edges of multi-piece bodies, never contact normals;
//! - [`swept_put_back`] (`toi.rs`): the swept test (time of impact) for bodies too fast for one
//!   sample, and the speed limits the world guarantees ([`speed_limit`], [`allowed_depth`]).
//!
//! Per tick (§0.5 steps 3–4), after [`Collider::update`] for every collider:
//!
//! ```text
//! if k % N_g == 0 { broad.update(&colliders, &mut pairs) }           // proximity set
//! local.update(&colliders, &pairs, DEFAULT_DELTA_C, &mut candidates) // sorted VE candidates
//! ```

mod broad;
mod candidates;
mod clip;
mod collider;
mod gjk;
mod local;
mod overlap;
mod queries;
mod reuse;
mod seam;
mod toi;
mod tracker;

pub use broad::{required_delta_prox, BroadPhase, BroadStats, DEFAULT_DELTA_PROX};
pub use candidates::corner_facing_edge;
pub use clip::{admissible_axis, clip_pairs, incident_edge, sat_face, SatFace, CLIP_MARGIN};
pub use collider::Collider;
pub use gjk::{
    gjk_distance, support_hill_climb, GjkCache, GjkOutput, GJK_EPS_ABS, GJK_EPS_REL,
    GJK_MAX_ITERATIONS,
};
pub use local::{LocalStage, PairState, DEFAULT_DELTA_C, DEFAULT_EPS_S, NEAR_PARALLEL_ANGLE};
pub use overlap::{max_overlap, max_overlap_of_states, Overlap};
pub use queries::{nearest_line, sat_axis, sat_depth};
pub use seam::{mark_seams, seam_mask, seam_reach, SEAM_ANGLE, SEAM_DISTANCE, SEAM_MAX_EDGES};
pub use toi::{
    allowed_depth, radius as polygon_radius, speed_limit, swept_put_back,
    thickness as body_thickness, SweepScratch, SweptShape, TOI_MAX_SAMPLES,
};
pub use tracker::{
    ClosestFeatures, Feature, FeatureTracker, TrackStatus, TrackerStats, PARALLEL_TOL, VORONOI_TOL,
};

/// A vertex–edge candidate produced by the local stage (§9.5): vertex `vertex` of collider
/// `vertex_collider` against edge `edge` of collider `edge_collider`.
///
/// Ordering is lexicographic on `(vertex_collider, vertex, edge_collider, edge)`; candidates are sorted
/// before use so that everything downstream is deterministic.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct VeCandidate {
    /// Collider that owns the vertex (the "A" side).
    pub vertex_collider: u32,
    /// Vertex index in that collider.
    pub vertex: u32,
    /// Collider that owns the edge (the "B" side).
    pub edge_collider: u32,
    /// Edge index in that collider (edge `i` runs from vertex `i` to `i+1`).
    pub edge: u32,
}

/// An axis-aligned rectangle from corner `(x0, y0)` to corner `(x1, y1)` (m), for the tests.
#[cfg(test)]
fn test_rect(x0: f64, y0: f64, x1: f64, y1: f64) -> crate::geom::ConvexPolygon {
    crate::geom::ConvexPolygon::new(vec![
        crate::geom::Vec2::new(x0, y0),
        crate::geom::Vec2::new(x1, y0),
        crate::geom::Vec2::new(x1, y1),
        crate::geom::Vec2::new(x0, y1),
    ])
    .unwrap()
}
