//! The global proximity stage (§9.1): inflated AABBs, sort-and-sweep on x, then GJK distance.
//!
//! # The algorithm
//!
//! Every `N_g` samples (`T_g = 20 ms` by default):
//!
//! 1. Each collider's world AABB is enlarged by `δ_prox/2` on every side, so two boxes overlap
//!    whenever the polygons are closer than `δ_prox` (a necessary condition).
//! 2. Sort-and-sweep: the boxes are sorted by `(min.x, collider index)` (a total order, so the
//!    result does not depend on the sort algorithm) and each box is tested only against the boxes
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
//! # Spreading the stage over the samples
//!
//! Run at once, the stage makes every `N_g`-th sample the slowest (≈ 2.7× the others at 1000
//! bodies): a deadline spike. The margin above already allows one period for the update itself,
//! so the work can instead be spread over the `N_g` samples of a period (the world's default):
//!
//! ```text
//! sample k·N_g           publish(set of (k−1)·N_g)   begin(poses of k·N_g)
//! sample k·N_g + j       advance: ⌈remaining/(N_g−j)⌉ boxes                  j = 1 … N_g−2
//! sample k·N_g + N_g−1   advance: the last boxes, then merge the pairs in order (publish only
//!                        hands them over), or patch in place (below)
//! ```
//!
//! The publishing sample sweeps nothing: publishing and `begin` (the snapshot, the boxes and
//! their sort) are its share.
//!
//! `begin` copies the world vertices (the snapshot), so the set published at `(k+1)·N_g` is
//! exactly the set [`BroadPhase::update`] would have computed at `k·N_g` (same pairs, distances
//! and caches: each pair's GJK depends only on its vertices and its own cache, not on the order
//! of the pairs). It is used until `(k+2)·N_g`: a pair it leaves out was `≥ δ_prox` apart at
//! `k·N_g` and, at `v_rel,max`, is still `> δ_c` apart `2·T_g` later, which is the margin rule.
//! The world's early update (a body that moved more than `(δ_prox − δ_c)/2` since the poses of
//! the set in use) still runs the whole stage at once, so fast bodies keep their guarantee.
//!
//! # Distances that need no GJK (issue 17)
//!
//! Given the bodies' odometers (bounds on how far any point of a body has moved, m), a pair
//! tested by the last update at distance `D` whose bodies have moved `m` in all since that
//! distance was computed is now between `D − m` and `D + m` apart. When that interval is on one
//! side of `δ_prox` (by a 1 µm guard), the pair's side of the test is known: GJK is skipped and
//! the pair keeps its distance, cache and odometer reference (`BroadStats::reused_distances`).
//! A pile at rest moves micrometres per period, so its pairs are re-tested only in the sweep.
//!
//! # Patching in place
//!
//! When every pair an update tests is one of the published update's (every lookup found its
//! entry, and the counts agree), rebuilding the published arrays would change only the entries
//! that needed GJK. The update then writes just those entries over the published ones and
//! rebuilds the set only if one of them changed side of `δ_prox` (`BroadStats::in_place`). A
//! settled pile:1000 takes this path in 143 of 150 updates.
//!
//! Otherwise the published pairs the sweep met again are already in pair order: the few pairs
//! the published update did not have are sorted, and the two lists merged in one pass over the
//! published arrays (a pile that is still moving; pile:1000 between 1 and 2 s, 37 of 100
//! updates).
//!
//! # Skipping an update that cannot change the set (issue 17)
//!
//! The sweep also records how close each of its decisions came to going the other way: the
//! smallest gap between the inflated boxes of two colliders it did not pair (`gap`), and the
//! smallest distance of a paired pair's distance interval from `δ_prox` (`slack`). While no
//! vertex has moved by half the smaller of the two since the update's snapshot, no pair can have
//! changed side, so a new update would compute the same set ([`BroadPhase::still_exact`]). The
//! world then skips the periodic update ([`WorldParams::proximity_skip`](crate::world::WorldParams)):
//! a pile at rest (pile:100, the pyramid, the paper's box scenes) does no global work at all.
//! One pair near a threshold is enough to fail the check, so a large settling pile rarely
//! passes it; after a failed check the next updates skip the bookkeeping
//! ([`BroadPhase::skip_update`]).

use super::gjk::{gjk_distance, GjkCache};
use super::Collider;
use crate::geom::Vec2;

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
    /// last distance kept (module docs).
    pub reused_distances: usize,
    /// The update tested exactly the last published update's pairs: its few new GJK distances
    /// were written into the published result in place instead of sorting and copying every
    /// pair again (a pile at rest, most updates).
    pub in_place: bool,
}

/// One box in the sweep: the inflated box's x and y ranges, the collider index and its body (the
/// y range here too, so that the sweep rejects boxes apart in y without reading anything else:
/// in a pile, every box of a column overlaps in x; the body too, so that the same-body and
/// fixed–fixed filters need no lookup either; 40 bytes with both).
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

/// Grows `v`'s capacity to at least `n` (no allocation when it has that room already).
fn room<T>(v: &mut Vec<T>, n: usize) {
    if v.capacity() < n {
        v.reserve(n - v.len());
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
///   set then describes the poses at `begin`; the §9.1 margin covers that delay (module docs).
#[derive(Clone, Debug)]
pub struct BroadPhase {
    delta_prox: f64,
    sweep: Vec<SweepEntry>,
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
        for v in [&mut b.cache_pairs, &mut b.ready.pairs, &mut b.ready.set] {
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

    /// Whether an update now, for the current world features of `colliders`, would compute the
    /// proximity set the last published update computed, so that it may be skipped (issue 17).
    /// False while an update is in progress, or for colliders other than the published
    /// update's (count, vertex counts, bodies and dynamic flags).
    ///
    /// **Why it holds.** Let `M` be the largest distance a vertex has moved since the published
    /// update's snapshot (the snapshot keeps the vertices). Every point of a convex polygon is a
    /// convex combination of its vertices, so it has moved by at most `M` as well: a pair's
    /// distance, and each side of its colliders' boxes, changed by at most `2·M`.
    /// - A pair the sweep paired has a GJK distance interval (its distance at its odometer
    ///   reference, grown by the motion up to the snapshot) that was `slack` away from `δ_prox`
    ///   (beyond the reuse guard): while `2·M < slack`, it is on the same side of `δ_prox`, so in
    ///   the set or out of it as before.
    /// - A pair the sweep did not pair (of two bodies, not both fixed) had inflated boxes `gap` or
    ///   more apart in x or in y, so the colliders were more than `δ_prox + gap` apart: while
    ///   `2·M < gap` they are still more than `δ_prox` apart, and out of the set.
    ///
    /// So while `2·M < min(slack, gap)`, every pair is in the set exactly when it was, and an
    /// update would give the same set (its internal distances and caches aside). The published
    /// set is then as good as a new one for the margin rule (module docs). Costs one pass over
    /// the colliders' world vertices.
    pub fn still_exact(&self, colliders: &[Collider]) -> bool {
        let snap = &self.snapshot;
        let Some(c) = self.certificate else {
            return false;
        };
        if self.next.is_some()
            || colliders.len() != snap.colliders.len()
            || !(c.gap > 0.0 && c.slack > 0.0)
        {
            return false;
        }
        let limit = 0.5 * c.gap.min(c.slack);
        let limit_sq = limit * limit;
        for (i, col) in colliders.iter().enumerate() {
            let now = col.world_vertices();
            let then = snap.vertices(i as u32);
            if now.len() != then.len() || body_code(col) != snap.bodies[i] {
                return false;
            }
            for (p, q) in now.iter().zip(then) {
                // A NaN vertex fails too.
                let moved_sq = (*p - *q).length_squared();
                if moved_sq >= limit_sq || moved_sq.is_nan() {
                    return false;
                }
            }
        }
        true
    }

    /// [`still_exact`](Self::still_exact), with a backoff for worlds where it keeps failing
    /// (a settling pile:1000 has thousands of pairs, and one of them near a threshold is
    /// enough): after a failed check the next 1, 2, 4, … (at most 16) updates
    /// compute no certificate, so their sweep records no slack and no check reads the vertices;
    /// a check that holds resets it. Returns whether the periodic update may be skipped.
    pub fn skip_update(&mut self, colliders: &[Collider]) -> bool {
        if self.certificate.is_none() {
            return false; // no certificate to check
        }
        if self.still_exact(colliders) {
            self.backoff = 0;
            return true;
        }
        self.backoff = (2 * self.backoff).clamp(1, MAX_BACKOFF);
        self.wait = self.backoff;
        // Checked once: the next update makes a new one, if any.
        self.certificate = None;
        false
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
    /// motion since their last distance cannot have changed (module docs): `odometer[i]` (m) is
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

    /// Starts an update for the current poses of `colliders`: copies their world vertices, builds
    /// the inflated boxes and sorts them (abandons an update in progress). Nothing is published
    /// until [`publish`](Self::publish).
    pub fn begin(&mut self, colliders: &[Collider]) {
        self.begin_with_motion(colliders, &[]);
    }

    /// [`begin`](Self::begin) with the bodies' odometers now (see
    /// [`update_with_motion`](Self::update_with_motion)).
    pub fn begin_with_motion(&mut self, colliders: &[Collider], odometer: &[f64]) {
        let half = 0.5 * self.delta_prox;
        // 0. The snapshot: the rest of the update reads only this copy.
        self.snapshot.vertices.clear();
        self.snapshot.colliders.clear();
        self.snapshot.odo.clear();
        self.snapshot.bodies.clear();
        for c in colliders {
            let s = self.snapshot.vertices.len() as u32;
            self.snapshot.vertices.extend_from_slice(c.world_vertices());
            self.snapshot
                .colliders
                .push((s, c.world_vertices().len() as u32));
            self.snapshot
                .odo
                .push(odometer.get(c.body).copied().unwrap_or(f64::NAN));
            self.snapshot.bodies.push(body_code(c));
        }
        self.progress = (self.wait == 0).then_some(Certificate::OPEN);
        self.wait = self.wait.saturating_sub(1);
        // 1. Inflated boxes, sorted by (min.x, index): in the last update's order, which is
        //    nearly sorted when the bodies move little between updates (insertion sort), or by
        //    index (a full sort) when the colliders changed.
        let entry = |i: usize, c: &Collider| {
            let bx = c.aabb.inflated(half);
            SweepEntry {
                min_x: bx.min.x,
                max_x: bx.max.x,
                min_y: bx.min.y,
                max_y: bx.max.y,
                index: i as u32,
                body: body_code(c),
            }
        };
        if self.sweep.len() == colliders.len() {
            for e in self.sweep.iter_mut() {
                *e = entry(e.index as usize, &colliders[e.index as usize]);
            }
            sort_sweep(&mut self.sweep);
        } else {
            self.sweep.clear();
            for (i, c) in colliders.iter().enumerate() {
                self.sweep.push(entry(i, c));
            }
            self.sweep.sort_unstable_by(sweep_order);
        }
        // Both buffers of the per-collider starts, sized here (an update in place leaves them
        // unswapped for many periods, so the second one would otherwise grow late).
        room(&mut self.cache_start, colliders.len() + 1);
        room(&mut self.ready.start, colliders.len() + 1);
        self.tested.clear();
        self.kept.clear();
        self.fresh.clear();
        self.sorted = false;
        self.all_published = true;
        self.patches.clear();
        // Room for every published pair, so that patching allocates only when the published
        // update has grown (when the other buffers grow too).
        room(&mut self.patches, self.cache_pairs.len());
        room(&mut self.kept, self.cache_pairs.len());
        self.in_place = false;
        self.gjk_iterations = 0;
        self.reused_distances = 0;
        self.next = Some(0);
    }

    /// Advances the update in progress by one sample's share, `samples_left` being the number of
    /// calls left before [`publish`](Self::publish) (this one included; at least 1): the
    /// remaining boxes are split evenly over the `samples_left` calls (`⌈remaining /
    /// samples_left⌉` boxes, each tested against the boxes that start before it ends in x, GJK on
    /// every pair that overlaps); the last call (`samples_left = 1`) sweeps whatever is left and
    /// finishes the result (sorts the pairs, or marks them for patching in place), so the
    /// publishing sample only hands it over. Does nothing when no update is in progress.
    pub fn advance(&mut self, samples_left: usize) {
        let Some(start) = self.next else { return };
        let n = self.sweep.len();
        let share = (n - start).div_ceil(samples_left.max(1));
        let stop = (start + share).min(n);
        match self.progress {
            Some(cert) => self.progress = Some(self.sweep_boxes::<true>(start, stop, cert)),
            None => {
                self.sweep_boxes::<false>(start, stop, Certificate::OPEN);
            }
        }
        self.next = Some(stop);
        if samples_left <= 1 && !self.sorted {
            // Every tested pair is a published one (distinct ones: the sweep meets each pair
            // once), so when the counts agree the tested pairs are exactly the published pairs:
            // sorting them would rebuild the published arrays with the reused entries as they
            // are and the `patches` written over theirs.
            self.in_place = self.all_published
                && self.tested.len() + self.kept.len() == self.cache_pairs.len()
                && self.cache_start.len() == self.snapshot.colliders.len() + 1;
            if !self.in_place {
                self.sort_fresh();
                self.fill_ready();
            }
            self.sorted = true;
        }
    }

    /// Steps 2–3 of an update for the sweep entries `start..stop`. With `CERTIFY`, returns the
    /// certificate `cert` of the update so far with each of these decisions' slack taken in
    /// (without, `cert` unchanged).
    fn sweep_boxes<const CERTIFY: bool>(
        &mut self,
        start: usize,
        stop: usize,
        mut cert: Certificate,
    ) -> Certificate {
        // 2. Sweep on x, test y, filter same-body and fixed–fixed pairs; 3. warm-started GJK per
        //    pair (each pair's result depends on its own cache only, so the order of this loop
        //    does not change any result).
        // Same body, or both fixed (the dynamic flags are the low bits): never a pair.
        let unpaired = |p: &SweepEntry, q: &SweepEntry| {
            p.body >> 1 == q.body >> 1 || (p.body | q.body) & 1 == 0
        };
        let n = self.sweep.len();
        for i in start..stop {
            let ei = self.sweep[i];
            // The run of boxes that start before `ei` ends in x (sorted by start), 64 at a time,
            // and a bit for each that overlaps `ei` (the rest of `Aabb::overlaps`, closed
            // intervals, from the entries alone: in y, which rejects most of a pile's column).
            // The bits are set without a branch: whether a box of another row overlaps is what a
            // branch predictor cannot guess.
            let mut from = i + 1;
            let end = loop {
                let to = (from + 64).min(n);
                let mut end = to;
                let mut bits = 0u64;
                for (k, ej) in self.sweep[from..to].iter().enumerate() {
                    if ej.min_x > ei.max_x {
                        end = from + k;
                        break;
                    }
                    let overlaps =
                        (ej.min_y <= ei.max_y) & (ei.min_y <= ej.max_y) & (ei.min_x <= ej.max_x);
                    if CERTIFY {
                        // The y gap to a box it could be paired with but does not overlap.
                        let gap = if overlaps || unpaired(&ei, ej) {
                            f64::INFINITY
                        } else {
                            (ej.min_y - ei.max_y).max(ei.min_y - ej.max_y)
                        };
                        cert.gap = cert.gap.min(gap);
                    }
                    bits |= (overlaps as u64) << k;
                }
                while bits != 0 {
                    let ej = self.sweep[from + bits.trailing_zeros() as usize];
                    bits &= bits - 1;
                    if !unpaired(&ei, &ej) {
                        self.test_pair::<CERTIFY>(&ei, &ej, &mut cert);
                    }
                }
                if end < to || to == n {
                    break end;
                }
                from = to;
            };
            if CERTIFY && end < n {
                // Every later box starts at least this far beyond `ei`'s end (the gap to the
                // first one it could be paired with, looking a few entries ahead).
                let rest = &self.sweep[end..];
                let beyond = rest
                    .iter()
                    .take(GAP_LOOKAHEAD)
                    .find(|e| !unpaired(&ei, e))
                    .or(rest.get(GAP_LOOKAHEAD - 1));
                if let Some(e) = beyond {
                    cert.gap = cert.gap.min(e.min_x - ei.max_x);
                }
            }
        }
        cert
    }

    /// Step 3 for one pair of overlapping boxes: its last distance reused when the motion cannot
    /// have moved it across `δ_prox`, warm-started GJK otherwise. With `CERTIFY`, takes the
    /// decision's slack into `cert`.
    #[inline(always)]
    fn test_pair<const CERTIFY: bool>(
        &mut self,
        ei: &SweepEntry,
        ej: &SweepEntry,
        cert: &mut Certificate,
    ) {
        let (a, b) = (ei.index.min(ej.index), ei.index.max(ej.index));
        let odo = self.snapshot.odo[a as usize] + self.snapshot.odo[b as usize];
        let last = self.cached(a, b);
        if let Some(k) = last {
            // The pair's side of δ_prox is known from its last distance and the motion.
            let (d, moved) = (self.distances[k], odo - self.odo_refs[k]);
            let below = (self.delta_prox - REUSE_GUARD) - (d + moved);
            let above = (d - moved) - (self.delta_prox + REUSE_GUARD);
            if below > 0.0 || above > 0.0 {
                if CERTIFY {
                    cert.slack = cert.slack.min(below.max(above));
                }
                self.reused_distances += 1;
                self.kept.push(k as u32);
                return;
            }
        }
        match last {
            Some(k) => self.patches.push((k as u32, self.tested.len() as u32)),
            None => {
                self.all_published = false;
                self.fresh.push(self.tested.len() as u32);
            }
        }
        let mut cache = last.map(|k| self.caches[k]).unwrap_or_default();
        let g = gjk_distance(
            self.snapshot.vertices(a),
            self.snapshot.vertices(b),
            &mut cache,
        );
        self.gjk_iterations += g.iterations as u64;
        if CERTIFY {
            let slack = (g.distance - self.delta_prox).abs() - REUSE_GUARD;
            cert.slack = cert.slack.min(slack);
        }
        self.tested.push(Tested {
            pair: (a, b),
            cache,
            distance: g.distance,
            odo_ref: odo,
        });
    }

    /// Where pair `(a, b)` is in the published update (its cache, distance and odometer
    /// reference), if it tested the pair.
    #[inline]
    fn cached(&self, a: u32, b: u32) -> Option<usize> {
        let from = *self.cache_start.get(a as usize)? as usize;
        let to = *self.cache_start.get(a as usize + 1)? as usize;
        Some(from + self.cache_pairs[from..to].iter().position(|p| p.1 == b)?)
    }

    /// `order` = `fresh` sorted by pair: a counting sort on the first collider, then an insertion
    /// sort of each collider's few pairs on the second (pairs are unique, so the order is the one
    /// any sort gives).
    fn sort_fresh(&mut self) {
        let n = self.snapshot.colliders.len();
        self.bucket.clear();
        self.bucket.resize(n + 1, 0);
        for &k in &self.fresh {
            self.bucket[self.tested[k as usize].pair.0 as usize + 1] += 1;
        }
        for i in 0..n {
            self.bucket[i + 1] += self.bucket[i];
        }
        self.order.clear();
        self.order.resize(self.fresh.len(), 0);
        for &k in &self.fresh {
            let at = &mut self.bucket[self.tested[k as usize].pair.0 as usize];
            self.order[*at as usize] = k;
            *at += 1;
        }
        // `bucket[a]` is now the end of collider a's pairs; sort each run on the second collider.
        let mut from = 0;
        for a in 0..n {
            let to = self.bucket[a] as usize;
            for i in from + 1..to {
                let k = self.order[i];
                let key = self.tested[k as usize].pair.1;
                let mut j = i;
                while j > from && self.tested[self.order[j - 1] as usize].pair.1 > key {
                    self.order[j] = self.order[j - 1];
                    j -= 1;
                }
                self.order[j] = k;
            }
            from = to;
        }
    }

    /// Writes the sorted result of the update in progress into `ready` (the set, the pairs'
    /// caches and distances, where each first collider's pairs start, the counters), so that
    /// publishing is a swap.
    ///
    /// The result is the published pairs the sweep met again (their published entries where the
    /// distance was reused, their new GJK results otherwise) and the fresh pairs: two lists in
    /// pair order, merged. The published arrays are read in order, so a pile whose pairs change
    /// by a few per update costs one sequential pass, not a sort of every pair (issue 17: the
    /// sort made the last share of such an update 1.5 times a sample's median at pile:1000).
    fn fill_ready(&mut self) {
        // Where each published pair comes from (the published arrays have not changed since the
        // sweep looked them up: only `publish` writes them).
        self.source.clear();
        self.source.resize(self.cache_pairs.len(), DROPPED);
        for &k in &self.kept {
            self.source[k as usize] = KEPT;
        }
        for &(k, t) in &self.patches {
            self.source[k as usize] = t;
        }
        let r = &mut self.ready;
        r.clear();
        r.reserve(self.tested.len() + self.kept.len());
        let mut fresh = self
            .order
            .iter()
            .map(|&t| &self.tested[t as usize])
            .peekable();
        for (k, &source) in self.source.iter().enumerate() {
            let entry = match source {
                DROPPED => continue,
                KEPT => Tested {
                    pair: self.cache_pairs[k],
                    cache: self.caches[k],
                    distance: self.distances[k],
                    odo_ref: self.odo_refs[k],
                },
                t => self.tested[t as usize],
            };
            while let Some(f) = fresh.next_if(|f| f.pair < entry.pair) {
                r.push(f, self.delta_prox);
            }
            r.push(&entry, self.delta_prox);
        }
        for f in fresh {
            r.push(f, self.delta_prox);
        }
        r.finish(self.snapshot.colliders.len());
        r.stats = BroadStats {
            aabb_pairs: r.pairs.len(),
            proximate_pairs: r.set.len(),
            gjk_iterations: self.gjk_iterations,
            reused_distances: self.reused_distances,
            in_place: false,
        };
    }

    /// Writes the GJK results of an update in place (`patches`) into the published arrays; the
    /// proximity set is rebuilt from the distances when a patched pair changed side of `δ_prox`.
    fn patch(&mut self) {
        let mut crossed = false;
        for &(k, t) in &self.patches {
            let (k, t) = (k as usize, &self.tested[t as usize]);
            crossed |= (self.distances[k] < self.delta_prox) != (t.distance < self.delta_prox);
            self.caches[k] = t.cache;
            self.distances[k] = t.distance;
            self.odo_refs[k] = t.odo_ref;
        }
        if crossed {
            self.set.clear();
            for (&p, &d) in self.cache_pairs.iter().zip(&self.distances) {
                if d < self.delta_prox {
                    self.set.push(p);
                }
            }
        }
    }

    /// Finishes the update in progress (sweeps what is left) and writes its proximity set into
    /// `out` (cleared first; sorted, `a < b`, GJK distance `< δ_prox`); the pairs' caches become
    /// the warm starts of the next update. Leaves `out` untouched when no update is in progress.
    pub fn publish(&mut self, out: &mut Vec<(u32, u32)>) {
        if self.next.is_none() {
            return;
        }
        self.advance(1);
        self.next = None;
        self.certificate = self.progress;
        if self.in_place {
            self.patch();
            if *out != self.set {
                out.clone_from(&self.set);
            }
            self.stats = BroadStats {
                aabb_pairs: self.tested.len() + self.kept.len(),
                proximate_pairs: self.set.len(),
                gjk_iterations: self.gjk_iterations,
                reused_distances: self.reused_distances,
                in_place: true,
            };
            return;
        }
        // Everything was written by the last `advance`: publishing swaps the buffers.
        let r = &mut self.ready;
        std::mem::swap(out, &mut r.set);
        std::mem::swap(&mut self.cache_pairs, &mut r.pairs);
        std::mem::swap(&mut self.caches, &mut r.caches);
        std::mem::swap(&mut self.distances, &mut r.distances);
        std::mem::swap(&mut self.odo_refs, &mut r.odo_refs);
        std::mem::swap(&mut self.cache_start, &mut r.start);
        // An update in place has these pairs, so its set has at most as many: with this room in
        // the copy and in both buffers that take turns as the caller's, it allocates nothing.
        let most = self.cache_pairs.len();
        self.set.clone_from(out);
        room(&mut self.set, most);
        room(&mut r.set, most);
        self.stats = r.stats;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{ConvexPolygon, Pose};

    fn square(body: usize, dynamic: bool, x: f64, y: f64) -> Collider {
        Collider::new(
            body,
            dynamic,
            ConvexPolygon::rectangle(0.04, 0.04).unwrap(),
            &Pose::new(x, y, 0.0),
        )
    }

    #[test]
    fn margin_rule_gives_default() {
        assert!((required_delta_prox(1.0, 0.02, 0.002) - DEFAULT_DELTA_PROX).abs() < 1e-15);
        assert!(BroadPhase::new(0.0).is_err());
        assert!(BroadPhase::new(f64::NAN).is_err());
    }

    #[test]
    fn filters_and_threshold() {
        let cols = vec![
            square(0, false, 0.0, 0.0),
            square(1, false, 0.06, 0.0),  // fixed–fixed with 0: skipped
            square(2, true, 0.0, 0.081),  // 0.041 from 0: proximate
            square(2, true, 0.0, 0.0805), // same body as 2: never paired with it
            square(3, true, 0.2, 0.0),    // far from everything
            square(4, true, 0.0, -0.083), // 0.043 from 0: not proximate
        ];
        let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        let mut out = Vec::new();
        bp.update(&cols, &mut out);
        assert_eq!(out, vec![(0, 2), (0, 3)]);
    }

    /// A jittered grid of squares, some rotated, with a fixed floor: many AABB pairs, some proximate.
    fn grid(shift: f64, pitch: f64) -> Vec<Collider> {
        let mut cols = vec![Collider::new(
            0,
            false,
            ConvexPolygon::rectangle(2.0, 0.1).unwrap(),
            &Pose::new(0.0, -0.05, 0.0),
        )];
        for k in 0..120usize {
            let (i, j) = ((k % 12) as f64, (k / 12) as f64);
            let jitter = ((k * 7919) % 13) as f64 * 1e-3;
            cols.push(Collider::new(
                k + 1,
                true,
                ConvexPolygon::rectangle(0.04, 0.04).unwrap(),
                &Pose::new(
                    -0.3 + i * pitch + jitter + shift,
                    0.021 + j * 0.0455,
                    0.1 * jitter * k as f64,
                ),
            ));
        }
        cols
    }

    /// A seeded xorshift generator of uniform numbers in `[0, 1)`.
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut rng = seed;
        move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The sweep pairs exactly the colliders whose inflated boxes overlap (closed), once each,
    /// leaving out same-body and fixed–fixed pairs, against a test of every pair: random scenes
    /// from 1 to 400 colliders, some stacked in narrow columns so that a box's x run is longer
    /// than one or two of the sweep's 64-box blocks, some touching exactly, some sharing a body;
    /// with the certificate's bookkeeping and without it.
    #[test]
    fn the_sweep_pairs_every_overlapping_pair_once() {
        let mut next = uniform(0x2545_f491_4f6c_dd1du64);
        let half = 0.5 * DEFAULT_DELTA_PROX;
        let (mut longest_run, mut plain_updates) = (0, 0);
        for trial in 0..300 {
            let n = 1 + (400.0 * next() * next()) as usize;
            let columns = 1 + (6.0 * next()) as usize;
            let (mut cols, mut poses) = (Vec::new(), Vec::new());
            for i in 0..n {
                let body = if next() < 0.1 && i > 0 { i - 1 } else { i };
                let dynamic = next() < 0.8;
                let (w, h) = (0.01 + 0.05 * next(), 0.01 + 0.05 * next());
                let pose = if trial % 3 == 0 {
                    Pose::new(next(), next(), 6.0 * next())
                } else {
                    // A column: the same x up to a little jitter, rows 0.03 m apart, so that
                    // neighbours overlap and boxes two rows apart do not; every 7th exactly on
                    // the row above's edge.
                    let c = (i % columns) as f64 * 0.2;
                    let jitter = if i % 7 == 0 { 0.0 } else { 0.004 * next() };
                    Pose::new(c + jitter, 0.03 * (i / columns) as f64, 0.0)
                };
                let shape = ConvexPolygon::rectangle(w, h).unwrap();
                cols.push(Collider::new(body, dynamic, shape, &pose));
                poses.push(pose);
            }
            let mut want = Vec::new();
            for a in 0..n {
                let run = (a + 1..n)
                    .filter(|&b| {
                        let (p, q) = (cols[a].aabb.inflated(half), cols[b].aabb.inflated(half));
                        p.min.x <= q.max.x && q.min.x <= p.max.x
                    })
                    .count();
                longest_run = longest_run.max(run);
                for b in a + 1..n {
                    let (ca, cb) = (&cols[a], &cols[b]);
                    let overlap = ca.aabb.inflated(half).overlaps(&cb.aabb.inflated(half));
                    let filtered = ca.body == cb.body || !(ca.dynamic || cb.dynamic);
                    if overlap && !filtered {
                        want.push((a as u32, b as u32));
                    }
                }
            }
            // The sweep with the certificate's bookkeeping (a first update), and without it
            // (an update after a failed skip check, which backs off from certifying).
            let mut certifying = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
            certifying.update(&cols, &mut Vec::new());
            assert!(certifying.certificate.is_some());
            assert_eq!(
                certifying.tested_pairs().0,
                &want[..],
                "trial {trial}, {n} boxes"
            );
            let mut plain = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
            plain.update(&cols, &mut Vec::new());
            let moved: Vec<Collider> = cols
                .iter()
                .zip(&poses)
                .map(|(c, p)| {
                    let mut c = c.clone();
                    c.update(&Pose::new(p.pos.x + 0.3, p.pos.y, p.angle + 0.5));
                    c
                })
                .collect();
            if !plain.skip_update(&moved) {
                plain.update(&cols, &mut Vec::new());
                plain_updates += usize::from(plain.certificate.is_none());
                assert_eq!(
                    plain.tested_pairs().0,
                    &want[..],
                    "trial {trial}, {n} boxes"
                );
            }
        }
        assert!(longest_run > 128, "x runs over two blocks ({longest_run})");
        assert!(
            plain_updates > 200,
            "updates without the certificate: {plain_updates}"
        );
    }

    /// The spread update publishes exactly the set, distances, caches and counters of the whole
    /// update at the poses of `begin`, whatever the poses of the colliders in between, and
    /// whatever number of samples it is spread over.
    #[test]
    fn spread_update_equals_whole_update_at_begin() {
        let (a, b) = (grid(0.0, 0.05), grid(0.013, 0.09));
        for samples in [1usize, 2, 3, 10, 500] {
            let mut whole = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
            let mut spread = whole.clone();
            let (mut out_w, mut out_s) = (Vec::new(), vec![(7, 7)]);
            // Warm both caches on `b` first, so the warm starts are exercised.
            whole.update(&b, &mut out_w);
            spread.update(&b, &mut out_s);
            whole.update(&a, &mut out_w);
            spread.begin(&a);
            for j in 0..samples {
                assert!(spread.in_progress());
                spread.advance(samples - j);
            }
            let before = out_s.clone();
            spread.publish(&mut out_s);
            assert_ne!(out_s, before, "the set of `a` differs from the set of `b`");
            assert!(!spread.in_progress());
            assert!(whole.stats().aabb_pairs > 200, "{:?}", whole.stats());
            assert_eq!(out_s, out_w, "{samples} samples");
            assert_eq!(spread.stats(), whole.stats(), "{samples} samples");
            let (pw, dw) = whole.tested_pairs();
            let (ps, ds) = spread.tested_pairs();
            assert_eq!(pw, ps);
            let bits = |d: &[f64]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(dw), bits(ds));
            // Publishing with no update in progress leaves the set alone.
            spread.publish(&mut out_s);
            assert_eq!(out_s, out_w);
        }
    }

    /// `advance(k)` splits the remaining boxes evenly over the first `N_g − 1` samples of the period
    /// and sorts at the last one, so publish has nothing left to do but copy.
    #[test]
    fn advance_shares_cover_the_sweep() {
        let cols = grid(0.0, 0.05);
        let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        bp.begin(&cols);
        let mut swept = Vec::new();
        for j in 1..9 {
            bp.advance(10 - j);
            swept.push(bp.next.unwrap());
        }
        // Nine even shares of the boxes over the samples after `begin`; the last one sorts too.
        let share = cols.len().div_ceil(9);
        assert_eq!(swept[0], share);
        assert!(swept.windows(2).all(|w| w[1] - w[0] <= share));
        assert!(!bp.sorted);
        bp.advance(1);
        assert_eq!(bp.next, Some(cols.len()));
        assert!(cols.len() - swept[7] <= share);
        let pairs = bp.tested.len();
        assert!(bp.sorted && bp.order.len() == pairs && pairs > 0);
        assert!(bp.ready.pairs.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(bp.ready.pairs.len(), pairs);
    }

    /// The warm-start lookup by first collider finds exactly the published pairs' caches.
    #[test]
    fn cache_lookup_finds_the_published_pairs() {
        let cols = grid(0.0, 0.05);
        let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        let mut out = Vec::new();
        bp.update(&cols, &mut out);
        assert!(bp.cache_pairs.len() > 200);
        for (k, &(a, b)) in bp.cache_pairs.iter().enumerate() {
            let c = bp.cached(a, b).expect("a published pair has its cache");
            assert_eq!(c, k);
        }
        let n = cols.len() as u32;
        let tested: std::collections::BTreeSet<_> = bp.cache_pairs.iter().copied().collect();
        for a in 0..n + 2 {
            for b in a + 1..n + 2 {
                assert_eq!(
                    bp.cached(a, b).is_some(),
                    tested.contains(&(a, b)),
                    "{a} {b}"
                );
            }
        }
    }

    /// GJK skipped on the pairs whose side of `δ_prox` the motion cannot have changed gives the
    /// proximity set of running GJK on every pair, update after update, with bodies creeping
    /// (reused) and jumping (re-tested) by turns.
    #[test]
    fn reused_distances_give_the_set_of_testing_every_pair() {
        let home = grid(0.0, 0.05);
        let mut cols = home.clone();
        let radius = 0.02 * 2f64.sqrt();
        let mut odometer = vec![0.0; cols.len()];
        let mut poses: Vec<Pose> = (0..cols.len()).map(|_| Pose::new(0.0, 0.0, 0.0)).collect();
        let mut fast = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        let mut every: BroadPhase;
        let (mut out_fast, mut out_every) = (Vec::new(), Vec::new());
        let mut reused = 0;
        for k in 0..60u64 {
            // Every third update some bodies jump by up to 3 cm; otherwise all creep by 1 µm.
            for i in 1..cols.len() {
                let h = (i as u64 * 2654435761 + k * 40503) % 1000;
                let step = if k % 3 == 2 && h < 300 { 0.03 } else { 1e-6 };
                let u = h as f64 / 1000.0 - 0.5;
                let last = poses[i];
                let p = Pose::new(
                    last.pos.x + step * u,
                    last.pos.y - step * u.abs(),
                    last.angle + step * u,
                );
                odometer[i] += (p.pos - last.pos).length() + (p.angle - last.angle).abs() * radius;
                poses[i] = p;
                let h0 = home[i].world_vertices()[0] - home[i].local.vertices()[0];
                cols[i].update(&Pose::new(h0.x + p.pos.x, h0.y + p.pos.y, p.angle));
            }
            fast.update_with_motion(&cols, &odometer, &mut out_fast);
            // A new stage each time: GJK on every pair and the full path.
            every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
            every.update(&cols, &mut out_every);
            assert_eq!(out_fast, out_every, "update {k}");
            assert_eq!(fast.stats().aabb_pairs, every.stats().aabb_pairs);
            assert_eq!(every.stats().reused_distances, 0);
            reused += fast.stats().reused_distances;
        }
        assert!(reused > 1000, "reused {reused}");
    }

    /// An update whose pairs differ from the published ones merges the published pairs it met
    /// again with the new ones: every pair keeps its own GJK result. Bodies jump between updates,
    /// so pairs leave, join and stay; without odometers every pair runs GJK (warm-started from
    /// its own cache), so each distance must be what a new stage computes for that pair now.
    #[test]
    fn a_merged_update_keeps_each_pair_with_its_own_distance() {
        let home = grid(0.0, 0.05);
        let mut cols = home.clone();
        let mut warm = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        let (mut out_warm, mut out_cold) = (Vec::new(), Vec::new());
        let (mut left, mut joined) = (0, 0);
        let mut last: Vec<(u32, u32)> = Vec::new();
        for k in 0..40u64 {
            for i in 1..cols.len() {
                let h = (i as u64 * 2654435761 + k * 40503) % 1000;
                let u = h as f64 / 1000.0 - 0.5;
                let step = if h < 200 { 0.03 } else { 0.0 };
                let h0 = home[i].world_vertices()[0] - home[i].local.vertices()[0];
                let p = h0 + Vec2::new(step * u, -step * u.abs());
                cols[i].update(&Pose::new(p.x, p.y, step * u));
            }
            warm.update(&cols, &mut out_warm);
            let mut cold = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
            cold.update(&cols, &mut out_cold);
            assert_eq!(out_warm, out_cold, "update {k}");
            let ((pw, dw), (pc, dc)) = (warm.tested_pairs(), cold.tested_pairs());
            assert_eq!(pw, pc, "update {k}");
            for ((p, a), b) in pw.iter().zip(dw).zip(dc) {
                assert!(
                    (a - b).abs() <= 1e-12,
                    "update {k}, pair {p:?}: {a} against {b}"
                );
            }
            left += last.iter().filter(|p| pw.binary_search(p).is_err()).count();
            joined += pw.iter().filter(|p| last.binary_search(p).is_err()).count();
            last = pw.to_vec();
        }
        assert!(left > 100 && joined > 100, "left {left}, joined {joined}");
    }

    /// An update that tests exactly the published pairs writes its few GJK results into the
    /// published arrays in place (`BroadStats::in_place`) and publishes what a full sort would:
    /// at rest (whole and spread), with a pair re-measured on the same side of `δ_prox` and one
    /// that crosses it. A pair leaving the AABB test while every other is reused (a body drifting
    /// away diagonally, farther than `δ_prox` throughout), or a new pair, takes the full path.
    #[test]
    fn an_update_testing_the_published_pairs_patches_them_in_place() {
        // Body 1 near body 2 (10 mm: proximate); body 3 diagonal to body 1, 38 mm gaps in x and
        // y: the boxes overlap (inflated by 21 mm each) but the squares are 53.7 mm apart.
        let mut cols = vec![
            square(0, false, 0.0, -1.0),
            square(1, true, 0.0, 0.0),
            square(2, true, -0.05, 0.0),
            square(3, true, 0.078, 0.078),
        ];
        let mut odometer = vec![0.0; 4];
        let mut fast = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        // The oracle: a new stage each time (no published pairs, so always the full path).
        let mut every: BroadPhase;
        let (mut out, mut out_every) = (Vec::new(), Vec::new());
        fast.update_with_motion(&cols, &odometer, &mut out);
        assert!(!fast.stats().in_place);
        let (pairs0, dist0) = (
            fast.tested_pairs().0.to_vec(),
            fast.tested_pairs().1.to_vec(),
        );
        assert_eq!(out, vec![(1, 2)]);
        assert_eq!(pairs0, vec![(1, 2), (1, 3)]);
        // At rest: in place with nothing to write, whole and spread.
        for spread in [false, true] {
            let mut o = vec![(7, 8)];
            if spread {
                fast.begin_with_motion(&cols, &odometer);
                fast.advance(3);
                fast.advance(2);
                fast.publish(&mut o);
            } else {
                fast.update_with_motion(&cols, &odometer, &mut o);
            }
            let st = fast.stats();
            assert!(st.in_place, "spread {spread}");
            assert_eq!(
                (st.aabb_pairs, st.proximate_pairs, st.gjk_iterations),
                (2, 1, 0)
            );
            assert_eq!(o, out);
            assert_eq!(fast.tested_pairs().0, pairs0.as_slice());
            assert_eq!(fast.tested_pairs().1, dist0.as_slice());
        }
        // Body 2 goes 20 mm away and 15 mm back (odometer +35 mm): its pair needs GJK and stays
        // proximate; body 3's keeps its distance.
        cols[2].update(&Pose::new(-0.055, 0.0, 0.0));
        odometer[2] += 0.035;
        fast.update_with_motion(&cols, &odometer, &mut out);
        every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        every.update(&cols, &mut out_every);
        assert!(fast.stats().in_place && fast.stats().gjk_iterations > 0);
        assert_eq!(out, out_every);
        assert_eq!(fast.tested_pairs().0, pairs0.as_slice());
        assert_eq!(fast.tested_pairs().1[0], every.tested_pairs().1[0]);
        assert_eq!(fast.tested_pairs().1[1], dist0[1]);
        // Body 3 comes 13 mm closer on both axes (35.4 mm apart): its pair crosses into the set.
        cols[3].update(&Pose::new(0.065, 0.065, 0.0));
        odometer[3] += 0.013 * 2f64.sqrt();
        fast.update_with_motion(&cols, &odometer, &mut out);
        every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        every.update(&cols, &mut out_every);
        assert!(fast.stats().in_place);
        assert_eq!(out, vec![(1, 2), (1, 3)]);
        assert_eq!(out, out_every);
        assert_eq!(fast.tested_pairs(), every.tested_pairs());
        // Body 3 drifts away diagonally in 1 mm steps until its box leaves body 1's: that update
        // must take the full path.
        let (mut left, mut patched) = (false, 0);
        for k in 1..=20 {
            let x = 0.065 + 0.001 * k as f64;
            cols[3].update(&Pose::new(x, x, 0.0));
            odometer[3] += 0.001 * 2f64.sqrt();
            fast.update_with_motion(&cols, &odometer, &mut out);
            every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
            every.update(&cols, &mut out_every);
            assert_eq!(out, out_every, "step {k}");
            assert_eq!(fast.tested_pairs().0, every.tested_pairs().0, "step {k}");
            assert_eq!(fast.stats().proximate_pairs, out.len());
            let dropped = fast.stats().aabb_pairs < 2;
            if dropped && !left {
                assert!(!fast.stats().in_place, "step {k}: a pair left");
            }
            patched += fast.stats().in_place as usize;
            left |= dropped;
        }
        assert!(left, "body 3's box left body 1's");
        assert!(patched > 10, "{patched} updates in place");
        // A new pair (body 2 jumps 5 mm above body 3): the full path.
        cols[2].update(&Pose::new(0.085, 0.13, 0.0));
        odometer[2] += 0.2;
        fast.update_with_motion(&cols, &odometer, &mut out);
        every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        every.update(&cols, &mut out_every);
        assert!(!fast.stats().in_place);
        assert_eq!(out, out_every);
        assert_eq!(fast.tested_pairs(), every.tested_pairs());
    }

    /// The sweep's insertion sort gives the order of a full sort, on nearly sorted input (the
    /// last update's order) and on shuffled input (past its move budget), ties on `min.x` too.
    #[test]
    fn sweep_sort_matches_a_full_sort() {
        let mut seed = 12345u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for (n, jitter) in [(0, 0.0), (1, 0.0), (50, 0.01), (1000, 0.002), (1000, 10.0)] {
            let mut sweep: Vec<SweepEntry> = (0..n)
                .map(|i| {
                    let x = (i / 2) as f64 * 0.05 + jitter * next();
                    SweepEntry {
                        min_x: if i % 7 == 0 { 0.5 } else { x },
                        max_x: x + 0.1,
                        min_y: 0.0,
                        max_y: 0.1,
                        index: i as u32,
                        body: (i as u32) << 1 | 1,
                    }
                })
                .collect();
            let mut full = sweep.clone();
            full.sort_unstable_by(sweep_order);
            sort_sweep(&mut sweep);
            let order = |v: &[SweepEntry]| v.iter().map(|e| e.index).collect::<Vec<_>>();
            assert_eq!(order(&sweep), order(&full), "n {n}, jitter {jitter}");
        }
    }

    /// `still_exact` is sound: whenever it says the published set still holds, a new stage run
    /// on the moved colliders computes that very set. Seeded random scenes: 24 rectangles of
    /// 1–8 cm, a quarter of them fixed, some sharing a body, in a square of 0.3–3 m (dense scenes
    /// are bound by the paired pairs' slack, sparse ones by the unpaired boxes' gap), published
    /// once, then moved by up to a random scale from 1 µm to 3 cm and checked against a fresh
    /// update. Half the trials move every body straight towards the middle by the whole scale
    /// (pairs close at up to twice the scale, the bound's worst case); the others move them at
    /// random, with a rotation.
    #[test]
    fn a_still_exact_set_is_what_an_update_now_computes() {
        let mut next = uniform(0x9e37_79b9_7f4a_7c15u64);
        let (mut held, mut changed, mut failed_same) = (0, 0, 0);
        let (mut gap_bound, mut tight) = (0, 0);
        for trial in 0..2000 {
            let (n, bodies) = (24, 20);
            let side = 0.3 * 10f64.powf(next());
            let mut poses = Vec::new();
            let mut cols = Vec::new();
            for i in 0..n {
                let body = if i < bodies { i } else { i - bodies };
                let dynamic = body % 4 != 0;
                let (w, h) = (0.01 + 0.07 * next(), 0.01 + 0.07 * next());
                let pose = Pose::new(side * next(), side * next(), 6.0 * next());
                let shape = ConvexPolygon::rectangle(w, h).unwrap();
                cols.push(Collider::new(body, dynamic, shape, &pose));
                poses.push(pose);
            }
            let odometer = vec![0.0; bodies];
            let mut stage = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
            let mut published = Vec::new();
            stage.update_with_motion(&cols, &odometer, &mut published);
            // (Unmoved it holds unless a pair sits within the guard of δ_prox.)
            let c = stage.certificate.expect("an update with a certificate");
            assert_eq!(
                stage.still_exact(&cols),
                c.gap > 0.0 && c.slack > 0.0,
                "{trial}"
            );
            gap_bound += (c.gap < c.slack) as usize;
            // One scale per trial, 1 µm to 3 cm (log-uniform).
            let scale = 1e-6 * (3e4f64).powf(next());
            let inward = trial % 2 == 0;
            let mut moves = Vec::new();
            for b in 0..bodies {
                let p = poses
                    .iter()
                    .zip(&cols)
                    .find(|(_, c)| c.body == b)
                    .unwrap()
                    .0;
                moves.push(if inward {
                    // Straight to the middle by the whole scale (a body off its origin only
                    // translates, so every vertex moves by exactly `scale`).
                    let to = Vec2::new(0.5 * side, 0.5 * side) - p.pos;
                    let d = to * (scale / to.length().max(1e-12));
                    (d.x, d.y, 0.0)
                } else {
                    let u = |x: f64| scale * (2.0 * x - 1.0);
                    (u(next()), u(next()), 20.0 * u(next()))
                });
            }
            for (c, p) in cols.iter_mut().zip(&poses) {
                let (dx, dy, da) = moves[c.body];
                c.update(&Pose::new(p.pos.x + dx, p.pos.y + dy, p.angle + da));
            }
            let mut fresh = Vec::new();
            BroadPhase::new(DEFAULT_DELTA_PROX)
                .unwrap()
                .update(&cols, &mut fresh);
            let exact = stage.still_exact(&cols);
            if exact {
                held += 1;
                tight += (4.0 * scale > c.gap.min(c.slack)) as usize;
                assert_eq!(
                    fresh, published,
                    "{trial}: still_exact, but the set changed"
                );
            } else if fresh == published {
                failed_same += 1;
            } else {
                changed += 1;
            }
        }
        assert!(
            held > 500 && changed > 200 && gap_bound > 100 && tight > 50,
            "held {held} ({tight} with the motion past half the bound), changed {changed}, \
             neither {failed_same}, bound by the gap {gap_bound}"
        );
    }

    /// The gap in y counts: a column of boxes 1 cm farther apart than `δ_prox` (their inflated
    /// boxes overlap in x and are 1 cm apart in y, so the sweep tests them in y and pairs none).
    /// Moving each box 4 mm towards the middle one keeps the set (empty) exact; 6 mm brings
    /// neighbours within `δ_prox`, and the certificate must fail.
    #[test]
    fn the_gap_between_unpaired_boxes_in_y_bounds_the_motion() {
        let pitch = 0.04 + DEFAULT_DELTA_PROX + 0.01;
        let place = |shift: f64| -> Vec<Collider> {
            (0..5)
                .map(|i| {
                    let y = pitch * i as f64;
                    let toward = (2.0 * pitch - y).signum() * shift;
                    square(i, true, 0.0, y + toward)
                })
                .collect()
        };
        let mut stage = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        let mut set = Vec::new();
        stage.update_with_motion(&place(0.0), &[0.0; 5], &mut set);
        assert!(set.is_empty());
        assert!((stage.certificate.unwrap().gap - 0.01).abs() < 1e-12);
        assert!(stage.still_exact(&place(0.004)));
        let near = place(0.006);
        assert!(!stage.still_exact(&near));
        let mut fresh = Vec::new();
        BroadPhase::new(DEFAULT_DELTA_PROX)
            .unwrap()
            .update(&near, &mut fresh);
        assert!(!fresh.is_empty(), "the moved boxes are within δ_prox");
    }

    /// After a failed check the next updates compute no certificate (1, then 2, 4, … up to
    /// `MAX_BACKOFF`), and a check that holds resets the backoff.
    #[test]
    fn a_failed_check_backs_off() {
        let home: Vec<Collider> = (0..3)
            .map(|i| square(i, true, 0.2 * i as f64, 0.0))
            .collect();
        let mut moved = home.clone();
        moved[1].update(&Pose::new(0.3, 0.0, 0.0)); // 10 cm: past the certificate (gaps 11.8 cm)
        let mut stage = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        let mut set = Vec::new();
        let update = |stage: &mut BroadPhase, cols: &[Collider], set: &mut Vec<(u32, u32)>| {
            stage.update_with_motion(cols, &[0.0; 3], set);
        };
        update(&mut stage, &home, &mut set);
        assert!(stage.skip_update(&home), "unmoved");
        // Fail once: the next update has no certificate.
        assert!(!stage.skip_update(&moved));
        update(&mut stage, &home, &mut set);
        assert!(
            !stage.skip_update(&home),
            "no certificate while backing off"
        );
        // The one after has one again; failing now waits two updates.
        update(&mut stage, &home, &mut set);
        assert!(!stage.skip_update(&moved));
        for _ in 0..2 {
            update(&mut stage, &home, &mut set);
            assert!(!stage.skip_update(&home), "backing off");
        }
        update(&mut stage, &home, &mut set);
        assert!(stage.skip_update(&home), "certified again");
        assert_eq!((stage.backoff, stage.wait), (0, 0));
        // The backoff stops growing at MAX_BACKOFF.
        for _ in 0..20 {
            stage.backoff = MAX_BACKOFF;
            update(&mut stage, &home, &mut set);
            stage.wait = 0;
        }
        update(&mut stage, &home, &mut set);
        assert!(!stage.skip_update(&moved));
        assert_eq!(stage.wait, MAX_BACKOFF);
    }
}
