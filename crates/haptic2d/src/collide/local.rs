//! The local stage (§9.3–9.5): closest-feature tracking and vertex–edge (VE) candidates for every
//! proximate pair, every control sample.
//!
//! # VE candidates
//!
//! Every contact is a vertex of one polygon against an edge of the other (§0.4), with signed
//! distance `d = n·(V − E0)` and edge coordinate `s = t·(V − E0)`; a candidate is recorded only if
//! `−ε_s ≤ s ≤ L + ε_s`. For a pair `(A, B)` the tracker (§9.3) gives either the closest features or
//! "penetrating":
//!
//! - **Separated, distance ≤ δ_c** (§9.5):
//!   - vertex–edge `(V_A, E_B)`: one candidate;
//!   - vertex–vertex `(V_A, V_B)`: two candidates `(V_A, E_B*)` and `(V_B, E_A*)`, where `E_B*` is
//!     the edge incident to `V_B` whose outward normal is most aligned with `V_A − V_B`, i.e. the
//!     one with the larger `d = n·(V_A − V_B)` (both edges pass through `V_B`); same on A;
//!   - parallel edge–edge: the overlap interval of the two edges (in B's edge coordinate) has two
//!     ends; each is a vertex of A inside `[0, L_B]` or else B's edge end, which then lies inside A's
//!     edge: `(that vertex, the other polygon's edge)`.
//!
//!   **Near-parallel faces** (addition to §9.5): a box resting "flat" is never exactly flat in
//!   floating point, so the tracker usually reports vertex–edge for it, which alone would give one
//!   corner. Before the rules above, each edge incident to A's closest feature is therefore tried
//!   against each edge incident to B's: if the two are antiparallel within [`NEAR_PARALLEL_ANGLE`]
//!   and their overlap is longer than `ε_s` with *both* ends within `δ_c`, the pair is handled as a
//!   parallel edge–edge case (two candidates). This is exact for exactly parallel edges and keeps
//!   the count at 2 for a box tilted by round-off.
//! - **Penetrating** (§9.4): every vertex `V` of A that is inside B or within `δ_c` of it, i.e.
//!   `max_j d_j(V) ≤ δ_c` over B's edges `j`, gives one candidate with the edge of least
//!   penetration depth (largest `d_j`) among the edges whose range contains `V`; the same for B's
//!   vertices against A. The contact manager (§8.3) picks the edge of a *new* contact by the
//!   god-object crossing rule and keeps the edge of an existing one; it only needs every touching
//!   vertex to be proposed. The same scan runs for a pair reported apart at a distance below GJK's
//!   `ε_abs` (1e-9 m): there "apart" is round-off (see below).
//!
//!   **Corner on corner** (addition to §9.4): when `V` is within `δ_c` of the lines of two adjacent
//!   edges of B (it sits at B's corner `W`), least depth is decided by round-off: for equal boxes
//!   stacked exactly, `V` is `~1e-4 m` below the top line and `±1e-19 m` from the side line. The
//!   edge is then chosen by orientation only ([`corner_facing_edge`]): the one antiparallel, within
//!   [`NEAR_PARALLEL_ANGLE`], to an edge of A at `V` (the faces in contact), if exactly one is.
//!   Such stacks also overlap with every vertex exactly on the other box's edge lines, so no
//!   vertex is strictly inside and the walk certifies "apart" at ~1e-20 m: hence the vertex scan
//!   below `ε_abs`.
//!
//!   **Crossing corners** (addition, issue 35, §9.5b): a penetrating pair with no vertex strictly
//!   inside the other polygon (corners crossed through each other's edges) whose separating-axis
//!   overlap exceeds `CLIP_MARGIN·δ_c` gets its reference face's clip pairs (`clip.rs`) instead
//!   (not flagged as the vertex scan's: they are not nearest lines). The contact manager starts
//!   them with their surface at the vertex (`create.rs`, found inside).
//!
//! The rules live in [`candidates`](super::candidates), one file per query; this file keeps the
//! pair bookkeeping (the tracked pairs, their gaps and reuse, the four update entry points).
//! Candidates are sorted and deduplicated so that everything downstream is deterministic.

use super::candidates::{Ctx, Side};
use super::reuse::{PairCandidates, Slack, SLOT};
use super::tracker::{ClosestFeatures, Feature, FeatureTracker, TrackStatus};
use super::{Collider, VeCandidate};
use crate::geom::{Pose, Vec2};

/// Default contact distance tolerance `δ_c` (m), §9.5.
pub const DEFAULT_DELTA_C: f64 = 0.002;
/// Default edge-range tolerance `ε_s` (m), §0.4.
pub const DEFAULT_EPS_S: f64 = 1e-4;
/// Largest angle between two edges (rad, from antiparallel) that the near-parallel face rule treats
/// as one face contact. A box of length `L` has both corners within `δ_c` only up to a tilt of
/// `δ_c/L` (0.05 rad for 4 cm), so this only keeps short edges (polygonal circles) out of the rule.
pub const NEAR_PARALLEL_ANGLE: f64 = 0.1;

/// The tracker result of one proximate pair at the last update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairState {
    /// Collider indices `(a, b)`, `a < b`.
    pub pair: (u32, u32),
    /// Closest features (or penetration) of the pair.
    pub features: ClosestFeatures,
}

impl PairState {
    /// The state of a pair not tracked yet: separated at infinite distance.
    fn untracked(pair: (u32, u32)) -> Self {
        Self {
            pair,
            features: ClosestFeatures {
                status: TrackStatus::Separated,
                feature_a: Feature::Vertex(0),
                feature_b: Feature::Vertex(0),
                point_a: Vec2::ZERO,
                point_b: Vec2::ZERO,
                distance: f64::INFINITY,
                parallel: false,
                iterations: 0,
                used_gjk: false,
            },
        }
    }
}

/// Local stage: one closest-feature tracker per proximate pair, and VE candidate generation.
#[derive(Clone, Debug)]
pub struct LocalStage {
    eps_s: f64,
    cos_parallel: f64,
    pairs: Vec<(u32, u32)>,
    trackers: Vec<FeatureTracker>,
    /// The certified gap of each pair at its last tracked sample (see [`Gap`]).
    gaps: Vec<Gap>,
    states: Vec<PairState>,
    old_pairs: Vec<(u32, u32)>,
    old_trackers: Vec<FeatureTracker>,
    old_gaps: Vec<Gap>,
    old_states: Vec<PairState>,
    /// Each pair's candidates at its last tracked sample (a reused scan's while it is reused,
    /// see [`Gap::reused`]).
    candidates: Vec<PairCandidates>,
    old_candidates: Vec<PairCandidates>,
    /// `δ_c` of the reused scans (a change drops them).
    reused_delta_c: f64,
    /// Pairs whose tracking the last update skipped (their gap still held).
    skipped: usize,
    /// Penetrating pairs whose vertex scan the last update reused (`reuse.rs`).
    reused: usize,
    /// The output of the last update, sorted and deduplicated, and whether it is assembled from
    /// the current pairs' candidates (false after the pair list changed).
    sorted: Vec<VeCandidate>,
    assembled: bool,
    /// This update's tracked pairs' candidates, and the ranges of the pairs with more than a
    /// slot holds (with their `from_scan` flag).
    fresh: Vec<VeCandidate>,
    overflow: Vec<(u32, u32, bool)>,
    /// Scratch of the candidate sort (each candidate with its `from_scan` flag).
    sort_buf: Vec<(VeCandidate, bool)>,
    bucket: Vec<u32>,
    /// For each candidate of the last update (in output order), whether the vertex scan proposed
    /// it (see [`LocalStage::from_vertex_scan`]).
    from_scan: Vec<bool>,
    /// Always rebuild the pair list whole (tests compare the two ways).
    full_rebuild: bool,
}

/// Changed pairs (dropped plus new) up to which [`LocalStage::rebuild`] splices the middle of the
/// list in place, at least; an eighth of the list otherwise.
const SPLICE_LIMIT: usize = 64;

/// The certified distance of a separated pair when it was last tracked, and the two bodies'
/// relative pose then: the distance between a point of A and a point of B changes by at most
/// the relative motion `m = |ΔP_A − ΔP_B|₁ + |Δθ_A|·l_a + |Δθ_B|·l_b` (body origins `P`, net
/// rotations `Δθ`, each polygon's vertex radius `l` about its body's origin; a common translation
/// of both bodies changes nothing). While `m` is less than that distance less `δ_c`, the pair is
/// still farther apart than `δ_c` and has no candidate, so its tracking can wait. `δ_c` is the
/// one of the sample that checks, so a tolerance changed at run time counts at once.
///
/// A penetrating pair's vertex scan is reused the same way (`reused`, see `reuse.rs`): while
/// `m < clear − δ_c`, with `clear = σ + δ_c` of the scan and the levers `l` of its lines.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Gap {
    /// `distance − GAP_GUARD` at the last tracked sample (m); 0 = track every sample.
    clear: f64,
    /// `P_A − P_B` (m) and the bodies' angles (rad) then.
    rel: Vec2,
    angle_a: f64,
    angle_b: f64,
    /// How far a unit rotation of each body moves the pair's compared quantities (m/rad).
    l_a: f64,
    l_b: f64,
    /// The pair's bodies (`u32::MAX` for a collider that does not exist), kept here so that a
    /// skipped pair reads nothing but this record.
    body_a: u32,
    body_b: u32,
    /// The tracker's penetration flag after its last update (a copy, read every sample).
    penetrating: bool,
    /// The pair's state is the tracker's confirmed penetration (see
    /// [`FeatureTracker::confirm_penetration`]): confirming it again only moves the reported
    /// point, so the tracker is not touched.
    confirmed: bool,
    /// The pair's last vertex scan is reused while the gap holds (its candidates are kept).
    reused: bool,
}

impl Gap {
    /// A pair of bodies `body_a`, `body_b` to track at the next sample.
    fn track(body_a: u32, body_b: u32) -> Gap {
        Gap {
            clear: 0.0,
            rel: Vec2::ZERO,
            angle_a: 0.0,
            angle_b: 0.0,
            l_a: 0.0,
            l_b: 0.0,
            body_a,
            body_b,
            penetrating: false,
            confirmed: false,
            reused: false,
        }
    }
}

/// Kept off every certified gap (m): the tracker's distance is exact up to round-off, this
/// absorbs that and the rounding of the poses and slacks.
const GAP_GUARD: f64 = 1e-6;

/// The pose of the two bodies of a pair when it is tracked: `P_A − P_B` and the angles (NaN when
/// a body has no pose, so that nothing is skipped).
#[derive(Clone, Copy, Debug)]
struct RelPose {
    rel: Vec2,
    angle_a: f64,
    angle_b: f64,
}

impl RelPose {
    fn of(poses: &[Pose], body_a: u32, body_b: u32) -> RelPose {
        match (poses.get(body_a as usize), poses.get(body_b as usize)) {
            (Some(a), Some(b)) => RelPose::between(a, b),
            _ => RelPose {
                rel: Vec2::splat(f64::NAN),
                angle_a: f64::NAN,
                angle_b: f64::NAN,
            },
        }
    }

    /// The relative pose of two bodies with poses `a`, `b`.
    #[inline(always)]
    fn between(a: &Pose, b: &Pose) -> RelPose {
        RelPose {
            rel: a.pos - b.pos,
            angle_a: a.angle,
            angle_b: b.angle,
        }
    }

    /// The relative motion bound `m` of [`Gap`] since `g` was certified (m; NaN if unknown).
    #[inline]
    fn moved_since(&self, g: &Gap) -> f64 {
        let d = self.rel - g.rel;
        d.x.abs()
            + d.y.abs()
            + (self.angle_a - g.angle_a).abs() * g.l_a
            + (self.angle_b - g.angle_b).abs() * g.l_b
    }
}

impl Gap {
    /// Whether the gap still holds at the bodies' poses `poses` for contact distance `delta_c`
    /// (m): `m < clear − δ_c`. False when a body has no pose (`RelPose::of`'s NaN motion).
    #[inline(always)]
    fn holds(&self, poses: &[Pose], delta_c: f64) -> bool {
        match (
            poses.get(self.body_a as usize),
            poses.get(self.body_b as usize),
        ) {
            (Some(a), Some(b)) => RelPose::between(a, b).moved_since(self) < self.clear - delta_c,
            _ => false,
        }
    }
}

/// The first of `gaps` at or after `from` that does not [hold](Gap::holds) (`gaps.len()` if
/// none), with how many before it held and how many of those were reused scans. A loop of its
/// own: a settled pile skips most of its pairs, and this keeps their test to the gap record and
/// the two poses, away from the tracking code's registers.
#[inline(never)]
fn first_unheld(gaps: &[Gap], from: usize, poses: &[Pose], delta_c: f64) -> (usize, usize, usize) {
    let (mut held, mut reused) = (0usize, 0usize);
    for (k, g) in gaps.iter().enumerate().skip(from) {
        if !g.holds(poses, delta_c) {
            return (k, held, reused);
        }
        held += 1;
        reused += usize::from(g.reused);
    }
    (gaps.len(), held, reused)
}

impl Default for LocalStage {
    fn default() -> Self {
        Self::new()
    }
}

impl LocalStage {
    /// An empty local stage with `ε_s` = [`DEFAULT_EPS_S`].
    pub fn new() -> Self {
        Self {
            eps_s: DEFAULT_EPS_S,
            cos_parallel: NEAR_PARALLEL_ANGLE.cos(),
            pairs: Vec::new(),
            trackers: Vec::new(),
            gaps: Vec::new(),
            states: Vec::new(),
            old_pairs: Vec::new(),
            old_trackers: Vec::new(),
            old_gaps: Vec::new(),
            old_states: Vec::new(),
            candidates: Vec::new(),
            old_candidates: Vec::new(),
            reused_delta_c: DEFAULT_DELTA_C,
            skipped: 0,
            reused: 0,
            sorted: Vec::new(),
            assembled: false,
            fresh: Vec::new(),
            overflow: Vec::new(),
            sort_buf: Vec::new(),
            bucket: Vec::new(),
            from_scan: Vec::new(),
            full_rebuild: false,
        }
    }

    /// A local stage with room for `pairs` proximate pairs, so that pair lists up to that size never
    /// allocate (the pair and tracker buffers are double-buffered across global updates).
    pub fn with_capacity(pairs: usize) -> Self {
        let mut s = Self::new();
        s.pairs.reserve(pairs);
        s.trackers.reserve(pairs);
        s.gaps.reserve(pairs);
        s.states.reserve(pairs);
        s.old_pairs.reserve(pairs);
        s.old_trackers.reserve(pairs);
        s.old_gaps.reserve(pairs);
        s.old_states.reserve(pairs);
        s.candidates.reserve(pairs);
        s.old_candidates.reserve(pairs);
        s.sorted.reserve(2 * pairs);
        s.fresh.reserve(2 * pairs);
        s.sort_buf.reserve(2 * pairs);
        s.from_scan.reserve(2 * pairs);
        s
    }

    /// Sets the edge-range tolerance `ε_s` (m, finite, ≥ 0).
    pub fn set_edge_tolerance(&mut self, eps_s: f64) -> Result<(), String> {
        if !(eps_s.is_finite() && eps_s >= 0.0) {
            return Err(format!(
                "eps_s (edge-range tolerance) must be a finite distance ≥ 0 m, got {eps_s}"
            ));
        }
        if eps_s != self.eps_s {
            self.drop_reused_scans();
        }
        self.eps_s = eps_s;
        Ok(())
    }

    /// The edge-range tolerance `ε_s` (m).
    pub fn edge_tolerance(&self) -> f64 {
        self.eps_s
    }

    /// The proximate pairs currently tracked (sorted as given to [`LocalStage::update`]).
    pub fn pairs(&self) -> &[(u32, u32)] {
        &self.pairs
    }

    /// Tracker results, one per pair, in pair order: of the last update that tracked the pair
    /// (a pair skipped by [`update_with_motion`](Self::update_with_motion) keeps its last
    /// features; a pair never tracked, e.g. one naming a collider that does not exist, reads
    /// separated at infinite distance).
    pub fn pair_states(&self) -> &[PairState] {
        &self.states
    }

    /// Pairs whose tracking the last update skipped because their certified gap still held.
    pub fn skipped(&self) -> usize {
        self.skipped
    }

    /// Penetrating pairs whose vertex scan the last update reused because their bodies had not
    /// moved enough to change any of its comparisons (the candidates are those a scan would give;
    /// the pair's reported point is the scan's).
    pub fn reused(&self) -> usize {
        self.reused
    }

    /// For each candidate of the last update (parallel to its output), whether it came from the
    /// vertex scan (§9.4, fresh or reused): its edge is then its vertex's nearest edge line, or
    /// the corner-on-corner rule's edge within `δ_c` of it, computed from the colliders' world
    /// features of this sample. A contact record with that key satisfies the depth invariant
    /// (`d_e ≥ max_j d_j − δ_c`, see [`ContactSet::step`](crate::contact::ContactSet::step))
    /// exactly as the contact manager would compute it, so its hand-over check can be skipped.
    pub fn from_vertex_scan(&self) -> &[bool] {
        &self.from_scan
    }

    /// Drops every reused vertex scan: the next update scans those pairs again.
    fn drop_reused_scans(&mut self) {
        for g in self.gaps.iter_mut().filter(|g| g.reused) {
            *g = Gap {
                penetrating: g.penetrating,
                confirmed: g.confirmed,
                ..Gap::track(g.body_a, g.body_b)
            };
        }
    }

    /// The trackers (with their work counters), in pair order. A pair that stays penetrating is
    /// confirmed once (counted in its tracker's `updates`); the samples after that only move the
    /// reported point and are not counted.
    pub fn trackers(&self) -> &[FeatureTracker] {
        &self.trackers
    }

    /// Replaces the pair list, keeping the trackers of pairs that persist (capacity is reused).
    fn rebuild(&mut self, pairs: &[(u32, u32)], colliders: &[Collider]) {
        // Both lists are sorted. Between global updates they usually differ by a few pairs: the
        // common head and tail stay where they are and only the middle is merged and spliced in,
        // instead of copying every pair's state (about 1.5 MB at 1000 bodies: a deadline spike).
        let (n_old, n_new) = (self.pairs.len(), pairs.len());
        let head = self
            .pairs
            .iter()
            .zip(pairs)
            .take_while(|(a, b)| a == b)
            .count();
        let tail = self.pairs[head..]
            .iter()
            .rev()
            .zip(pairs[head..].iter().rev())
            .take_while(|(a, b)| a == b)
            .count();
        let (old_mid, new_mid) = (head..n_old - tail, head..n_new - tail);
        if !self.full_rebuild && old_mid.len() + new_mid.len() <= SPLICE_LIMIT.max(n_new / 8) {
            self.splice(old_mid, &pairs[new_mid], colliders);
            return;
        }
        std::mem::swap(&mut self.pairs, &mut self.old_pairs);
        std::mem::swap(&mut self.trackers, &mut self.old_trackers);
        std::mem::swap(&mut self.gaps, &mut self.old_gaps);
        std::mem::swap(&mut self.states, &mut self.old_states);
        std::mem::swap(&mut self.candidates, &mut self.old_candidates);
        self.assembled = false;
        self.pairs.clear();
        self.trackers.clear();
        self.gaps.clear();
        self.states.clear();
        self.candidates.clear();
        // One merge keeps the trackers (and gaps) of pairs that persist.
        let mut k = 0;
        for &p in pairs {
            let (t, g, st, r) = self.kept_or_new(p, &mut k, self.old_pairs.len(), colliders);
            self.pairs.push(p);
            self.trackers.push(t);
            self.gaps.push(g);
            self.states.push(st);
            self.candidates.push(r);
        }
    }

    /// Pair `p`'s state from the old buffers' first `end` entries (sorted; `k` is the merge
    /// position, advanced past the pairs before `p`), or a new pair's if it is not there.
    fn kept_or_new(
        &self,
        p: (u32, u32),
        k: &mut usize,
        end: usize,
        colliders: &[Collider],
    ) -> (FeatureTracker, Gap, PairState, PairCandidates) {
        while *k < end && self.old_pairs[*k] < p {
            *k += 1;
        }
        if *k < end && self.old_pairs[*k] == p {
            (
                self.old_trackers[*k],
                self.old_gaps[*k],
                self.old_states[*k],
                self.old_candidates[*k],
            )
        } else {
            Self::untracked(p, colliders)
        }
    }

    /// The state of a pair new to the list: not tracked yet, no candidates.
    fn untracked(
        p: (u32, u32),
        colliders: &[Collider],
    ) -> (FeatureTracker, Gap, PairState, PairCandidates) {
        let body = |c: u32| {
            colliders
                .get(c as usize)
                .map_or(u32::MAX, |c| c.body as u32)
        };
        (
            FeatureTracker::new(),
            Gap::track(body(p.0), body(p.1)),
            PairState::untracked(p),
            PairCandidates::EMPTY,
        )
    }

    /// [`rebuild`](Self::rebuild) of the pairs `old_mid` (positions in the current list) replaced
    /// by `new_mid` (sorted, between the same neighbours): the old middle moves to the `old_*`
    /// buffers, the merged middle is appended after it there and spliced in. The output needs
    /// assembling again only if a dropped pair had candidates (a new pair has none yet).
    fn splice(
        &mut self,
        old_mid: std::ops::Range<usize>,
        new_mid: &[(u32, u32)],
        colliders: &[Collider],
    ) {
        let m = old_mid.len();
        self.old_pairs.clear();
        self.old_trackers.clear();
        self.old_gaps.clear();
        self.old_states.clear();
        self.old_candidates.clear();
        self.old_pairs
            .extend_from_slice(&self.pairs[old_mid.clone()]);
        self.old_trackers
            .extend_from_slice(&self.trackers[old_mid.clone()]);
        self.old_gaps.extend_from_slice(&self.gaps[old_mid.clone()]);
        self.old_states
            .extend_from_slice(&self.states[old_mid.clone()]);
        self.old_candidates
            .extend_from_slice(&self.candidates[old_mid.clone()]);
        let mut k = 0;
        for &p in new_mid {
            let (t, g, st, r) = self.kept_or_new(p, &mut k, m, colliders);
            self.old_pairs.push(p);
            self.old_trackers.push(t);
            self.old_gaps.push(g);
            self.old_states.push(st);
            self.old_candidates.push(r);
        }
        // A dropped pair had candidates: the kept pairs keep theirs and the new ones have none.
        let dropped_candidates = self.old_candidates[..m]
            .iter()
            .filter(|c| **c != PairCandidates::EMPTY)
            .count()
            > self.old_candidates[m..]
                .iter()
                .filter(|c| **c != PairCandidates::EMPTY)
                .count();
        if dropped_candidates {
            self.assembled = false;
        }
        self.pairs
            .splice(old_mid.clone(), self.old_pairs[m..].iter().copied());
        self.trackers
            .splice(old_mid.clone(), self.old_trackers[m..].iter().copied());
        self.gaps
            .splice(old_mid.clone(), self.old_gaps[m..].iter().copied());
        self.states
            .splice(old_mid.clone(), self.old_states[m..].iter().copied());
        self.candidates
            .splice(old_mid, self.old_candidates[m..].iter().copied());
    }

    /// Tracks every proximate pair `pairs` (sorted `(a, b)` collider indices, `a < b`, as produced
    /// by the global stage) and writes the VE candidates with contact distance tolerance `delta_c`
    /// (m) into `out` (cleared first), sorted and deduplicated. Pairs naming a collider outside
    /// `colliders` are skipped. No allocation once the buffers have grown.
    pub fn update(
        &mut self,
        colliders: &[Collider],
        pairs: &[(u32, u32)],
        delta_c: f64,
        out: &mut Vec<VeCandidate>,
    ) {
        self.update_with_motion(colliders, pairs, delta_c, &[], out);
    }

    /// [`update`](Self::update), skipping the tracking of separated pairs that cannot have come
    /// within `delta_c` since they were last tracked, given the bodies' poses `poses` (indexed
    /// by body; the colliders' world features must be those of these poses). A pair last
    /// tracked at distance `D` is skipped while its bodies' relative motion since (`m` of the
    /// private `Gap`: relative translation plus each body's rotation times its polygon's
    /// radius) is less than `D − δ_c` (less a guard): its distance is then still above `δ_c`,
    /// where it has no candidate, so the candidates are those of tracking every pair. Its
    /// tracker and [`PairState`] keep their last features. A penetrating pair's vertex scan is
    /// reused the same way ([`reused`](Self::reused), `reuse.rs`). An empty `poses` (or one
    /// shorter than the bodies) tracks every pair.
    pub fn update_with_motion(
        &mut self,
        colliders: &[Collider],
        pairs: &[(u32, u32)],
        delta_c: f64,
        poses: &[Pose],
        out: &mut Vec<VeCandidate>,
    ) {
        self.update_in_place(colliders, pairs, delta_c, poses);
        out.clone_from(&self.sorted);
    }

    /// [`update_with_motion`](Self::update_with_motion) without copying the candidates out:
    /// they are [`candidates`](Self::candidates) until the next update (the world's tick reads
    /// them there, instead of copying them every sample).
    pub fn update_in_place(
        &mut self,
        colliders: &[Collider],
        pairs: &[(u32, u32)],
        delta_c: f64,
        poses: &[Pose],
    ) {
        self.update_known_pairs(colliders, pairs, true, delta_c, poses);
    }

    /// [`update_in_place`](Self::update_in_place) for a caller that knows whether `pairs` may
    /// differ from the last update's: `pairs_may_differ = false` promises they are the same list
    /// (the world's tick between global updates), which skips comparing them (a pile:1000 has
    /// about 9 000 pairs, 70 kB read every sample for nothing). The promise is checked in debug
    /// builds.
    pub fn update_known_pairs(
        &mut self,
        colliders: &[Collider],
        pairs: &[(u32, u32)],
        pairs_may_differ: bool,
        delta_c: f64,
        poses: &[Pose],
    ) {
        debug_assert!(
            pairs_may_differ || self.pairs.as_slice() == pairs,
            "the pairs changed while the caller said they had not"
        );
        if pairs_may_differ && self.pairs.as_slice() != pairs {
            self.rebuild(pairs, colliders);
        }
        self.skipped = 0;
        self.reused = 0;
        if delta_c != self.reused_delta_c {
            self.drop_reused_scans();
            self.reused_delta_c = delta_c;
        }
        // The candidate sort's buckets are sized now, before any contact needs them.
        self.bucket.resize(colliders.len() + 1, 0);
        // Each tracked pair's candidates go to `fresh` and are compared with its last ones: the
        // sorted output is assembled again only if some pair's changed.
        let mut changed = !self.assembled;
        let mut fresh = std::mem::take(&mut self.fresh);
        fresh.clear();
        self.overflow.clear();
        let mut from = 0;
        loop {
            // Pairs whose gap certified at the last tracked sample still holds: nothing to do (a
            // reused scan's candidates are its last ones).
            let (k, held, reused) = first_unheld(&self.gaps[..pairs.len()], from, poses, delta_c);
            self.skipped += held - reused;
            self.reused += reused;
            let Some(&(ia, ib)) = pairs.get(k) else {
                break;
            };
            from = k + 1;
            let g = self.gaps[k];
            let now = RelPose::of(poses, g.body_a, g.body_b);
            let (Some(a), Some(b)) = (colliders.get(ia as usize), colliders.get(ib as usize))
            else {
                continue;
            };
            let mark = fresh.len();
            let scan = self.track(k, (ia, a), (ib, b), now, delta_c, &mut fresh);
            let found = &fresh[mark..];
            match PairCandidates::of(found, scan) {
                Some(c) => {
                    if self.candidates[k] != c {
                        self.candidates[k] = c;
                        changed = true;
                    }
                }
                None => {
                    self.candidates[k] = PairCandidates::OVERFLOW;
                    self.overflow.push((mark as u32, fresh.len() as u32, scan));
                    changed = true;
                }
            }
        }
        if changed {
            self.assemble(&fresh, colliders.len());
        }
        self.fresh = fresh;
    }

    /// The VE candidates of the last update, sorted and deduplicated (what
    /// [`update_with_motion`](Self::update_with_motion) copies out).
    pub fn candidates(&self) -> &[VeCandidate] {
        &self.sorted
    }

    /// The sorted, deduplicated candidates of every pair (`sorted`, with `from_scan`), from the
    /// pairs' last candidates and this update's overflowing ones (ranges of `fresh`).
    fn assemble(&mut self, fresh: &[VeCandidate], colliders: usize) {
        self.sorted.clear();
        self.from_scan.clear();
        // Most pairs have none (`get` is empty for an overflowing pair too): they cost a test.
        for c in &self.candidates {
            let found = c.get();
            if found.is_empty() {
                continue;
            }
            self.sorted.extend_from_slice(found);
            self.from_scan.resize(self.sorted.len(), c.scan);
        }
        for &(start, end, scan) in &self.overflow {
            self.sorted
                .extend_from_slice(&fresh[start as usize..end as usize]);
            self.from_scan.resize(self.sorted.len(), scan);
        }
        sort_dedup(
            &mut self.sorted,
            &mut self.from_scan,
            &mut self.sort_buf,
            &mut self.bucket,
            colliders,
        );
        self.assembled = true;
    }

    /// Tracks pair `k` (colliders `a`, `b` with their indices; the bodies' relative pose `now`)
    /// and pushes its VE candidates to `out`. Returns whether they are the vertex scan's (§9.4).
    fn track(
        &mut self,
        k: usize,
        (ia, a): (u32, &Collider),
        (ib, b): (u32, &Collider),
        now: RelPose,
        delta_c: f64,
        out: &mut Vec<VeCandidate>,
    ) -> bool {
        let g = self.gaps[k];
        let ctx = Ctx {
            delta_c,
            eps_s: self.eps_s,
            cos_parallel: self.cos_parallel,
        };
        let (sa, sb) = (Side { id: ia, c: a }, Side { id: ib, c: b });
        // A pair that was penetrating and still has a vertex strictly inside the other polygon is
        // still penetrating: its candidates are exactly the vertex scan (§9.4), and the closest-
        // feature walk/GJK is skipped (resting contacts, e.g. a pile, stay on this path).
        if g.penetrating {
            let mark = out.len();
            let mut slack = Slack::new();
            let inside_a = ctx.vertices_against(sa, sb, out, &mut slack);
            let inside_b = ctx.vertices_against(sb, sa, out, &mut slack);
            if let Some(at) = inside_a.or(inside_b) {
                if g.confirmed {
                    // What `confirm_penetration` would return again, but for the point.
                    let f = &mut self.states[k].features;
                    (f.point_a, f.point_b) = (at, at);
                    // The scan is reused while the bodies cannot have changed it.
                    let cert = slack.certificate(a, b, delta_c, self.eps_s, GAP_GUARD);
                    let fits = out.len() - mark <= SLOT;
                    self.gaps[k] = match cert {
                        Some((sigma, l_a, l_b)) if fits => Gap {
                            clear: sigma + delta_c,
                            rel: now.rel,
                            angle_a: now.angle_a,
                            angle_b: now.angle_b,
                            l_a,
                            l_b,
                            reused: true,
                            ..g
                        },
                        _ => Gap {
                            clear: 0.0,
                            reused: false,
                            ..g
                        },
                    };
                    return true;
                }
                let f = self.trackers[k].confirm_penetration(at);
                self.states[k] = PairState {
                    pair: (ia, ib),
                    features: f,
                };
                self.gaps[k] = Gap {
                    penetrating: self.trackers[k].is_penetrating(),
                    confirmed: true,
                    ..Gap::track(g.body_a, g.body_b)
                };
                return true;
            }
            out.truncate(mark);
        }
        // Closest features (§9.3).
        let f = self.trackers[k].update(a, b);
        self.states[k] = PairState {
            pair: (ia, ib),
            features: f,
        };
        // A pair apart from a piece with `across` seams by less than their reach can have a
        // vertex across one (in the piece under it), held by the piece's surfaces: scanned
        // every sample.
        let under = (a.across | b.across) != 0
            && f.status == TrackStatus::Separated
            && f.distance <= a.max_reach().max(b.max_reach())
            && (a.beyond_across(&b.aabb) || b.beyond_across(&a.aabb));
        // A separated pair farther than δ_c may wait until its bodies have moved its gap.
        self.gaps[k] = match f.status {
            TrackStatus::Separated if f.distance > delta_c + GAP_GUARD && !under => Gap {
                clear: f.distance - GAP_GUARD,
                rel: now.rel,
                angle_a: now.angle_a,
                angle_b: now.angle_b,
                l_a: a.local.radius(),
                l_b: b.local.radius(),
                ..Gap::track(g.body_a, g.body_b)
            },
            _ => Gap::track(g.body_a, g.body_b),
        };
        self.gaps[k].penetrating = self.trackers[k].is_penetrating();
        // VE candidates (§9.4–9.5).
        ctx.candidates(sa, sb, &f, under, out)
    }
}

/// Sorts and deduplicates `out` (the candidates of one update) with their flags `flag`
/// (parallel; a key proposed twice keeps the flag only if both had it): a counting sort by vertex
/// collider into `buf` (each collider's candidates are a handful), then an insertion sort of
/// each bucket. The same order as `sort_unstable` + `dedup` (keys are plain integers), in
/// `O(n + colliders)`. `bucket` is scratch of `colliders + 1` starts.
fn sort_dedup(
    out: &mut Vec<VeCandidate>,
    flag: &mut Vec<bool>,
    buf: &mut Vec<(VeCandidate, bool)>,
    bucket: &mut Vec<u32>,
    colliders: usize,
) {
    debug_assert_eq!(out.len(), flag.len());
    if out.len() < 2 {
        return;
    }
    // Candidates come only from pairs whose colliders exist (`update_with_motion` skips others).
    debug_assert!(out.iter().all(|c| (c.vertex_collider as usize) < colliders));
    bucket.clear();
    bucket.resize(colliders + 1, 0); // no allocation: sized by the caller
    for c in out.iter() {
        bucket[c.vertex_collider as usize + 1] += 1;
    }
    for i in 1..bucket.len() {
        bucket[i] += bucket[i - 1];
    }
    buf.clear();
    buf.resize(out.len(), (out[0], false));
    for (&c, &f) in out.iter().zip(flag.iter()) {
        let at = &mut bucket[c.vertex_collider as usize];
        buf[*at as usize] = (c, f);
        *at += 1;
    }
    // `bucket[i]` is now the end of collider i's run (and the start of i + 1's).
    out.clear();
    flag.clear();
    let mut start = 0usize;
    for &end in bucket.iter().take(colliders) {
        let run = &mut buf[start..end as usize];
        if run.len() > 32 {
            run.sort_unstable();
        } else {
            for i in 1..run.len() {
                let mut j = i;
                while j > 0 && run[j - 1] > run[j] {
                    run.swap(j - 1, j);
                    j -= 1;
                }
            }
        }
        for &(c, f) in run.iter() {
            if out.last() == Some(&c) {
                // A key proposed twice keeps the flag only if both proposals had it.
                let last = flag.last_mut().expect("parallel to out");
                *last = *last && f;
            } else {
                out.push(c);
                flag.push(f);
            }
        }
        start = end as usize;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{ConvexPolygon, Pose};

    /// Splicing the changed middle of the pair list gives the pair states, trackers, gaps,
    /// candidates and output of rebuilding the whole list: random edits of a random pair list
    /// (a few pairs, or many) of squares that touch, overlap and drift, 40 seeds.
    #[test]
    fn splicing_the_pair_list_gives_the_whole_rebuild() {
        use rand::{Rng, SeedableRng};
        for seed in 0..40u64 {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let n = 14;
            let mut poses: Vec<Pose> = (0..n)
                .map(|i| {
                    Pose::new(
                        0.045 * (i % 5) as f64 + rng.random_range(-0.004..0.004),
                        0.045 * (i / 5) as f64 + rng.random_range(-0.004..0.004),
                        rng.random_range(-0.2..0.2),
                    )
                })
                .collect();
            let mut cols: Vec<Collider> = poses
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    Collider::new(i, i > 0, ConvexPolygon::rectangle(0.05, 0.05).unwrap(), p)
                })
                .collect();
            let all: Vec<(u32, u32)> = (0..n as u32)
                .flat_map(|a| (a + 1..n as u32).map(move |b| (a, b)))
                .collect();
            let mut on: Vec<bool> = all.iter().map(|_| rng.random_bool(0.5)).collect();
            let (mut fast, mut whole) = (LocalStage::new(), LocalStage::new());
            whole.full_rebuild = true;
            let (mut out_fast, mut out_whole) = (Vec::new(), Vec::new());
            let mut spliced = 0;
            for k in 0..60 {
                let flips = if k % 10 == 9 {
                    40
                } else {
                    rng.random_range(0..4)
                };
                for _ in 0..flips {
                    let i = rng.random_range(0..all.len());
                    on[i] = !on[i];
                }
                let pairs: Vec<(u32, u32)> = all
                    .iter()
                    .zip(&on)
                    .filter(|(_, o)| **o)
                    .map(|(p, _)| *p)
                    .collect();
                for (i, p) in poses.iter_mut().enumerate().skip(1) {
                    *p = Pose::new(
                        p.pos.x + rng.random_range(-3e-4..3e-4),
                        p.pos.y + rng.random_range(-3e-4..3e-4),
                        p.angle + rng.random_range(-5e-3..5e-3),
                    );
                    cols[i].update(p);
                }
                if fast.pairs != pairs {
                    fast.rebuild(&pairs, &cols);
                    whole.rebuild(&pairs, &cols);
                    spliced += fast.assembled as usize;
                }
                fast.update_with_motion(&cols, &pairs, DEFAULT_DELTA_C, &poses, &mut out_fast);
                whole.update_with_motion(&cols, &pairs, DEFAULT_DELTA_C, &poses, &mut out_whole);
                assert_eq!(out_fast, out_whole, "seed {seed} update {k}");
                assert_eq!(fast.from_scan, whole.from_scan, "seed {seed} update {k}");
                assert_eq!(fast.pairs, whole.pairs);
                assert_eq!(fast.trackers, whole.trackers, "seed {seed} update {k}");
                assert_eq!(fast.gaps, whole.gaps, "seed {seed} update {k}");
                assert_eq!(fast.states, whole.states, "seed {seed} update {k}");
                assert_eq!(fast.candidates, whole.candidates, "seed {seed} update {k}");
            }
            assert!(
                spliced > 0,
                "seed {seed}: some splices kept the assembled output"
            );
        }
    }

    /// The held-pair scan stops at exactly the pairs whose gap fails the per-pair test
    /// (`RelPose::of(..).moved_since(g) < g.clear − δ_c`, what every pair used to run) and
    /// counts the held ones between, reused scans apart: random gaps against random poses, with
    /// bodies without a pose (`u32::MAX` too), gaps of 0 (tracked every sample), NaN poses and
    /// certificates rounded onto their threshold, 200 seeds.
    #[test]
    fn held_pair_scan_stops_where_the_per_pair_test_fails() {
        use rand::{Rng, SeedableRng};
        let delta_c = DEFAULT_DELTA_C;
        let (mut held_total, mut on_edge) = (0, 0);
        for seed in 0..200u64 {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let mut r = |lo: f64, hi: f64| rng.random_range(lo..hi);
            let mut poses: Vec<Pose> = (0..10)
                .map(|_| Pose::new(r(-0.1, 0.1), r(-0.1, 0.1), r(-1.0, 1.0)))
                .collect();
            poses[9].pos.x = f64::NAN;
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed + 1000);
            let mut gaps = Vec::new();
            for _ in 0..rng.random_range(0..60) {
                let body = |rng: &mut rand_chacha::ChaCha8Rng| match rng.random_range(0..24) {
                    0 => u32::MAX,
                    k => k % 12,
                };
                let (ba, bb) = (body(&mut rng), body(&mut rng));
                let mut g = Gap::track(ba, bb);
                g.reused = rng.random_bool(0.3);
                if rng.random_bool(0.9) {
                    // Certified at poses near the current ones.
                    let old = RelPose::of(&poses, ba, bb);
                    g.rel = old.rel + Vec2::new(rng.random_range(-1e-3..1e-3), 0.0);
                    g.angle_a = old.angle_a + rng.random_range(-1e-3..1e-3);
                    g.angle_b = old.angle_b;
                    (g.l_a, g.l_b) = (rng.random_range(0.0..0.05), rng.random_range(0.0..0.05));
                    // NaN for a body without a pose: then any clear.
                    let m = old.moved_since(&g);
                    let edge = if m.is_nan() { 0.005 } else { m + delta_c };
                    g.clear = match rng.random_range(0..3) {
                        0 => edge,
                        1 => rng.random_range(0.0..2.0 * edge),
                        _ => edge.next_down(),
                    };
                }
                gaps.push(g);
            }
            let (mut want, mut held, mut reused) = (Vec::new(), 0, 0);
            for (k, g) in gaps.iter().enumerate() {
                let m = RelPose::of(&poses, g.body_a, g.body_b).moved_since(g);
                on_edge += usize::from(m == g.clear - delta_c);
                if m < g.clear - delta_c {
                    held += 1;
                    reused += usize::from(g.reused);
                } else {
                    want.push((k, held, reused));
                    (held, reused) = (0, 0);
                }
            }
            want.push((gaps.len(), held, reused));
            let mut got = Vec::new();
            let mut from = 0;
            while from <= gaps.len() {
                let (k, h, r) = first_unheld(&gaps, from, &poses, delta_c);
                got.push((k, h, r));
                held_total += h;
                from = k + 1;
            }
            assert_eq!(got, want, "seed {seed}");
        }
        assert!(
            held_total > 500 && on_edge > 20,
            "{held_total} held, {on_edge} on the edge"
        );
    }

    /// A pair that stays penetrating is confirmed by its tracker once; the samples after that
    /// report the same states (the point moving) and candidates as confirming every sample.
    #[test]
    fn confirmed_penetration_reports_what_confirming_again_would() {
        let square = |body, dynamic, pose: &Pose| {
            Collider::new(
                body,
                dynamic,
                ConvexPolygon::rectangle(0.05, 0.05).unwrap(),
                pose,
            )
        };
        let mut cols = vec![
            square(0, false, &Pose::new(0.0, 0.0, 0.0)),
            square(1, true, &Pose::new(0.01, 0.049, 0.02)),
        ];
        let pairs = [(0u32, 1u32)];
        let (mut fast, mut every) = (LocalStage::new(), LocalStage::new());
        let (mut out_fast, mut out_every) = (Vec::new(), Vec::new());
        for k in 0..20 {
            let pose = Pose::new(0.01 + 1e-4 * k as f64, 0.049 - 2e-5 * k as f64, 0.02);
            cols[1].update(&pose);
            for g in every.gaps.iter_mut() {
                g.confirmed = false;
            }
            fast.update(&cols, &pairs, DEFAULT_DELTA_C, &mut out_fast);
            every.update(&cols, &pairs, DEFAULT_DELTA_C, &mut out_every);
            assert_eq!(fast.pair_states(), every.pair_states(), "sample {k}");
            assert_eq!(out_fast, out_every, "sample {k}");
            assert!(!out_fast.is_empty());
            assert_eq!(
                fast.pair_states()[0].features.status,
                TrackStatus::Penetrating
            );
        }
        assert!(fast.gaps[0].confirmed);
        // The first sample walks, the second confirms; the rest do not touch the tracker.
        assert_eq!(fast.trackers()[0].stats.updates, 2);
        assert_eq!(every.trackers()[0].stats.updates, 20);
    }
}
