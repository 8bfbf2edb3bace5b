//! Stage 4 of the contact step: §8.2 rules 1–2, record creation with the crossed-edge rule (§8.3),
//! one pair per coincident corner, then the simultaneity window; the braking pulse's effective
//! masses.

use super::invariant::depth_ok;
use super::sync::{geometry, in_range, new_entry, past_ds};
use super::ContactSet;
use super::PastPoses;
use crate::body::Body;
use crate::collide::{corner_facing_edge, Collider, VeCandidate};
use crate::contact::god_object::{crossing_coordinate, entry_point};
use crate::contact::params::ContactParams;
use crate::contact::record::{ContactEvent, ContactState, EventKind, VeContact};
use crate::laws::friction::FrictionModel;
use crate::laws::normal::NormalModel;

impl ContactSet {
    /// §8.2 rules 1–2: creation with the crossed-edge rule, then the simultaneity window.
    /// Returns true if any record is Colliding.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn create(
        &mut self,
        tick: u64,
        dt: f64,
        colliders: &[Collider],
        bodies: &[Body],
        past: &PastPoses<'_>,
        normal: &NormalModel,
        friction: &FrictionModel,
    ) -> bool {
        let p = self.params;
        self.pending.clear();
        for c in self.new_count.iter_mut() {
            *c = 0;
        }
        // Rule 1, one vertex–collider group at a time (entries of a group are adjacent), in key
        // order: only the groups with a touching pair without a record (`may_touch`), found by
        // one cheap pass, are looked at.
        let mut i = 0;
        while let Some((g, h)) = next_group(&self.entries, i, |e| may_touch(e, p)) {
            i = h;
            // A group with a record creates nothing (rule 1: one record per vertex).
            if self.entries[g..h].iter().any(|e| e.is_contact()) {
                continue;
            }
            let touching = self.entries[g..h]
                .iter()
                .enumerate()
                .filter(|(_, e)| e.d[0] <= p.delta_on && in_range(e, colliders, p.eps_s))
                .max_by(|a, b| a.1.d[0].total_cmp(&b.1.d[0]))
                .map(|(k, _)| g + k);
            let cos = self.cos_parallel;
            // One VE pair per coincident corner (see `twin_has_record`): checked on the proposed
            // edge first, so a suppressed twin costs no crossed-edge search.
            let touching = touching.filter(|&t| {
                !twin_has_record(
                    &self.entries,
                    &self.pending,
                    self.entries[t].key,
                    colliders,
                    cos,
                )
            });
            if let Some(fallback) = touching {
                let key = self.entries[fallback].key;
                let edge = creation_edge(key, colliders, past, p.eps_s, cos);
                // The depth invariant (see `step`): the crossed edge of a fast vertex may be one
                // whose line is far deeper than the vertex's real depth (a vertex that went past
                // the middle of a thin part of B); then the proposed edge, which satisfies it by
                // construction in the local stage, is used, and if neither does, no record.
                let (dc, cos) = (self.delta_c, self.cos_parallel);
                let edge = if depth_ok(VeCandidate { edge, ..key }, colliders, dc, cos) {
                    edge
                } else if depth_ok(key, colliders, dc, cos) {
                    key.edge
                } else {
                    continue;
                };
                if edge != key.edge
                    && twin_has_record(
                        &self.entries,
                        &self.pending,
                        VeCandidate { edge, ..key },
                        colliders,
                        cos,
                    )
                {
                    continue;
                }
                let target = self.entries[g..h]
                    .iter()
                    .position(|e| e.key.edge == edge)
                    .map(|k| g + k);
                match target {
                    Some(t) => {
                        let e = &mut self.entries[t];
                        start_record(e, p, tick, &mut self.events, false);
                        e.law = self.laws.acquire(normal, friction, e.s_g);
                        found_inside(e, colliders, self.delta_c, &mut self.laws);
                        self.new_count[e.body_a] += 1;
                    }
                    None => {
                        let key = VeCandidate { edge, ..key };
                        let mut e = new_entry(tick, key, colliders, bodies, past);
                        start_record(&mut e, p, tick, &mut self.events, false);
                        e.law = self.laws.acquire(normal, friction, e.s_g);
                        found_inside(&mut e, colliders, self.delta_c, &mut self.laws);
                        self.new_count[e.body_a] += 1;
                        self.pending.push(e);
                    }
                }
            }
        }
        if !self.pending.is_empty() {
            self.entries.extend_from_slice(&self.pending);
            self.entries.sort_unstable_by_key(|e| e.key);
        }

        // Rule 2: the simultaneity window. Records are Colliding only if created (or promoted) in this
        // sample, so the event list tells whether there is anything to do.
        let any = self.events.iter().any(|ev| {
            matches!(
                ev.kind,
                EventKind::Created(ContactState::Colliding) | EventKind::Recollision
            )
        });
        if any {
            for f in self.body_flag.iter_mut() {
                *f = false;
            }
            for e in &self.entries {
                if e.state == Some(ContactState::Colliding) {
                    self.body_flag[e.body_a] |= bodies[e.body_a].is_dynamic();
                    self.body_flag[e.body_b] |= bodies[e.body_b].is_dynamic();
                }
            }
        }
        if any && p.impacts {
            // Only a group with a pair that approaches while apart (`may_strike`) can pick one.
            let mut i = 0;
            while let Some((g, h)) = next_group(&self.entries, i, |e| may_strike(e, p)) {
                i = h;
                if !self.entries[g..h].iter().any(|e| e.is_contact()) {
                    let flag = &self.body_flag;
                    let (entries, pending) = (&self.entries, &self.pending);
                    let cos = self.cos_parallel;
                    let pick = self.entries[g..h]
                        .iter()
                        .position(|e| {
                            (flag[e.body_a] || flag[e.body_b])
                                && e.d[0] > 0.0
                                && e.c0 < -p.v_c
                                && e.d[0] + dt * e.c0 <= 0.0
                                && in_range(e, colliders, p.eps_s)
                                && !twin_has_record(entries, pending, e.key, colliders, cos)
                        })
                        .map(|k| g + k);
                    if let Some(t) = pick {
                        let e = &mut self.entries[t];
                        start_record(e, p, tick, &mut self.events, true);
                        e.law = self.laws.acquire(normal, friction, e.s_g);
                        self.new_count[e.body_a] += 1;
                    }
                }
            }
        }
        // Effective masses for the braking pulse: the pair's reduced mass shared by the contacts that
        // started on the vertex body in this sample.
        let created = self.events.iter().any(|ev| {
            matches!(
                ev.kind,
                EventKind::Created(_) | EventKind::CreatedSimultaneous
            )
        });
        for e in self.entries.iter_mut().filter(|_| created) {
            if e.since == tick && e.is_contact() {
                let inv = bodies[e.body_a].inv_mass + bodies[e.body_b].inv_mass;
                let n = self.new_count[e.body_a].max(1) as f64;
                e.m_eff = if inv > 0.0 { 1.0 / inv / n } else { 0.0 };
            }
        }
        any || self
            .events
            .iter()
            .any(|ev| ev.kind == EventKind::CreatedSimultaneous)
    }
}

/// A record on a piece with seams, found with its vertex already behind its edge's line by more
/// than `δ_c` at the last sample (issue 35), did not come in through that edge but through a seam
/// (a vertex that slid under a wall slab inside the floor slab and rose into the wall slab 27 mm
/// from its face: +7.4 J from nothing in `corner-seam-tunnel.toml`). Its spring would store
/// `½·K·δ²` that nothing paid for, so the law's surface starts at the vertex (the surface offset
/// of `laws/normal/impact_offset.rs`, `σ = δ`): it stores nothing at creation, resists any
/// further penetration, and follows the vertex back out. The overlap stays (reported by
/// [`World::max_overlap`](crate::world::World::max_overlap)), and no energy appears. Records at
/// `t = 0` (no history) keep their depth, as before. The same for a pair the vertex scan did not
/// propose (issue 35, §9.5b): the clip pairs of crossing corners with no vertex inside, whose
/// depth nothing paid for either (a separated pair's closest-feature candidates are never
/// `δ_c` behind their line). Otherwise only pieces with seams: elsewhere a record
/// released and created again deep (a recollision, a vertex past an edge's end) would lose its
/// depth each time and let a body sink (random scenes fell 100 mm into the floor).
fn found_inside(
    e: &mut VeContact,
    colliders: &[Collider],
    delta_c: f64,
    laws: &mut crate::contact::law_pool::LawPool,
) {
    let seams = colliders[e.key.edge_collider as usize].seams != 0;
    // A clip pair of crossing corners (`collide/clip.rs`, not the vertex scan's) found deep.
    let clip = !e.nearest_edge;
    if (seams || clip) && e.hist >= 2 && e.d[0] < 0.0 && e.d[1] < -delta_c {
        laws.impact_resolved(e.law, e.d, 0);
    }
}

/// The vertex–collider group (entries `g..h`, adjacent in key order) of the first entry at or
/// after `from` that `hint` accepts; `None` when no entry from there on does. A pass that looks
/// only at such groups, continuing from `h`, visits in key order the groups of the pass over
/// every group that can act, when `hint` holds for every entry on which that pass acts.
#[inline]
fn next_group(
    entries: &[VeContact],
    from: usize,
    hint: impl Fn(&VeContact) -> bool,
) -> Option<(usize, usize)> {
    let i = from + entries.get(from..)?.iter().position(hint)?;
    let key = &entries[i].key;
    let g = entries[..i]
        .iter()
        .rposition(|e| !same_group(&e.key, key))
        .map_or(0, |k| k + 1);
    let h = i + entries[i..]
        .iter()
        .position(|e| !same_group(&e.key, key))
        .unwrap_or(entries.len() - i);
    Some((g, h))
}

/// A pair without a record within `δ_on` of its edge line: rule 1's `touching` test without
/// the range test (it holds wherever that test does).
#[inline(always)]
fn may_touch(e: &VeContact, p: ContactParams) -> bool {
    e.state.is_none() && e.d[0] <= p.delta_on
}

/// A pair without a record, apart and approaching faster than `v_c`: the part of rule 2's pick
/// that reads the entry alone (it holds wherever the pick does, whose group has no record).
#[inline(always)]
fn may_strike(e: &VeContact, p: ContactParams) -> bool {
    e.state.is_none() && e.d[0] > 0.0 && e.c0 < -p.v_c
}

#[inline]
fn same_group(a: &VeCandidate, b: &VeCandidate) -> bool {
    a.vertex_collider == b.vertex_collider
        && a.vertex == b.vertex
        && a.edge_collider == b.edge_collider
}

/// Turns a tracked pair into a record: Colliding if it approaches faster than `v_c` (and impacts are on),
/// otherwise Continuous (an invalid impact, §8.2 rule 1). Initialises the god-object; the caller
/// gives the record its law states ([`LawState::begin`]).
fn start_record(
    e: &mut VeContact,
    p: ContactParams,
    tick: u64,
    events: &mut Vec<ContactEvent>,
    simultaneous: bool,
) {
    let state = if simultaneous || (p.impacts && e.c0 < -p.v_c) {
        ContactState::Colliding
    } else {
        ContactState::Continuous
    };
    e.state = Some(state);
    e.since = tick;
    e.m_eff = 0.0;
    e.s_g = if e.hist >= 2 {
        entry_point(e.d[1], e.d[0], e.s_prev, e.s, e.len)
            .map(|(_, s)| s)
            .unwrap_or(e.s.clamp(0.0, e.len))
    } else {
        e.s.clamp(0.0, e.len)
    };
    e.s_entry = e.s_g;
    events.push(ContactEvent {
        tick,
        key: e.key,
        kind: if simultaneous {
            EventKind::CreatedSimultaneous
        } else {
            EventKind::Created(state)
        },
    });
}

/// The edge of a new record for the touching pair `key` (§8.3): the crossed edge (or the proposed
/// one if no edge line was crossed), except at a corner of the edge collider, where the proposed
/// edge and the crossed one are adjacent: there the facing edge wins (corner-on-corner rule,
/// [`corner_facing_edge`]). For boxes stacked exactly, the upper box's corner crosses the lower
/// box's top line on landing and its side line by round-off (`d` from `+1e-19` to `−1e-19 m`, at
/// any `λ`), so the smallest-`λ` crossing alone picks either edge by chance.
fn creation_edge(
    key: VeCandidate,
    colliders: &[Collider],
    past: &PastPoses<'_>,
    eps_s: f64,
    cos_parallel: f64,
) -> u32 {
    match crossed_edge(key, colliders, past, eps_s) {
        None => key.edge,
        Some(c) if c == key.edge => c,
        Some(c) => {
            let cb = &colliders[key.edge_collider as usize];
            let (e1, e2) = (c as usize, key.edge as usize);
            if cb.local.next(e1) != e2 && cb.local.next(e2) != e1 {
                return c;
            }
            let ca = &colliders[key.vertex_collider as usize];
            corner_facing_edge(ca, key.vertex as usize, cb, e1, e2, cos_parallel)
                .map_or(c, |e| e as u32)
        }
    }
}

/// One VE pair per coincident corner: whether the *twin* of the pair `key` (vertex `V` of A against
/// edge `e` of B) is a contact record already, in `entries` or `pending`.
///
/// Where a corner `V` of A lies on a corner `W` of B with facing edges `e_A ∋ V`, `e ∋ W`
/// (antiparallel within [`NEAR_PARALLEL_ANGLE`]), both `(V, e)` and `(W, e_A)` are valid pairs at
/// the same point with the same normal line: two springs there double the stiffness (`2·K_c`);
/// on the aligned 100-box pile (1 kHz) that left boxes rocking in a limit cycle at half the sample
/// rate (`ω = ±1.54 rad/s`, alternating every sample) and 350 records instead of 200.
/// The twin is `(W = end of e, e_A = V's outgoing edge)` or `(W = start of e, e_A = V's incoming
/// edge)`: `W` and `V` are then the same end of the two antiparallel faces. Both pairs lie in
/// their edge ranges only while the corners coincide along the face: for `W = start of e`
/// (`s(V) = t·(V − W)`) and `V = end of e_A` with `t_A = −t`, `s_A(W) − L_A = t_A·(W − V) =
/// s(V)`, so `(V, e)` needs `s(V) ≥ −ε_s` and `(W, e_A)` needs `s(V) ≤ ε_s`: both hold iff
/// `|t·(V − W)| ≤ ε_s` (the other case is the mirror image). A record is released outside its
/// range, so an existing twin record means the corners coincide. (The two ends of the overlap of
/// antiparallel faces that do not coincide are the ends of both edges or the starts of both,
/// never twins.) The first pair in key order to touch keeps the corner; the other stays tracked.
fn twin_has_record(
    entries: &[VeContact],
    pending: &[VeContact],
    key: VeCandidate,
    colliders: &[Collider],
    cos_parallel: f64,
) -> bool {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let (v, e) = (key.vertex as usize, key.edge as usize);
    let n_e = cb.world_normals()[e];
    let twins = [(cb.local.next(e), v), (e, ca.local.prev(v))];
    twins.into_iter().any(|(w, e_a)| {
        if n_e.dot(ca.world_normals()[e_a]) >= -cos_parallel {
            return false;
        }
        let twin = VeCandidate {
            vertex_collider: key.edge_collider,
            vertex: w as u32,
            edge_collider: key.vertex_collider,
            edge: e_a as u32,
        };
        let in_entries = entries
            .binary_search_by(|x| x.key.cmp(&twin))
            .is_ok_and(|k| entries[k].is_contact());
        in_entries || pending.iter().any(|x| x.key == twin)
    })
}

/// The crossed-edge rule of §8.3: among the edges of the edge collider whose line the vertex crossed
/// during the last sample, within the edge range, the one crossed first (smallest λ).
fn crossed_edge(
    key: VeCandidate,
    colliders: &[Collider],
    past: &PastPoses<'_>,
    eps_s: f64,
) -> Option<u32> {
    if past.prev.is_empty() {
        return None;
    }
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let (pa, pb) = (&past.prev[ca.body], &past.prev[cb.body]);
    let mut best: Option<(f64, u32)> = None;
    // A seam (an internal edge of a multi-piece body, `collide/seam.rs`) is never crossed.
    for e in (0..cb.len()).filter(|&e| !cb.is_seam(e)) {
        let k = VeCandidate {
            edge: e as u32,
            ..key
        };
        let (_, e0, n, t, len) = geometry(k, colliders);
        let v = ca.world_vertices()[key.vertex as usize];
        let (d_now, s_now) = (n.dot(v - e0), t.dot(v - e0));
        let (d_prev, s_prev) = past_ds(k, colliders, pa, pb);
        if d_prev > 0.0 && d_now <= 0.0 {
            let lam = d_prev / (d_prev - d_now);
            let s_cross = crossing_coordinate(d_prev, d_now, s_prev, s_now);
            let (r0, r1) = if cb.across == 0 {
                (0.0, len)
            } else {
                cb.edge_range(e)
            };
            if s_cross >= r0 - eps_s && s_cross <= r1 + eps_s && best.is_none_or(|(l, _)| lam < l) {
                best = Some((lam, e as u32));
            }
        }
    }
    best.map(|(_, e)| e)
}

#[cfg(test)]
mod tests {
    use super::{next_group, same_group};
    use crate::collide::VeCandidate;
    use crate::contact::manager::{box_on_floor, fresh_entry};
    use crate::contact::record::{ContactState, VeContact};
    use crate::geom::Pose;

    /// A tracked pair of a box on a floor, to copy with other keys, states and depths.
    fn template() -> VeContact {
        let (bodies, colliders, key) =
            box_on_floor(Pose::new(0.0, 0.05, 0.0), Pose::new(0.0, -0.1, 0.0));
        fresh_entry(key, &colliders, &bodies)
    }

    /// Over 3 000 seeded random sorted entry lists (groups of one to four entries, some with a
    /// record), the groups `next_group` visits from 0, each search going on from the last group's
    /// end, are exactly the groups that the walk over every group finds to hold an entry the hint
    /// accepts, in the same order.
    #[test]
    fn groups_found_by_a_hint_are_the_groups_with_an_accepted_entry() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut below = move |n: u64| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) % n
        };
        let base = template();
        let hint = |e: &VeContact| e.state.is_none() && e.d[0] <= 0.0;
        let (mut visited, mut passed) = (0, 0);
        for _ in 0..3_000 {
            let mut entries: Vec<VeContact> = (0..below(40))
                .map(|_| {
                    let mut e = base;
                    e.key = VeCandidate {
                        vertex_collider: below(5) as u32,
                        vertex: below(3) as u32,
                        edge_collider: below(3) as u32,
                        edge: below(4) as u32,
                    };
                    e.state = (below(4) == 0).then_some(ContactState::Continuous);
                    e.d[0] = below(100) as f64 * 1e-3 - 0.08;
                    e
                })
                .collect();
            entries.sort_by_key(|e| e.key);
            entries.dedup_by_key(|e| e.key);
            // Every group, by a walk over all entries.
            let mut all = Vec::new();
            let mut g = 0;
            while g < entries.len() {
                let mut h = g + 1;
                while h < entries.len() && same_group(&entries[g].key, &entries[h].key) {
                    h += 1;
                }
                all.push((g, h));
                g = h;
            }
            let wanted: Vec<_> = all
                .iter()
                .copied()
                .filter(|&(g, h)| entries[g..h].iter().any(hint))
                .collect();
            let mut found = Vec::new();
            let mut i = 0;
            while let Some((g, h)) = next_group(&entries, i, hint) {
                found.push((g, h));
                i = h;
            }
            assert_eq!(
                found,
                wanted,
                "{:?}",
                entries.iter().map(|e| e.key).collect::<Vec<_>>()
            );
            visited += found.len();
            passed += all.len() - found.len();
        }
        assert!(
            visited > 5_000 && passed > 5_000,
            "{visited} groups visited, {passed} passed over"
        );
    }
}
