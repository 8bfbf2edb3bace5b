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
    /// the face-on-face exception), or the merge changed the set.
    pub hand_over: bool,
    /// Some tracked pair without a record touches (`d ≤ δ_on`, in range), or the merge changed
    /// the set (`create` also runs after any release or hand-over event).
    pub create: bool,
}

impl ContactSet {
    /// Merges the sorted candidates with the tracked set: existing entries are re-measured (history
    /// shifted), new candidates get a fresh entry whose history is rebuilt from the past poses, tracked
    /// pairs that are neither candidates nor records are dropped. Every entry's `nearest_edge` is
    /// its candidate's `from_scan` flag (parallel to `candidates`; false for a record that is not a
    /// candidate, or if `from_scan` is not parallel). Returns what the later stages may find to
    /// do ([`StageWork`]), seen in the same pass.
    #[allow(clippy::too_many_arguments)]
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
        // Every tracked entry is re-measured in place (one pass over the set), checking on the way
        // whether merging would keep exactly the current entries: every candidate is tracked already,
        // and every tracked pair is a candidate or a record. That is the steady-contact case, and then
        // nothing is copied. (An entry that the merge drops is measured for nothing; that is harmless.)
        let flags = (from_scan.len() == candidates.len()).then_some(from_scan);
        let flag = |j: usize| flags.is_some_and(|f| f[j]);
        let mut same = true;
        let mut j = 0;
        let p = self.params;
        let recollide = p.v_re.filter(|_| p.impacts);
        let mut work = StageWork::default();
        for e in self.entries.iter_mut() {
            measure(e, bodies, rots);
            e.nearest_edge = false;
            if same {
                if j < candidates.len() && e.key == candidates[j] {
                    e.nearest_edge = flag(j);
                    j += 1;
                } else if !e.is_contact() || (j < candidates.len() && candidates[j] < e.key) {
                    same = false;
                }
            }
            // The tests of `release`, `hand_over` and `create`, on this sample's measures.
            match e.state {
                Some(ContactState::Continuous) => {
                    if e.d[0] > p.delta_off
                        || !e.in_range(p.eps_s)
                        || recollide.is_some_and(|v_re| e.c0 < -v_re)
                    {
                        work.release = true;
                    } else if same && !e.nearest_edge && !work.hand_over {
                        let cb = &colliders[e.key.edge_collider as usize];
                        work.hand_over = e.d[0] < nearest_line(cb, e.point).1 - self.delta_c;
                    }
                }
                Some(ContactState::Colliding) => {}
                None => work.create |= e.d[0] <= p.delta_on && e.in_range(p.eps_s),
            }
        }
        if same && j == candidates.len() {
            return work;
        }
        // The merge adds pairs and sets `nearest_edge` anew: the later stages look at them all.
        work.hand_over = true;
        work.create = true;
        self.merged.clear();
        let (mut i, mut j) = (0, 0);
        let old = std::mem::take(&mut self.entries);
        while i < old.len() || j < candidates.len() {
            let take_old = j >= candidates.len() || (i < old.len() && old[i].key <= candidates[j]);
            if take_old {
                let same = j < candidates.len() && old[i].key == candidates[j];
                if same || old[i].is_contact() {
                    self.merged.push(VeContact {
                        nearest_edge: same && flag(j),
                        ..old[i]
                    });
                }
                if same {
                    j += 1;
                }
                i += 1;
            } else {
                let e = new_entry(tick, candidates[j], colliders, bodies, past);
                self.merged.push(VeContact {
                    nearest_edge: flag(j),
                    ..e
                });
                j += 1;
            }
        }
        self.entries = old;
        std::mem::swap(&mut self.entries, &mut self.merged);
        work
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
    e.hist = (e.hist + 1).min(3);
    e.s_prev = e.s;
    e.s = t.dot(rel);
    e.point = v;
    let v_rel = ba.point_velocity(v) - bb.point_velocity(v);
    e.c0 = n.dot(v_rel);
    e.s0 = t.dot(v_rel);
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
