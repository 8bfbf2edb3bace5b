//! The global proximity stage (§9.1): inflated AABBs, sort-and-sweep on x or y, then GJK distance.
//!
//! # The algorithm
//!
//! Every `N_g` samples (`T_g = 20 ms` by default):
//!
//! 1. Each collider's world AABB is enlarged by `δ_prox/2` on every side, so two boxes overlap
//!    whenever the polygons are closer than `δ_prox` (a necessary condition).
//! 2. Sort-and-sweep along x or y, whichever meets fewer boxes (`axis.rs`; said here for x): the
//!    boxes are sorted by `(min.x, collider index)` (a total order, so the result does not depend
//!    on the sort algorithm) and each box is tested only against the boxes
//!    that start before it ends in x; y overlap is then checked directly, 64 boxes at a time into
//!    a bit mask (no branch per box: on a pile, which box of the run overlaps in y follows no
//!    pattern a branch predictor learns), and the marked pairs are tested in order. Pairs on the
//!    same body and pairs of two fixed colliders are skipped.
//! 3. Each surviving pair gets a warm-started GJK distance (§9.2; one [`GjkCache`] per pair, kept
//!    while the pair keeps overlapping in the AABB test). Pairs with distance `< δ_prox` form the
//!    proximity set, a sorted list of `(a, b)` collider indices with `a < b`.
//!
//! # The margin
//!
//! The proximity set must not miss a collision until the next global update. The distance of two
//! bodies decreases at most at `v_rel,max`; allowing one period for the update itself and one for
//! its result to be consumed (it may run on another thread, §0.5 step 3), a pair found farther than
//! `δ_prox` is still farther than `δ_c` — so still without VE candidates — for `2·T_g`:
//!
//! ```text
//! δ_prox ≥ 2·v_rel,max·T_g + δ_c      (1 m/s, 0.02 s, 0.002 m → 0.042 m)
//! ```
//!
//! The folder, one concern a file: this file the stage's types, its buffers and the whole update;
//! `axis.rs` the sweep's axis; `sweep.rs` the sort-and-sweep and the pair test (with reused
//! distances); `spread.rs` an update spread over the samples of a period; `publish.rs` the merge
//! or in-place patch that publishes an update; `skip.rs` the certificate that lets the world skip
//! an update that cannot change the set; `partial.rs` the partial update of the bodies that moved
//! past the margin.

mod axis;
mod partial;
mod publish;
mod skip;
mod spread;
mod sweep;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_axis;

use self::axis::{sweep_axis, Axis};
use super::gjk::{gjk_distance, GjkCache};
use super::Collider;
use crate::buffers::room;
use crate::geom::{Aabb, Vec2};

/// Default proximity distance `δ_prox` (m), §9.1: `2·(1 m/s)·(0.02 s) + 0.002 m`.
pub const DEFAULT_DELTA_PROX: f64 = 0.042;

/// The smallest proximity distance `δ_prox = 2·v_rel,max·T_g + δ_c` (m) that cannot miss a
/// collision between global updates (§9.1), for the largest relative speed of any two points
/// `v_rel_max` (m/s), the global period `t_g` (s) and the contact distance tolerance `delta_c` (m).
pub fn required_delta_prox(v_rel_max: f64, t_g: f64, delta_c: f64) -> f64 {
    2.0 * v_rel_max * t_g + delta_c
}

/// Work counters of the last [`BroadPhase::update`] (or published spread update).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BroadStats {
    /// Pairs whose inflated AABBs overlap (after the same-body / fixed–fixed filters).
    pub aabb_pairs: usize,
    /// Pairs found within `δ_prox` by GJK.
    pub proximate_pairs: usize,
    /// GJK iterations spent on all pairs.
    pub gjk_iterations: u64,
    /// Pairs whose side of `δ_prox` the bodies' motion could not have changed: GJK skipped, the
    /// last distance kept (`sweep.rs`).
    pub reused_distances: usize,
    /// The update tested exactly the last published update's pairs: its few new GJK distances
    /// were written into the published result in place instead of sorting and copying every
    /// pair again (a pile at rest, most updates).
    pub in_place: bool,
}

/// One box in the sweep: the inflated box's x and y ranges, the collider index and its body (the
/// y range here too, so that the sweep rejects boxes apart in y without reading anything else:
/// in a pile, every box of a column overlaps in x; the body too, so that the same-body and
/// fixed–fixed filters need no lookup either; 40 bytes with both). In a sweep along y
/// (`axis.rs`) the box's axes are exchanged: `min_x`, `max_x` are then its y range.
#[derive(Clone, Copy, Debug)]
struct SweepEntry {
    min_x: f64,
    max_x: f64,
    min_y: f64,
    max_y: f64,
    index: u32,
    /// `body << 1 | dynamic` of the collider's body.
    body: u32,
}

/// One AABB-overlapping pair of an update in progress: its warm-start cache and GJK distance (m),
/// and the sum of its bodies' odometers when that distance was computed (m; NaN = unknown).
#[derive(Clone, Copy, Debug)]
struct Tested {
    pair: (u32, u32),
    cache: GjkCache,
    distance: f64,
    odo_ref: f64,
}

impl SweepEntry {
    /// The entry of collider `i`, `c`, with box `bx` (m; the sweep's is inflated).
    fn of(i: usize, c: &Collider, bx: Aabb) -> Self {
        SweepEntry {
            min_x: bx.min.x,
            max_x: bx.max.x,
            min_y: bx.min.y,
            max_y: bx.max.y,
            index: i as u32,
            body: body_code(c),
        }
    }
}

/// The sweep's total order: by `min.x`, then by collider index.
fn sweep_order(p: &SweepEntry, q: &SweepEntry) -> std::cmp::Ordering {
    p.min_x.total_cmp(&q.min_x).then(p.index.cmp(&q.index))
}

/// Sorts `sweep` by [`sweep_order`]: an insertion sort, linear on the nearly sorted order of the
/// last update; past `8·n` moves it finishes with a full sort instead (the order is total, so
/// either gives the same result).
fn sort_sweep(sweep: &mut [SweepEntry]) {
    let budget = 8 * sweep.len();
    let mut moves = 0;
    for i in 1..sweep.len() {
        let mut j = i;
        while j > 0 && sweep_order(&sweep[j - 1], &sweep[j]).is_gt() {
            sweep.swap(j - 1, j);
            j -= 1;
            moves += 1;
        }
        if moves > budget {
            sweep.sort_unstable_by(sweep_order);
            return;
        }
    }
}

/// Kept between a reused distance's interval and `δ_prox` (m): GJK's tolerance and the
/// odometers' rounding are far below it.
const REUSE_GUARD: f64 = 1e-6;

/// The colliders as they were when an update began: world vertices (flat), and per collider its
/// vertex range, body and whether it is dynamic. An update spread over several samples works on
/// this copy, so its result is the proximity set of that one instant.
#[derive(Clone, Debug, Default)]
struct Snapshot {
    vertices: Vec<Vec2>,
    /// `(first vertex, vertex count)` per collider.
    colliders: Vec<(u32, u32)>,
    /// The odometer of each collider's body (m; NaN if not given).
    odo: Vec<f64>,
    /// Each collider's body and dynamic flag (`body << 1 | dynamic`, as in [`SweepEntry`]).
    bodies: Vec<u32>,
}

impl Snapshot {
    fn vertices(&self, c: u32) -> &[Vec2] {
        let (s, n) = self.colliders[c as usize];
        &self.vertices[s as usize..(s + n) as usize]
    }
}

/// The global proximity stage with its reusable buffers and per-pair GJK caches.
///
/// Two ways to run it, with the same result for the same collider poses:
///
/// - [`update`](Self::update): the whole stage at once;
/// - spread over samples: [`begin`](Self::begin) copies the colliders' world features and sorts the
///   boxes, [`advance`](Self::advance) sweeps a share of the boxes and runs GJK on their pairs (call
///   it once per sample), [`publish`](Self::publish) finishes what is left and writes the set. The
///   set then describes the poses at `begin`; the §9.1 margin covers that delay (`spread.rs`).
#[derive(Clone, Debug)]
pub struct BroadPhase {
    delta_prox: f64,
    sweep: Vec<SweepEntry>,
    /// The axis `sweep` runs along (`axis.rs`).
    axis: Axis,
    snapshot: Snapshot,
    /// Sweep position of the update in progress (`None` = no update in progress).
    next: Option<usize>,
    /// The pairs of the update in progress that ran GJK (or were not in the published update).
    tested: Vec<Tested>,
    /// The pairs of the update in progress whose published distance was reused: their index in
    /// the published arrays, whose cache, distance and odometer reference they keep (read from
    /// there by the merge of `fill_ready` when the update is not done in place).
    kept: Vec<u32>,
    /// The pairs of the update in progress that the published update did not have: their
    /// indices in `tested`, in the order met.
    fresh: Vec<u32>,
    /// `fresh` in pair order, made by the last `advance` of an update.
    order: Vec<u32>,
    /// Pairs per first collider (counting sort of `order`).
    bucket: Vec<u32>,
    /// Per published pair, where the finished update takes it from: [`KEPT`] (the published
    /// entry), an index in `tested` (a new GJK result), or [`DROPPED`] (not met by the sweep).
    source: Vec<u32>,
    /// The result of the update in progress is complete in `ready` (published by a swap), or in
    /// `patches` (`in_place`).
    sorted: bool,
    /// Every pair of the update in progress so far was in the published update.
    all_published: bool,
    /// The GJK results of the update in progress for published pairs: (index in the published
    /// arrays, index in `tested`).
    patches: Vec<(u32, u32)>,
    /// The finished update in progress tested exactly the published pairs: publishing writes
    /// `patches` into the published arrays.
    in_place: bool,
    gjk_iterations: u64,
    reused_distances: usize,
    /// The certificate of the update in progress so far, and of the published update
    /// ([`still_exact`](Self::still_exact)); `None` for an update begun without one.
    progress: Option<Certificate>,
    certificate: Option<Certificate>,
    /// The updates to begin without a certificate, and how many after the next failed check
    /// (the backoff; see [`skip_update`](Self::skip_update)).
    backoff: u32,
    wait: u32,
    /// The published update: its pairs (sorted), caches, distances and odometer references, and
    /// where each first collider's pairs start (`cache_pairs[cache_start[a]..cache_start[a + 1]]`).
    cache_pairs: Vec<(u32, u32)>,
    caches: Vec<GjkCache>,
    distances: Vec<f64>,
    odo_refs: Vec<f64>,
    cache_start: Vec<u32>,
    /// A copy of the published proximity set (handed out again by an update in place).
    set: Vec<(u32, u32)>,
    /// The same for the update in progress, once sorted, with its proximity set.
    ready: Published,
    stats: BroadStats,
    /// The pairs a partial update found (`partial.rs`), and the buffer its merged set is written
    /// to (then swapped with the caller's).
    found: Vec<(u32, u32)>,
    merged: Vec<(u32, u32)>,
    /// The dynamic colliders' world boxes (not inflated) sorted by [`sweep_order`], for a
    /// partial update's search by x, and the fixed colliders' boxes.
    near: Vec<SweepEntry>,
    fixed_near: Vec<SweepEntry>,
}

/// How far the bodies may move before an update could give another proximity set than the one
/// computed ([`BroadPhase::still_exact`]): the smallest slack (m) of the update's decisions, as
/// its sweep makes them.
#[derive(Clone, Copy, Debug)]
struct Certificate {
    /// Smallest gap between the inflated boxes of two colliders the sweep did not pair (and
    /// that are not of one body or both fixed).
    gap: f64,
    /// Smallest distance of a paired collider pair's GJK distance interval from `δ_prox`,
    /// beyond the reuse guard.
    slack: f64,
}

impl Certificate {
    /// Nothing decided yet.
    const OPEN: Certificate = Certificate {
        gap: f64::INFINITY,
        slack: f64::INFINITY,
    };
}

/// A collider's body and dynamic flag in one word, `body << 1 | dynamic` (as [`SweepEntry`] and
/// the [`Snapshot`] keep them).
fn body_code(c: &Collider) -> u32 {
    (c.body as u32) << 1 | c.dynamic as u32
}

/// Most updates begun without a certificate after a failed check (see
/// [`BroadPhase::skip_update`]): the backoff doubles from 1 up to this.
const MAX_BACKOFF: u32 = 16;

/// Sweep entries looked at beyond a box's end in x to find one it could be paired with (not of
/// its body, not both fixed): the gap to it bounds every later box's ([`Certificate::gap`]).
const GAP_LOOKAHEAD: usize = 8;

/// The result of an update, as [`BroadPhase::publish`] hands it over.
#[derive(Clone, Debug, Default)]
struct Published {
    set: Vec<(u32, u32)>,
    pairs: Vec<(u32, u32)>,
    caches: Vec<GjkCache>,
    distances: Vec<f64>,
    odo_refs: Vec<f64>,
    start: Vec<u32>,
    stats: BroadStats,
}

/// [`BroadPhase::source`] of a published pair whose published entry is kept.
const KEPT: u32 = u32::MAX - 1;
/// [`BroadPhase::source`] of a published pair the update did not meet.
const DROPPED: u32 = u32::MAX;

impl Published {
    fn clear(&mut self) {
        self.set.clear();
        self.pairs.clear();
        self.caches.clear();
        self.distances.clear();
        self.odo_refs.clear();
        self.start.clear();
    }

    /// Room for `n` pairs in every array (no allocation when there is room already).
    fn reserve(&mut self, n: usize) {
        room(&mut self.set, n);
        room(&mut self.pairs, n);
        room(&mut self.caches, n);
        room(&mut self.distances, n);
        room(&mut self.odo_refs, n);
    }

    /// Appends pair `t` (pairs come in pair order); it joins the set when closer than
    /// `delta_prox` (m).
    #[inline]
    fn push(&mut self, t: &Tested, delta_prox: f64) {
        if t.distance < delta_prox {
            self.set.push(t.pair);
        }
        while self.start.len() <= t.pair.0 as usize {
            self.start.push(self.pairs.len() as u32);
        }
        self.pairs.push(t.pair);
        self.caches.push(t.cache);
        self.distances.push(t.distance);
        self.odo_refs.push(t.odo_ref);
    }

    /// Ends `start` for `n` colliders.
    fn finish(&mut self, n: usize) {
        while self.start.len() <= n {
            self.start.push(self.pairs.len() as u32);
        }
    }
}

impl BroadPhase {
    /// A global stage with proximity distance `delta_prox` (m, finite, > 0; default
    /// [`DEFAULT_DELTA_PROX`]).
    pub fn new(delta_prox: f64) -> Result<Self, String> {
        if !(delta_prox.is_finite() && delta_prox > 0.0) {
            return Err(format!(
                "delta_prox (proximity distance) must be a finite distance > 0 m, got {delta_prox}"
            ));
        }
        Ok(Self {
            delta_prox,
            sweep: Vec::new(),
            axis: Axis::X,
            snapshot: Snapshot::default(),
            next: None,
            tested: Vec::new(),
            kept: Vec::new(),
            fresh: Vec::new(),
            order: Vec::new(),
            bucket: Vec::new(),
            source: Vec::new(),
            sorted: false,
            all_published: true,
            patches: Vec::new(),
            in_place: false,
            gjk_iterations: 0,
            reused_distances: 0,
            progress: None,
            certificate: None,
            backoff: 0,
            wait: 0,
            cache_pairs: Vec::new(),
            caches: Vec::new(),
            distances: Vec::new(),
            odo_refs: Vec::new(),
            cache_start: Vec::new(),
            set: Vec::new(),
            ready: Published::default(),
            stats: BroadStats::default(),
            found: Vec::new(),
            merged: Vec::new(),
            near: Vec::new(),
            fixed_near: Vec::new(),
        })
    }

    /// [`new`](Self::new) with room for `pairs` AABB-overlapping pairs, so that updates up to
    /// that size never allocate once the per-collider buffers have grown (the world sizes it
    /// like its local stage).
    pub fn with_capacity(delta_prox: f64, pairs: usize) -> Result<Self, String> {
        let mut b = Self::new(delta_prox)?;
        b.tested.reserve(pairs);
        b.kept.reserve(pairs);
        b.fresh.reserve(pairs);
        b.order.reserve(pairs);
        b.source.reserve(pairs);
        b.patches.reserve(pairs);
        b.set.reserve(pairs);
        for v in [
            &mut b.cache_pairs,
            &mut b.ready.pairs,
            &mut b.ready.set,
            &mut b.found,
            &mut b.merged,
        ] {
            v.reserve(pairs);
        }
        b.caches.reserve(pairs);
        b.ready.caches.reserve(pairs);
        for v in [
            &mut b.distances,
            &mut b.odo_refs,
            &mut b.ready.distances,
            &mut b.ready.odo_refs,
        ] {
            v.reserve(pairs);
        }
        Ok(b)
    }

    /// The proximity distance `δ_prox` (m).
    pub fn delta_prox(&self) -> f64 {
        self.delta_prox
    }

    /// Counters of the last update.
    pub fn stats(&self) -> BroadStats {
        self.stats
    }

    /// GJK distances (m) of the AABB-overlapping pairs of the last update, with those pairs (sorted).
    pub fn tested_pairs(&self) -> (&[(u32, u32)], &[f64]) {
        (&self.cache_pairs, &self.distances)
    }

    /// Whether a spread update is in progress (between [`begin`](Self::begin) and
    /// [`publish`](Self::publish)).
    pub fn in_progress(&self) -> bool {
        self.next.is_some()
    }

    /// Computes the proximity set of `colliders` (world features must be current) into `out`
    /// (cleared first): sorted `(a, b)` collider indices, `a < b`, with GJK distance `< δ_prox`.
    /// Abandons a spread update in progress. No allocation once the buffers have grown to the
    /// scene's size.
    pub fn update(&mut self, colliders: &[Collider], out: &mut Vec<(u32, u32)>) {
        self.update_with_motion(colliders, &[], out);
    }

    /// [`update`](Self::update), skipping GJK for the pairs whose side of `δ_prox` the bodies'
    /// motion since their last distance cannot have changed (`sweep.rs`): `odometer[i]` (m) is
    /// a running bound on the distance any point of body `i` has moved (non-decreasing). An empty
    /// `odometer` (or one shorter than the bodies) runs GJK on every pair.
    pub fn update_with_motion(
        &mut self,
        colliders: &[Collider],
        odometer: &[f64],
        out: &mut Vec<(u32, u32)>,
    ) {
        self.begin_with_motion(colliders, odometer);
        self.publish(out);
    }
}
