//! Stage 1 of the contact step (§0.5 step 4): merge the local stage's candidates into the tracked
//! set and re-measure every pair (distance and edge-coordinate histories, normal, tangent,
//! velocities). New entries get their history rebuilt from the past poses.

use super::ContactSet;
use super::PastPoses;
use crate::body::Body;
use crate::collide::{nearest_line, Collider, VeCandidate};
use crate::contact::record::{ContactState, LocalGeom, VeContact, NO_LAW};
use crate::geom::{Pose, Rot, Vec2};

/// What the stages after the merge may find to do this sample, as the merge's measuring pass
/// saw it: a stage whose flag is false would change nothing, so [`ContactSet::step`] skips its
/// pass over the records (on a pile at rest, all three). Each flag may be true without work;
/// it is false only when the stage's own tests fail for every entry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct StageWork {
    /// Some Continuous record meets the release or re-collision rule (`release`).
    pub release: bool,
    /// Some Continuous record that stays, not from this sample's vertex scan, has another line of
    /// its edge polygon nearer than its own by more than `δ_c` (`hand_over`, which also checks
    /// the face-on-face exception).
    pub hand_over: bool,
    /// Some tracked pair without a record, old or new, touches (`d ≤ δ_on`, in range; `create`
    /// also runs after any release or hand-over event).
    pub create: bool,
}

/// One difference between the tracked set and the candidates, found by the merge's walk
/// ([`ContactSet::sync`]), in order: positions are indices of the set before the merge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Change {
    /// Entry `i` is neither a candidate nor a record: it leaves the set.
    Drop(u32),
    /// Candidate `cand` (an index of the candidates) is new: it enters just before entry `at`
    /// (`at` = the set's length: at the end).
    Insert { at: u32, cand: u32 },
}

impl ContactSet {
    /// Merges the sorted candidates with the tracked set: existing entries are re-measured (history
    /// shifted), new candidates get a fresh entry whose history is rebuilt from the past poses, tracked
    /// pairs that are neither candidates nor records are dropped. Every entry's `nearest_edge` is
    /// its candidate's `from_scan` flag (parallel to `candidates`; false for a record that is not a
    /// candidate, or if `from_scan` is not parallel). Returns what the later stages may find to
    /// do ([`StageWork`]), seen in the same pass.
    ///
    /// One pass measures every entry and walks the candidates beside it, listing the differences
    /// ([`Change`]); the set is then changed in place, moving only the entries between changes
    /// (a candidate exchanged for another, the usual change on a settling pile, moves the
    /// entries between the two).
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    pub(super) fn sync(
        &mut self,
        tick: u64,
        candidates: &[VeCandidate],
        from_scan: &[bool],
        colliders: &[Collider],
        bodies: &[Body],
        rots: &[Rot],
        past: &PastPoses<'_>,
    ) -> StageWork {
        let flags = (from_scan.len() == candidates.len()).then_some(from_scan);
        let flag = |j: usize| flags.is_some_and(|f| f[j]);
        let p = self.params;
        let delta_c = self.delta_c;
        // `c0 < −v_re` of the re-collision rule, with −∞ when it is off (no `c0` is below it).
        let neg_v_re = recollision_floor(p.v_re.filter(|_| p.impacts));
        // One rotation per body: cut to the bodies' count, an index checked against `bodies`
        // needs no second check against `rots`.
        let rots = &rots[..bodies.len()];
        let mut work = StageWork::default();
        self.changes.clear();
        let mut j = 0;
        for (i, e) in self.entries.iter_mut().enumerate() {
            measure(e, bodies, rots);
            while j < candidates.len() && candidates[j] < e.key {
                self.changes.push(Change::Insert {
                    at: i as u32,
                    cand: j as u32,
                });
                j += 1;
            }
            if j < candidates.len() && e.key == candidates[j] {
                e.nearest_edge = flag(j);
                j += 1;
            } else {
                e.nearest_edge = false;
                if !e.is_contact() {
                    self.changes.push(Change::Drop(i as u32));
                    continue;
                }
            }
            // The tests of `release`, `hand_over` and `create`, on this sample's measures.
            match e.state {
                Some(ContactState::Continuous) => {
                    if e.d[0] > p.delta_off || !in_range(e, colliders, p.eps_s) || e.c0 < neg_v_re {
                        work.release = true;
                    } else if !e.nearest_edge && !work.hand_over {
                        let cb = &colliders[e.key.edge_collider as usize];
                        work.hand_over = e.d[0] < nearest_line(cb, e.point).1 - delta_c;
                    }
                }
                Some(ContactState::Colliding) => {}
                None => work.create |= e.d[0] <= p.delta_on && in_range(e, colliders, p.eps_s),
            }
        }
        let len = self.entries.len() as u32;
        for j in j..candidates.len() {
            self.changes.push(Change::Insert {
                at: len,
                cand: j as u32,
            });
        }
        if !self.changes.is_empty() {
            self.apply_changes(tick, candidates, flags, colliders, bodies, past, &mut work);
        }
        work
    }

    /// Applies the merge's changes (`self.changes`) to the set in place ([`merge_in_place`]),
    /// the new entries measured from the poses.
    #[allow(clippy::too_many_arguments)]
    fn apply_changes(
        &mut self,
        tick: u64,
        candidates: &[VeCandidate],
        flags: Option<&[bool]>,
        colliders: &[Collider],
        bodies: &[Body],
        past: &PastPoses<'_>,
        work: &mut StageWork,
    ) {
        let p = self.params;
        merge_in_place(&mut self.entries, &self.changes, |cand| {
            let j = cand as usize;
            let e = new_entry(tick, candidates[j], colliders, bodies, past);
            work.create |= e.d[0] <= p.delta_on && in_range(&e, colliders, p.eps_s);
            VeContact {
                nearest_edge: flags.is_some_and(|f| f[j]),
                ..e
            }
        });
    }
}

/// The re-collision rule's floor on `c0` (m/s): `−v_re`, or −∞ without the rule, so that
/// `c0 < floor` is the rule's `c0 < −v_re` (false for every `c0`, NaN included, without it).
#[inline(always)]
fn recollision_floor(v_re: Option<f64>) -> f64 {
    v_re.map_or(f64::NEG_INFINITY, |v| -v)
}

/// Applies a merge's `changes` (in order, positions in `v` as it is) to `v` in place, with
/// `fill(cand)` the new element of an insertion. Only the runs between changes move, each by the
/// number of insertions less drops before it: first those moving toward the front, front to
/// back, then those moving toward the back, back to front, so that no element is overwritten
/// before it has moved (the map from old to new places is increasing). Then the new elements are
/// written into the gaps (`fill` is called once per insertion, in order).
pub(super) fn merge_in_place<T: Copy>(
    v: &mut Vec<T>,
    changes: &[Change],
    mut fill: impl FnMut(u32) -> T,
) {
    let old_len = v.len();
    let inserts = changes
        .iter()
        .filter(|c| matches!(c, Change::Insert { .. }))
        .count();
    let new_len = old_len + inserts - (changes.len() - inserts);
    if new_len > old_len {
        // Room at the end, filled with any element: every slot past the kept ones is
        // overwritten below.
        let Some(&filler) = v.first() else {
            v.extend(changes.iter().map(|c| match *c {
                Change::Insert { cand, .. } => fill(cand),
                Change::Drop(_) => unreachable!("nothing to drop from an empty set"),
            }));
            return;
        };
        v.resize(new_len, filler);
    }
    // Front to back: the runs that move toward the front.
    let (mut shift, mut start) = (0isize, 0usize);
    for &c in changes {
        let (end, next_start, step) = match c {
            Change::Drop(i) => (i as usize, i as usize + 1, -1),
            Change::Insert { at, .. } => (at as usize, at as usize, 1),
        };
        if shift < 0 && start < end {
            v.copy_within(start..end, start - shift.unsigned_abs());
        }
        shift += step;
        start = next_start;
    }
    if shift < 0 && start < old_len {
        v.copy_within(start..old_len, start - shift.unsigned_abs());
    }
    // Back to front: the runs that move toward the back.
    let mut end = old_len;
    for &c in changes.iter().rev() {
        let (run_start, prev_end, step) = match c {
            Change::Drop(i) => (i as usize + 1, i as usize, -1),
            Change::Insert { at, .. } => (at as usize, at as usize, 1),
        };
        if shift > 0 && run_start < end {
            v.copy_within(run_start..end, run_start + shift as usize);
        }
        shift -= step;
        end = prev_end;
    }
    debug_assert_eq!(shift, 0);
    // The new elements, in the gaps.
    for &c in changes {
        match c {
            Change::Drop(_) => shift -= 1,
            Change::Insert { at, cand } => {
                v[(at as isize + shift) as usize] = fill(cand);
                shift += 1;
            }
        }
    }
    v.truncate(new_len);
}

/// Whether record `e`'s vertex is within its edge's range `±ε_s` ([`VeContact::in_range`]), the
/// range extended across the seams that face a partly covered edge
/// ([`Collider::edge_range`]): a face of a wall slab continues into the floor slab under it.
/// The edge's collider is read only for a vertex out of the plain range.
#[inline(always)]
pub(super) fn in_range(e: &VeContact, colliders: &[Collider], eps_s: f64) -> bool {
    e.in_range(eps_s) || {
        let cb = &colliders[e.key.edge_collider as usize];
        cb.across != 0 && {
            let (r0, r1) = cb.edge_range(e.key.edge as usize);
            e.s >= r0 - eps_s && e.s <= r1 + eps_s
        }
    }
}

/// Re-measures an existing entry: shifts the histories and refreshes geometry and velocities from
/// the body poses (`rots[i]` is body `i`'s rotation this sample).
#[inline]
pub(super) fn measure(e: &mut VeContact, bodies: &[Body], rots: &[Rot]) {
    let (ba, bb) = (&bodies[e.body_a], &bodies[e.body_b]);
    let (ra, rb) = (rots[e.body_a], rots[e.body_b]);
    let v = ba.pose.pos + ra.apply(e.local.v);
    let e0 = bb.pose.pos + rb.apply(e.local.e0);
    let n = rb.apply(e.local.n);
    e.n = n;
    let t = e.t();
    let rel = v - e0;
    e.d = [n.dot(rel), e.d[0], e.d[1]];
    e.hist = next_hist(e.hist);
    e.s_prev = e.s;
    e.s = t.dot(rel);
    e.point = v;
    let v_rel = ba.point_velocity(v) - bb.point_velocity(v);
    e.c0 = n.dot(v_rel);
    e.s0 = t.dot(v_rel);
}

/// The number of valid distance samples after one more (`hist ∈ 1..=3`, [`VeContact::hist`]):
/// one more, at most 3. The same as `(hist + 1).min(3)` on `0..=3`, in fewer instructions (a
/// compare and an add with carry instead of an add, a compare and a conditional move).
#[inline(always)]
fn next_hist(hist: u8) -> u8 {
    hist + u8::from(hist < 3)
}

/// A new tracked entry; its distance history and previous edge coordinate are rebuilt from the past
/// poses, so the SEH estimate has full history even for a pair first seen in contact.
pub(super) fn new_entry(
    tick: u64,
    key: VeCandidate,
    colliders: &[Collider],
    bodies: &[Body],
    past: &PastPoses<'_>,
) -> VeContact {
    let body_a = colliders[key.vertex_collider as usize].body;
    let body_b = colliders[key.edge_collider as usize].body;
    let (v, e0, n, t, len) = geometry(key, colliders);
    let (ca, cb) = (
        &colliders[key.vertex_collider as usize].local,
        &colliders[key.edge_collider as usize].local,
    );
    let local = LocalGeom {
        v: ca.vertices()[key.vertex as usize],
        e0: cb.vertices()[key.edge as usize],
        n: cb.normals()[key.edge as usize],
    };
    let rel = v - e0;
    let (d0, s0) = (n.dot(rel), t.dot(rel));
    let mut d = [d0, 0.0, 0.0];
    let mut hist = 1;
    let mut s_prev = s0;
    if !past.prev.is_empty() {
        let (d1, s1) = past_ds(key, colliders, &past.prev[body_a], &past.prev[body_b]);
        d[1] = d1;
        s_prev = s1;
        hist = 2;
        if !past.prev2.is_empty() {
            d[2] = past_ds(key, colliders, &past.prev2[body_a], &past.prev2[body_b]).0;
            hist = 3;
        }
    }
    let v_rel = bodies[body_a].point_velocity(v) - bodies[body_b].point_velocity(v);
    VeContact {
        key,
        body_a,
        body_b,
        state: None,
        d,
        hist,
        nearest_edge: false,
        loaded: false,
        s: s0,
        s_prev,
        len,
        point: v,
        n,
        c0: n.dot(v_rel),
        s0: t.dot(v_rel),
        s_g: s0.clamp(0.0, len),
        s_entry: s0.clamp(0.0, len),
        m_eff: 0.0,
        law: NO_LAW,
        f_n: 0.0,
        f_t: 0.0,
        since: tick,
        local,
        own_axis: (f64::NAN, f64::NAN, f64::NAN),
    }
}

/// World geometry of a VE pair now: `(V, E0, n, t, L)`.
#[inline]
pub(super) fn geometry(key: VeCandidate, colliders: &[Collider]) -> (Vec2, Vec2, Vec2, Vec2, f64) {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let e = key.edge as usize;
    (
        ca.world_vertices()[key.vertex as usize],
        cb.world_vertices()[e],
        cb.world_normals()[e],
        cb.world_tangent(e),
        cb.local.lengths()[e],
    )
}

/// Signed distance and edge coordinate of a VE pair at past poses `pa` (vertex body), `pb` (edge body).
#[inline]
pub(super) fn past_ds(
    key: VeCandidate,
    colliders: &[Collider],
    pa: &Pose,
    pb: &Pose,
) -> (f64, f64) {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let e = key.edge as usize;
    let v = pa.transform_point(ca.local.vertices()[key.vertex as usize]);
    let e0 = pb.transform_point(cb.local.vertices()[e]);
    let rot = pb.rot();
    let rel = v - e0;
    (
        rot.apply(cb.local.normals()[e]).dot(rel),
        rot.apply(cb.local.tangents()[e]).dot(rel),
    )
}

#[cfg(test)]
mod tests {
    use super::{merge_in_place, next_hist, recollision_floor, Change};

    /// A small deterministic generator (xorshift64*).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
    }

    /// The merge by copy that `merge_in_place` replaced: keep, drop or insert, into a new list.
    fn merged_by_copy(v: &[u32], changes: &[Change], new: impl Fn(u32) -> u32) -> Vec<u32> {
        let mut out = Vec::new();
        let mut c = changes.iter().peekable();
        for i in 0..=v.len() {
            let mut dropped = false;
            while let Some(&&ch) = c.peek() {
                match ch {
                    Change::Insert { at, cand } if at as usize == i => out.push(new(cand)),
                    Change::Drop(d) if d as usize == i => dropped = true,
                    _ => break,
                }
                c.next();
            }
            if i < v.len() && !dropped {
                out.push(v[i]);
            }
        }
        out
    }

    #[test]
    fn the_history_count_grows_to_three_as_min_did() {
        for hist in 0..=3u8 {
            assert_eq!(next_hist(hist), (hist + 1).min(3), "hist {hist}");
        }
    }

    #[test]
    fn the_recollision_floor_answers_as_the_rule() {
        let special = [
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            0.25,
            -0.25,
            3.0,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let mut rng = Rng(0x0123_4567_89ab_cdef);
        let random: Vec<f64> = (0..2000)
            .map(|_| f64::from_bits(rng.next()))
            .chain(special)
            .collect();
        for v_re in random.iter().map(|&v| Some(v)).chain([None]) {
            let floor = recollision_floor(v_re);
            for &c0 in &random {
                let rule = v_re.is_some_and(|v| c0 < -v);
                assert_eq!(c0 < floor, rule, "c0 {c0:e}, v_re {v_re:?}");
            }
        }
    }

    #[test]
    fn a_merge_in_place_gives_the_merge_by_copy() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut changed = 0;
        for case in 0..4000 {
            let len = rng.below(if case % 4 == 0 { 4 } else { 60 }) as usize;
            let v: Vec<u32> = (0..len as u32).map(|i| 1000 + i).collect();
            // Changes in the order the walk finds them: before each entry (and at the end)
            // some insertions, then perhaps the entry's drop.
            let rate = 1 + rng.below(6);
            let mut changes = Vec::new();
            let mut cand = 0;
            for i in 0..=len {
                while rng.below(10) < rate.min(4) && rng.below(3) == 0 {
                    changes.push(Change::Insert { at: i as u32, cand });
                    cand += 1;
                }
                if i < len && rng.below(10) < rate {
                    changes.push(Change::Drop(i as u32));
                }
            }
            changed += usize::from(!changes.is_empty());
            let new = |c: u32| 5000 + c;
            let want = merged_by_copy(&v, &changes, new);
            let mut got = v.clone();
            let mut calls = Vec::new();
            merge_in_place(&mut got, &changes, |c| {
                calls.push(c);
                new(c)
            });
            assert_eq!(got, want, "case {case}: {v:?} with {changes:?}");
            assert_eq!(calls, (0..cand).collect::<Vec<_>>(), "case {case}");
        }
        assert!(changed > 3000, "the cases change the list ({changed})");
    }
}
