//! Closest-feature tracking for a pair of convex polygons (Lin & Canny 1991, in 2-D; §9.3).
//!
//! # Features and Voronoi regions
//!
//! The features of a CCW polygon are its vertices `V_i` and edges `E_i = [V_i, V_{i+1}]` (unit
//! tangent `u_i`, outward normal `n_i = (u_i,y, −u_i,x)`, length `L_i`). Their external Voronoi
//! regions are bounded by lines, each labelled with the feature across it:
//!
//! ```text
//! Vor(E_i):  (p − V_i)·u_i ≥ 0        [else → V_i]
//!            (p − V_{i+1})·u_i ≤ 0    [else → V_{i+1}]
//!            (p − V_i)·n_i ≥ 0        [else → interior]
//! Vor(V_i):  (p − V_i)·u_i ≤ 0        [else → E_i]
//!            (p − V_i)·u_{i−1} ≥ 0    [else → E_{i−1}]
//! ```
//!
//! A feature pair `(f_A, f_B)` with closest points `p_A ∈ f_A`, `p_B ∈ f_B` is the closest pair iff
//! `p_B ∈ Vor(f_A)` and `p_A ∈ Vor(f_B)`. (This is also a separation certificate: the regions are
//! normal cones/slabs, so `p_B − p_A` then separates A from B.)
//!
//! # The walk
//!
//! Starting from the cached pair (first time: the features spanned by GJK's final simplex), each
//! iteration computes the closest points of the two features and, if `p_B` violates a boundary of
//! `Vor(f_A)` by more than [`VORONOI_TOL`], replaces `f_A` by the neighbour across the most violated
//! boundary (then the same for `p_A` and `Vor(f_B)`). Every step either lowers the distance between
//! the features or keeps it and changes the feature dimension, so under coherent motion the cached
//! pair is already (or one step from) the answer: O(1) per sample.
//!
//! Closest points between features:
//!
//! - vertex–vertex: the two points;
//! - vertex–edge: the vertex and its projection clamped to the edge, `E0 + clamp(s, 0, L)·u`;
//! - edge–edge, parallel (`|u_A·u_B| > 1 − 1e-9`) with overlapping ranges: the midpoints of the
//!   overlap interval (`parallel = true`);
//! - edge–edge otherwise: the closest pair is realised at an endpoint, so the edge owning that
//!   endpoint is replaced by the endpoint (one iteration) and the walk continues.
//!
//! A violated "interior" boundary of `Vor(E_i)` means `p_B` lies behind the line of `E_i`. If `p_B`
//! (a point of B) is inside A, the polygons overlap: the tracker reports
//! [`TrackStatus::Penetrating`] (the local stage then works with vertex signed distances, §9.4).
//! Otherwise `p_B` is in front of another edge of A and the walk jumps to the edge with the largest
//! signed distance (O(n), rare). If the walk has not settled after `2·(n_A + n_B)` iterations it
//! falls back to GJK (warm-started), which always gives the right answer; overlapping polygons
//! have no closest features, so that is how an overlap is found when no interior test fires.
//! While a pair stays penetrating, each update starts with the warm-started GJK instead (its
//! triangle simplex re-confirms the overlap in O(1)), and the walk resumes from GJK's features as
//! soon as the pair separates.

use super::gjk::{gjk_distance, GjkCache, GjkOutput};
use super::Collider;
use crate::geom::Vec2;

/// Edges are parallel when `|u_A·u_B| > 1 − PARALLEL_TOL` (§9.3).
pub const PARALLEL_TOL: f64 = 1e-9;
/// A Voronoi boundary counts as violated only by more than this (m); guards against cycling on
/// round-off at exact feature transitions (flat contact, touching corners).
pub const VORONOI_TOL: f64 = 1e-12;

/// A feature of a convex polygon: vertex `i`, or edge `i` from vertex `i` to vertex `i+1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Feature {
    /// Vertex index.
    Vertex(u32),
    /// Edge index (edge `i` runs from vertex `i` to vertex `i+1 mod n`).
    Edge(u32),
}

/// Whether a tracked pair is apart or overlapping.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackStatus {
    /// Disjoint (or touching): the features and points are the closest ones.
    Separated,
    /// Overlapping: features and points are the last ones visited (not closest); use vertex signed
    /// distances (§9.4).
    Penetrating,
}

/// Result of one tracker update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestFeatures {
    /// Separated or penetrating.
    pub status: TrackStatus,
    /// Closest feature of A.
    pub feature_a: Feature,
    /// Closest feature of B.
    pub feature_b: Feature,
    /// Closest point on A (m, world).
    pub point_a: Vec2,
    /// Closest point on B (m, world).
    pub point_b: Vec2,
    /// Distance `|p_A − p_B|` (m); 0 when penetrating.
    pub distance: f64,
    /// True for a parallel edge–edge pair (points are the overlap interval's midpoints).
    pub parallel: bool,
    /// Feature-walk iterations used by this update (0 if GJK answered directly).
    pub iterations: u32,
    /// True if this update was answered by GJK (first call, or fallback).
    pub used_gjk: bool,
}

/// Work counters of a tracker (accumulated over updates).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TrackerStats {
    /// Number of updates.
    pub updates: u64,
    /// Total feature-walk iterations.
    pub iterations: u64,
    /// Number of updates that started with GJK (first update, after `reset`, or while the pair was
    /// penetrating at the previous update).
    pub gjk_starts: u64,
    /// Number of GJK fallbacks after a walk that did not settle.
    pub gjk_fallbacks: u64,
}

/// Closest-feature cache for one pair of polygons (plus the GJK cache used to initialise it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FeatureTracker {
    feature_a: Option<Feature>,
    feature_b: Option<Feature>,
    penetrating: bool,
    gjk: GjkCache,
    /// Work counters.
    pub stats: TrackerStats,
}

/// What the closest-point step of the walk produced.
enum Step {
    /// Closest points `(p_A, p_B, parallel)` of the current features.
    Points(Vec2, Vec2, bool),
    /// Non-parallel edge–edge: replace A's edge by this vertex.
    ReduceA(Feature),
    /// Non-parallel edge–edge: replace B's edge by this vertex.
    ReduceB(Feature),
}

/// The neighbour across a violated Voronoi boundary.
enum Across {
    Feature(Feature),
    Interior,
}

#[inline]
fn next(c: &Collider, i: usize) -> usize {
    c.local.next(i)
}

#[inline]
fn prev(c: &Collider, i: usize) -> usize {
    c.local.prev(i)
}

#[inline]
fn edge_len(c: &Collider, e: usize) -> f64 {
    c.local.lengths()[e]
}

/// `E0 + clamp(s, 0, L)·u`: the point of edge `e` closest to `p`.
#[inline]
fn project_on_edge(c: &Collider, e: usize, p: Vec2) -> Vec2 {
    let s = c.edge_coordinate(e, p).clamp(0.0, edge_len(c, e));
    c.world_vertices()[e] + c.world_tangent(e) * s
}

fn feature_valid(c: &Collider, f: Feature) -> bool {
    match f {
        Feature::Vertex(i) | Feature::Edge(i) => (i as usize) < c.len(),
    }
}

/// Closest points of two features, or the reduction of a non-parallel edge–edge pair.
fn closest_points(a: &Collider, fa: Feature, b: &Collider, fb: Feature) -> Step {
    match (fa, fb) {
        (Feature::Vertex(i), Feature::Vertex(j)) => Step::Points(
            a.world_vertices()[i as usize],
            b.world_vertices()[j as usize],
            false,
        ),
        (Feature::Vertex(i), Feature::Edge(j)) => {
            let pa = a.world_vertices()[i as usize];
            Step::Points(pa, project_on_edge(b, j as usize, pa), false)
        }
        (Feature::Edge(i), Feature::Vertex(j)) => {
            let pb = b.world_vertices()[j as usize];
            Step::Points(project_on_edge(a, i as usize, pb), pb, false)
        }
        (Feature::Edge(i), Feature::Edge(j)) => {
            let (ea, eb) = (i as usize, j as usize);
            let a0 = a.world_vertices()[ea];
            let a1 = a.world_vertices()[next(a, ea)];
            let b0 = b.world_vertices()[eb];
            let b1 = b.world_vertices()[next(b, eb)];
            if a.world_tangent(ea).dot(b.world_tangent(eb)).abs() > 1.0 - PARALLEL_TOL {
                // Parallel: overlap of A's edge with B's edge in B's edge coordinate.
                let s0 = b.edge_coordinate(eb, a0);
                let s1 = b.edge_coordinate(eb, a1);
                let lo = s0.min(s1).max(0.0);
                let hi = s0.max(s1).min(edge_len(b, eb));
                if lo <= hi {
                    let pb = b0 + b.world_tangent(eb) * (0.5 * (lo + hi));
                    return Step::Points(project_on_edge(a, ea, pb), pb, true);
                }
            }
            // The closest pair is realised at one of the four endpoints.
            let cands = [
                (a0.distance_squared(project_on_edge(b, eb, a0)), 0usize),
                (a1.distance_squared(project_on_edge(b, eb, a1)), 1),
                (b0.distance_squared(project_on_edge(a, ea, b0)), 2),
                (b1.distance_squared(project_on_edge(a, ea, b1)), 3),
            ];
            let mut best = cands[0];
            for c in &cands[1..] {
                if c.0 < best.0 {
                    best = *c;
                }
            }
            match best.1 {
                0 => Step::ReduceA(Feature::Vertex(ea as u32)),
                1 => Step::ReduceA(Feature::Vertex(next(a, ea) as u32)),
                2 => Step::ReduceB(Feature::Vertex(eb as u32)),
                _ => Step::ReduceB(Feature::Vertex(next(b, eb) as u32)),
            }
        }
    }
}

/// The most violated boundary of `Vor(f)` (polygon `c`) for point `p`, if violated by more than
/// [`VORONOI_TOL`].
fn most_violated(c: &Collider, f: Feature, p: Vec2) -> Option<Across> {
    let mut worst = VORONOI_TOL;
    let mut across = None;
    match f {
        Feature::Vertex(i) => {
            let i = i as usize;
            let r = p - c.world_vertices()[i];
            // (p − V_i)·u_i ≤ 0, else → E_i.
            let out_next = r.dot(c.world_tangent(i));
            if out_next > worst {
                worst = out_next;
                across = Some(Across::Feature(Feature::Edge(i as u32)));
            }
            // (p − V_i)·u_{i−1} ≥ 0, else → E_{i−1}.
            let ip = prev(c, i);
            let out_prev = -r.dot(c.world_tangent(ip));
            if out_prev > worst {
                across = Some(Across::Feature(Feature::Edge(ip as u32)));
            }
        }
        Feature::Edge(i) => {
            let i = i as usize;
            let r = p - c.world_vertices()[i];
            let s = r.dot(c.world_tangent(i));
            // (p − V_i)·u_i ≥ 0, else → V_i.
            if -s > worst {
                worst = -s;
                across = Some(Across::Feature(Feature::Vertex(i as u32)));
            }
            // (p − V_{i+1})·u_i ≤ 0, else → V_{i+1}.
            let beyond = s - edge_len(c, i);
            if beyond > worst {
                worst = beyond;
                across = Some(Across::Feature(Feature::Vertex(next(c, i) as u32)));
            }
            // (p − V_i)·n_i ≥ 0, else → interior.
            let depth = -r.dot(c.world_normals()[i]);
            if depth > worst {
                across = Some(Across::Interior);
            }
        }
    }
    across
}

/// What one test of the walk found: the feature stays, it moved, or the point is inside the
/// polygon (deeper than `VORONOI_TOL` below every edge).
enum Walk {
    Stay,
    Moved,
    Inside,
}

/// Tests the other polygon's closest point `p` against the Voronoi region of feature `f` of `c`:
/// moves `f` across the most violated boundary (to the nearest edge when `p` is in the interior)
/// or leaves it where it is; `f` is untouched when `p` is inside `c`.
#[inline(always)]
fn walk_voronoi(c: &Collider, f: &mut Feature, p: Vec2) -> Walk {
    match most_violated(c, *f, p) {
        Some(Across::Feature(g)) => {
            *f = g;
            Walk::Moved
        }
        Some(Across::Interior) => {
            let (e, d) = max_edge_distance(c, p);
            if d < -VORONOI_TOL {
                return Walk::Inside;
            }
            *f = Feature::Edge(e as u32);
            Walk::Moved
        }
        None => Walk::Stay,
    }
}

/// The edge of `c` with the largest signed distance of `p`, and that distance (m).
fn max_edge_distance(c: &Collider, p: Vec2) -> (usize, f64) {
    let mut best = (0, f64::NEG_INFINITY);
    for e in 0..c.len() {
        let d = c.edge_distance(e, p);
        if d > best.1 {
            best = (e, d);
        }
    }
    best
}

/// The feature of polygon `c` spanned by the simplex vertex indices `idx` with weights `w`.
fn feature_from_simplex(c: &Collider, idx: &[u32], w: &[f64]) -> Feature {
    // Distinct indices, with the weight of each.
    let mut first = (idx[0], w[0]);
    let mut second: Option<(u32, f64)> = None;
    for k in 1..idx.len() {
        if idx[k] == first.0 {
            first.1 += w[k];
        } else if let Some(s) = second.as_mut() {
            if s.0 == idx[k] {
                s.1 += w[k];
            }
        } else {
            second = Some((idx[k], w[k]));
        }
    }
    match second {
        None => Feature::Vertex(first.0),
        Some(s) => {
            let (i, j) = (first.0 as usize, s.0 as usize);
            if next(c, i) == j {
                Feature::Edge(i as u32)
            } else if next(c, j) == i {
                Feature::Edge(j as u32)
            } else if first.1 >= s.1 {
                Feature::Vertex(first.0)
            } else {
                Feature::Vertex(s.0)
            }
        }
    }
}

impl FeatureTracker {
    /// True if the last update found the pair overlapping.
    #[inline]
    pub fn is_penetrating(&self) -> bool {
        self.penetrating
    }

    /// Re-confirms an overlap found by the caller (a vertex of one polygon strictly inside the other)
    /// without running GJK: the result of [`FeatureTracker::update`] for a pair that is still
    /// penetrating, with the last features and no closest points (they do not exist).
    pub fn confirm_penetration(&mut self, at: Vec2) -> ClosestFeatures {
        self.stats.updates += 1;
        self.penetrating = true;
        ClosestFeatures {
            status: TrackStatus::Penetrating,
            feature_a: self.feature_a.unwrap_or(Feature::Vertex(0)),
            feature_b: self.feature_b.unwrap_or(Feature::Vertex(0)),
            point_a: at,
            point_b: at,
            distance: 0.0,
            parallel: false,
            iterations: 0,
            used_gjk: false,
        }
    }

    /// A tracker with no cached features (the first update runs GJK).
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets the cached features (the next update runs GJK); keeps the counters.
    pub fn reset(&mut self) {
        self.feature_a = None;
        self.feature_b = None;
        self.penetrating = false;
        self.gjk.reset();
    }

    /// The cached feature pair, if any.
    pub fn features(&self) -> Option<(Feature, Feature)> {
        Some((self.feature_a?, self.feature_b?))
    }

    /// The GJK warm-start cache of this pair.
    pub fn gjk_cache(&self) -> &GjkCache {
        &self.gjk
    }

    /// Runs GJK (warm-started) and takes the features spanned by its simplex.
    fn start_from_gjk(&mut self, a: &Collider, b: &Collider, iterations: u32) -> ClosestFeatures {
        let g: GjkOutput = gjk_distance(a.world_vertices(), b.world_vertices(), &mut self.gjk);
        let n = g.simplex_count.max(1);
        let fa = feature_from_simplex(a, &g.index_a[..n], &g.weights[..n]);
        let fb = feature_from_simplex(b, &g.index_b[..n], &g.weights[..n]);
        self.feature_a = Some(fa);
        self.feature_b = Some(fb);
        self.penetrating = g.overlap;
        ClosestFeatures {
            status: if g.overlap {
                TrackStatus::Penetrating
            } else {
                TrackStatus::Separated
            },
            feature_a: fa,
            feature_b: fb,
            point_a: g.point_a,
            point_b: g.point_b,
            distance: g.distance,
            parallel: !g.overlap && matches!((fa, fb), (Feature::Edge(_), Feature::Edge(_))),
            iterations,
            used_gjk: true,
        }
    }

    /// Updates the closest features of polygons `a` and `b` (world features must be current).
    /// O(1) iterations under coherent motion; no allocation.
    pub fn update(&mut self, a: &Collider, b: &Collider) -> ClosestFeatures {
        self.stats.updates += 1;
        let cached = match (self.feature_a, self.feature_b) {
            (Some(fa), Some(fb)) if feature_valid(a, fa) && feature_valid(b, fb) => Some((fa, fb)),
            _ => None,
        };
        let (mut fa, mut fb) = match cached {
            Some(f) if !self.penetrating => f,
            _ => {
                // First time, or still overlapping at the last update: a warm-started GJK decides
                // (O(1) under coherence); if apart, the walk starts from its simplex features.
                self.stats.gjk_starts += 1;
                let r = self.start_from_gjk(a, b, 0);
                if r.status == TrackStatus::Penetrating {
                    return r;
                }
                (r.feature_a, r.feature_b)
            }
        };

        let max_iterations = 2 * (a.len() + b.len()) as u32;
        let mut it = 0u32;
        while it < max_iterations {
            it += 1;
            let (pa, pb, parallel) = match closest_points(a, fa, b, fb) {
                Step::Points(pa, pb, par) => (pa, pb, par),
                Step::ReduceA(f) => {
                    fa = f;
                    continue;
                }
                Step::ReduceB(f) => {
                    fb = f;
                    continue;
                }
            };
            // p_B against Vor(f_A), then p_A against Vor(f_B).
            let walk = match walk_voronoi(a, &mut fa, pb) {
                Walk::Stay => walk_voronoi(b, &mut fb, pa),
                moved_or_inside => moved_or_inside,
            };
            match walk {
                Walk::Moved => continue,
                Walk::Inside => return self.finish_penetrating(fa, fb, pa, pb, it),
                Walk::Stay => {}
            }
            self.feature_a = Some(fa);
            self.feature_b = Some(fb);
            self.penetrating = false;
            self.stats.iterations += it as u64;
            return ClosestFeatures {
                status: TrackStatus::Separated,
                feature_a: fa,
                feature_b: fb,
                point_a: pa,
                point_b: pb,
                distance: (pa - pb).length(),
                parallel,
                iterations: it,
                used_gjk: false,
            };
        }
        // The walk did not settle (degenerate geometry or overlap without a certificate): GJK decides.
        self.stats.iterations += it as u64;
        self.stats.gjk_fallbacks += 1;
        self.start_from_gjk(a, b, it)
    }

    fn finish_penetrating(
        &mut self,
        fa: Feature,
        fb: Feature,
        pa: Vec2,
        pb: Vec2,
        it: u32,
    ) -> ClosestFeatures {
        self.feature_a = Some(fa);
        self.feature_b = Some(fb);
        self.penetrating = true;
        self.stats.iterations += it as u64;
        ClosestFeatures {
            status: TrackStatus::Penetrating,
            feature_a: fa,
            feature_b: fb,
            point_a: pa,
            point_b: pb,
            distance: 0.0,
            parallel: false,
            iterations: it,
            used_gjk: false,
        }
    }
}
