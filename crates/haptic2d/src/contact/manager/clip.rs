//! Stage 4b of the contact step (issue 35, crossing corners; docs/MODELS.md §9.5b): a pair whose
//! separating-axis overlap runs deeper than its deepest record is held on its reference face.
//!
//! Where corners cross, each polygon's corner can sit on a *side* face of the other: the records'
//! normals are nearly perpendicular to the load and antagonistic, they hold none of it, and the
//! bodies sink into each other (`stack-5-polygons-interpenetrate.toml`), while every vertex stays
//! within a few millimetres of some line of the other polygon. When a pair's overlap `D`
//! ([`sat_face`]) exceeds the depth of its deepest record by more than [`CLIP_MARGIN`]·`δ_c`, its
//! clip pairs ([`clip_pairs`]: Box2D's reference-face clipping as vertex–edge pairs) become
//! Continuous records:
//!
//! - a vertex with a record on another edge of the same polygon is **handed over** to its clip
//!   edge with its law's effective depth kept: the new law's surface offset is
//!   `σ' = max(0, δ' − (δ − σ))` (`δ`, `δ'` the depths on the old and new edge, `σ` the old
//!   offset), so the spring pushes as hard as before, now along the separating axis, and stores
//!   `½·K·(δ' − σ')² ≤ ½·K·(δ − σ)²`: never more than before;
//! - a vertex without a record takes the largest effective depth left in the **pool** (capped at
//!   its own depth): the effective depths of the pair's records released in this sample because
//!   their vertex left the edge's range (`release.rs`), each used once. When such a record was
//!   deeper than every record the pair has left, the pair's support went with it, and the stage
//!   acts at once, whatever the margin (a box tilting on a stacked corner);
//! - otherwise it starts with its surface at the vertex (`σ' = δ'`): it stores nothing at
//!   creation and resists any further sinking (as the records found inside a seam piece,
//!   `create.rs`).
//!
//! After the switch each record is an ordinary VE spring `½·K·(δ' − σ')²` on a fixed key, a
//! function of the poses whose offset only shrinks where the spring is slack, so the stage adds
//! no energy (at a switch the new law's input depth is that of an energy the pair stored at the
//! start of the sample, or zero, so `E_stored` never rises there; the friction state starts at
//! zero, which drops its spring energy). The overlap that was there stays (its energy was already
//! dissipated where the records lost it); from then on the pair is supported along its separating
//! axis like a face on a face, so it does not grow by more than the springs' compression under
//! the load. Every clip pair is no deeper than `D` (see `collide/clip.rs`), so the records satisfy
//! the depth invariant's overlap bound and the hand-over stage keeps them.
//!
//! **Cost.** Every sample each record is tested against the overlap of the two polygons along its
//! own normal (`O(n)`, the deepest vertex of the vertex polygon behind its edge line): the pair's
//! overlap is no more than that, so a record for which it is within the margin of the record's
//! own depth clears its pair, and the separating-axis test runs only for the pairs none of whose
//! records clears it. The own-axis test depends on the two bodies' relative angle only, so it is
//! remembered per record and recomputed only when the angle has turned enough that the answer
//! could change (`own_axis_clears`): on a pile at rest, almost never. (On a piece with seams the
//! record's normal clears the pair only if it is an admissible axis: a body sunk into the joint of
//! a floor and a wall slab has its one record on the slab's corner, whose normal would move the
//! body out through the joint; such pairs recompute every sample.)

use super::sync::new_entry;
use super::PastPoses;
use super::{release_record, start_continuous, ContactSet};
use crate::body::Body;
use crate::collide::{admissible_axis, clip_pairs, sat_face, Collider, VeCandidate, CLIP_MARGIN};
use crate::contact::record::{ContactEvent, ContactState, VeContact};
use crate::laws::friction::FrictionModel;
use crate::laws::normal::NormalModel;

/// The own-axis test of a record (module docs): the overlap of the two polygons along the
/// record's normal is within `margin` (m) of the record's own depth, on an admissible axis (a
/// seam's piece is cleared through its surface only, `sat_depth`); then the pair's overlap is too.
///
/// The excess `max_v n·(V_rec − v)` over the vertices `v` of A depends on the relative angle
/// `φ = θ_A − θ_B` only (`n` is B's edge normal and `V_rec − v` a vector of A's, so the dot
/// product is `R(−φ)·n_B · (V_rec − v)_A`), and it changes by at most `|Δφ|·|V_rec − v| ≤
/// |Δφ|·2·r_A` (`r_A` A's vertex radius) when `φ` does. For a pair without seams the test is
/// remembered (`VeContact::own_axis`) and recomputed only once that bound, plus rounding
/// allowances far above the computation's own (1e-9 m per metre of position, 1e-15 rad per radian
/// of angle), could reach the margin: the answer is the one the full test gives. (The colliders'
/// world features are those of the bodies' poses here: both are updated at step 3a, and nothing
/// in the contact stage moves a body.)
///
/// The remembered answer is inlined into the stage's loop; the recomputation, rare on a pile at
/// rest, is a call ([`own_axis_recompute`]).
#[inline(always)]
fn own_axis_clears(
    e: &mut VeContact,
    colliders: &[Collider],
    bodies: &[Body],
    margin: f64,
) -> bool {
    // The remembered answer reads the record and the two bodies' poses only (the record's bodies
    // are its colliders' bodies, `A` the vertex's). It is remembered only for a pair without
    // seams, so a pair with seams holds NaN, which fails the comparison, as does "not yet".
    let (pa, pb) = (&bodies[e.body_a].pose, &bodies[e.body_b].pose);
    let phi = pa.angle - pb.angle;
    let (phi0, excess0, radius) = e.own_axis;
    let rounding = 1e-9 * (1.0 + pa.pos.x.abs() + pa.pos.y.abs() + pb.pos.x.abs() + pb.pos.y.abs());
    let turned = (phi - phi0).abs() + 1e-15 * (pa.angle.abs() + pb.angle.abs() + phi0.abs());
    if excess0 + turned * 2.0 * radius + rounding <= margin {
        return true;
    }
    let ca = &colliders[e.key.vertex_collider as usize];
    let cb = &colliders[e.key.edge_collider as usize];
    debug_assert_eq!((e.body_a, e.body_b), (ca.body, cb.body));
    let plain = ca.seams == 0 && cb.seams == 0;
    own_axis_recompute(e, ca, cb, phi, plain, margin)
}

/// The own-axis test computed in full ([`own_axis_clears`]) at relative angle `phi` (rad),
/// remembered in the record when the pair has no seams (`plain`).
#[inline(never)]
fn own_axis_recompute(
    e: &mut VeContact,
    ca: &Collider,
    cb: &Collider,
    phi: f64,
    plain: bool,
    margin: f64,
) -> bool {
    let edge = e.key.edge as usize;
    let along = ca
        .world_vertices()
        .iter()
        .map(|&v| -cb.edge_distance(edge, v))
        .fold(f64::NEG_INFINITY, f64::max);
    if plain {
        e.own_axis = (phi, along + e.d[0], ca.local.radius());
    }
    along <= -e.d[0] + margin && !cb.is_seam(edge) && admissible_axis(ca, cb, e.n)
}

/// Sets (or clears) the mark of both colliders of each pair.
fn mark_pairs(mark: &mut [bool], pairs: &[(u32, u32)], to: bool) {
    for &(a, b) in pairs {
        mark[a as usize] = to;
        mark[b as usize] = to;
    }
}

/// The index of `pair` in the sorted, deduplicated `crossing`, as its binary search finds it;
/// `marked` holds exactly the colliders of `crossing`'s pairs, so a pair with an unmarked
/// collider is in none and skips the search. On a landing pile most records belong to no
/// crossing pair, and the search was about half the stage's instructions (docs/PERFORMANCE.md,
/// session 29).
#[inline]
fn crossing_index(crossing: &[(u32, u32)], marked: &[bool], pair: (u32, u32)) -> Option<usize> {
    if !(marked[pair.0 as usize] && marked[pair.1 as usize]) {
        return None;
    }
    crossing.binary_search(&pair).ok()
}

impl ContactSet {
    /// Holds every pair whose overlap exceeds its deepest record's depth by more than
    /// `CLIP_MARGIN·δ_c` on its reference face (module docs). Runs after `create`, before the
    /// impacts; a pair with a Colliding record waits for its impact.
    pub(super) fn clip_crossing(
        &mut self,
        tick: u64,
        colliders: &[Collider],
        bodies: &[Body],
        past: &PastPoses<'_>,
        normal: &NormalModel,
        friction: &FrictionModel,
    ) {
        let margin = CLIP_MARGIN * self.delta_c;
        let clears = |e: &mut VeContact| own_axis_clears(e, colliders, bodies, margin);
        let pair_of = |key: &VeCandidate| {
            let (a, b) = (key.vertex_collider, key.edge_collider);
            (a.min(b), a.max(b))
        };
        // Pairs (a < b) with a record whose own-axis test fails, and those that lost a loaded
        // record out of its edge range this sample (`release`).
        self.crossing.clear();
        for e in self.entries.iter_mut().filter(|e| e.is_contact()) {
            if !clears(e) {
                self.crossing.push(pair_of(&e.key));
            }
        }
        for &(pair, _) in &self.dropped {
            self.crossing.push(pair);
        }
        if self.crossing.is_empty() {
            return;
        }
        self.crossing.sort_unstable();
        self.crossing.dedup();
        // Each such pair's records, in one pass: deepest depth, any Colliding, any that clears it.
        self.crossing_info.clear();
        self.crossing_info
            .resize(self.crossing.len(), (0.0, false, false));
        if self.crossing_mark.len() < colliders.len() {
            self.crossing_mark.resize(colliders.len(), false);
        }
        mark_pairs(&mut self.crossing_mark, &self.crossing, true);
        for e in self.entries.iter_mut().filter(|e| e.is_contact()) {
            if let Some(k) = crossing_index(&self.crossing, &self.crossing_mark, pair_of(&e.key)) {
                let info = &mut self.crossing_info[k];
                info.0 = info.0.max(-e.d[0]);
                info.1 |= e.state == Some(ContactState::Colliding);
                info.2 = info.2 || clears(e);
            }
        }
        mark_pairs(&mut self.crossing_mark, &self.crossing, false);
        self.pending.clear();
        for k in 0..self.crossing.len() {
            let (ia, ib) = self.crossing[k];
            let (deepest, colliding, cleared) = self.crossing_info[k];
            if colliding {
                continue;
            }
            // A loaded record that left its edge's range deeper than every record left: the
            // pair's support went with it, and its depth goes to the clip records at once.
            let dropped = self
                .dropped
                .iter()
                .filter(|(pair, _)| *pair == (ia, ib))
                .fold(0.0f64, |m, &(_, d)| m.max(d));
            if cleared && dropped <= deepest {
                continue;
            }
            let (a, b) = (&colliders[ia as usize], &colliders[ib as usize]);
            let Some(face) = sat_face(a, b) else {
                continue;
            };
            let lost = dropped > deepest && face.depth > deepest;
            if !face.admissible || (face.depth <= deepest + margin && !lost) {
                continue;
            }
            self.clip_keys.clear();
            clip_pairs(
                (ia, a),
                (ib, b),
                &face,
                self.params.eps_s,
                &mut self.clip_keys,
            );
            if self.clip_keys.is_empty() {
                continue;
            }
            self.take_dropped_pool((ia, ib));
            // The clip pairs deepest first.
            let geo = |key: &VeCandidate| {
                let ca = &colliders[key.vertex_collider as usize];
                let cb = &colliders[key.edge_collider as usize];
                cb.edge_distance(key.edge as usize, ca.world_vertices()[key.vertex as usize])
            };
            self.clip_keys.sort_by(|x, y| geo(x).total_cmp(&geo(y)));
            for c in 0..self.clip_keys.len() {
                let key = self.clip_keys[c];
                self.hold(tick, key, colliders, bodies, past, normal, friction);
            }
        }
        self.dropped.clear();
        if !self.pending.is_empty() {
            self.entries.extend_from_slice(&self.pending);
            self.entries.sort_unstable_by_key(|e| e.key);
            self.pending.clear();
        }
    }

    /// Fills the pool with the effective depths (m) of `pair`'s records released out of their
    /// edge range this sample, largest last (popped first), and takes them out of `dropped`.
    fn take_dropped_pool(&mut self, pair: (u32, u32)) {
        self.pool.clear();
        for &(p, depth) in &self.dropped {
            if p == pair {
                self.pool.push(depth);
            }
        }
        self.dropped.retain(|&(p, _)| p != pair);
        self.pool.sort_unstable_by(f64::total_cmp);
    }

    /// Makes the clip pair `key` a Continuous record (module docs): nothing if it is one; the
    /// vertex's record on another edge of the same collider is handed over with its effective
    /// depth; otherwise a record whose law starts at the largest effective depth left in the pool
    /// (capped at its own depth), or with its surface at the vertex when the pool is empty.
    #[allow(clippy::too_many_arguments)]
    fn hold(
        &mut self,
        tick: u64,
        key: VeCandidate,
        colliders: &[Collider],
        bodies: &[Body],
        past: &PastPoses<'_>,
        normal: &NormalModel,
        friction: &FrictionModel,
    ) {
        let group = |x: &VeCandidate| {
            (x.vertex_collider, x.vertex, x.edge_collider)
                == (key.vertex_collider, key.vertex, key.edge_collider)
        };
        if self
            .entries
            .iter()
            .chain(&self.pending)
            .any(|e| e.key == key && e.is_contact())
        {
            return;
        }
        let kept = if let Some(old) = self
            .entries
            .iter()
            .position(|e| group(&e.key) && e.is_contact())
        {
            let e = &self.entries[old];
            if e.state != Some(ContactState::Continuous) {
                return;
            }
            let offset = self.laws.get(e.law).map_or(0.0, |l| l.normal.offset());
            let kept = (-e.d[0] - offset).max(0.0);
            let e = &mut self.entries[old];
            release_record(e, &mut self.laws, &mut self.events, tick);
            kept
        } else {
            self.pool.pop().unwrap_or(0.0)
        };
        let start = |n: &mut VeContact,
                     laws: &mut crate::contact::law_pool::LawPool,
                     events: &mut Vec<ContactEvent>| {
            start_continuous(n, tick, events);
            n.law = laws.acquire(normal, friction, n.s_g);
            // Offset σ' = δ' − kept (the law's depth history shifted by it, `impact_offset.rs`).
            let depth = (-n.d[0]).max(0.0);
            laws.impact_resolved(n.law, [-depth, -kept.min(depth), 0.0], 2);
        };
        match self.entries.binary_search_by(|x| x.key.cmp(&key)) {
            Ok(t) => {
                let n = &mut self.entries[t];
                start(n, &mut self.laws, &mut self.events);
            }
            Err(_) => {
                let mut n = new_entry(tick, key, colliders, bodies, past);
                start(&mut n, &mut self.laws, &mut self.events);
                self.pending.push(n);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{crossing_index, mark_pairs, own_axis_clears};
    use crate::contact::manager::{box_on_floor, fresh_entry};
    use crate::geom::Pose;

    /// A 0.1 m box rocking and sliding on a floor, its bottom-right corner on the floor's top
    /// edge: over 20 000 seeded random motions (some in place) the remembered own-axis test answers
    /// exactly as the full test on a record that remembers nothing; both answers occur, and the
    /// remembered one is used after the box has turned.
    #[test]
    fn remembered_own_axis_test_answers_as_the_full_test() {
        let floor_pose = Pose::new(0.3, -0.1, 0.0);
        let (mut bodies, mut colliders, key) = box_on_floor(Pose::new(0.0, 0.048, 0.0), floor_pose);
        let margin = 1e-3;
        let mut remembered = fresh_entry(key, &colliders, &bodies);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
        };
        let (mut cleared, mut failed, mut reused) = (0, 0, 0);
        for _ in 0..20_000 {
            let pose = &mut bodies[0].pose;
            if uniform() > -0.5 {
                pose.angle = (pose.angle + 2e-3 * uniform()).clamp(-0.04, 0.04);
                pose.pos.x += 1e-3 * uniform();
                pose.pos.y = 0.048 + 1e-3 * uniform();
            }
            let pose = bodies[0].pose;
            colliders[0].update(&pose);
            let fresh = fresh_entry(key, &colliders, &bodies);
            remembered.d = fresh.d;
            let full = own_axis_clears(&mut fresh.clone(), &colliders, &bodies, margin);
            let answer = own_axis_clears(&mut remembered, &colliders, &bodies, margin);
            assert_eq!(answer, full, "at {pose:?}");
            if full {
                cleared += 1;
            } else {
                failed += 1;
            }
            // Not recomputed here: what it remembers is from another angle.
            if remembered.own_axis.0.to_bits() != (pose.angle - floor_pose.angle).to_bits() {
                reused += 1;
            }
        }
        assert!(
            cleared > 1000 && failed > 1000,
            "{cleared} cleared, {failed} failed"
        );
        assert!(
            reused > 1000,
            "the remembered answer was used {reused} times"
        );
    }

    /// Over 2 000 seeded random sets of crossing pairs among 40 colliders (sorted, deduplicated,
    /// a < b, as `clip_crossing` builds them), the marked search finds every one of 200 random
    /// pairs (half of them taken from the set) exactly where the plain binary search does; and
    /// the marks are all cleared afterwards.
    #[test]
    fn marked_crossing_search_finds_what_the_binary_search_finds() {
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let mut below = move |n: u64| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 33) % n) as u32
        };
        let mut marks = vec![false; 40];
        let (mut found, mut skipped) = (0, 0);
        for _ in 0..2_000 {
            let mut crossing: Vec<(u32, u32)> = (0..below(12))
                .map(|_| {
                    let (a, b) = (below(40), below(40));
                    (a.min(b), a.max(b))
                })
                .collect();
            crossing.sort_unstable();
            crossing.dedup();
            mark_pairs(&mut marks, &crossing, true);
            for i in 0..200 {
                let pair = if i % 2 == 0 && !crossing.is_empty() {
                    crossing[below(crossing.len() as u64) as usize]
                } else {
                    let (a, b) = (below(40), below(40));
                    (a.min(b), a.max(b))
                };
                let full = crossing.binary_search(&pair).ok();
                assert_eq!(
                    crossing_index(&crossing, &marks, pair),
                    full,
                    "{pair:?} in {crossing:?}"
                );
                found += usize::from(full.is_some());
                skipped += usize::from(!(marks[pair.0 as usize] && marks[pair.1 as usize]));
            }
            mark_pairs(&mut marks, &crossing, false);
            assert!(marks.iter().all(|&m| !m));
        }
        assert!(
            found > 100_000 && skipped > 50_000,
            "{found} found, {skipped} skipped"
        );
    }
}
