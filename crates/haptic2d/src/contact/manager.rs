//! The contact set: tracked VE pairs and contact records, their state machine (§8.2), god-objects
//! (§8.3), simultaneous impacts (§7) and continuous-contact forces (§5.9, §1–§4).
//!
//! Entries are kept sorted by `(vertex collider, vertex, edge collider, edge)`; every loop runs in that
//! order, so the result does not depend on anything but the inputs. After warm-up no step allocates:
//! the buffers are swapped and reused.

use super::god_object::{crossing_coordinate, entry_point};
use super::impact::{ImpactRow, ImpactSolver};
use super::law_pool::LawPool;
use super::params::ContactParams;
use super::record::{
    ContactEvent, ContactState, EventKind, LawState, LocalGeom, VeContact, NO_LAW,
};
use crate::body::Body;
use crate::collide::{
    corner_facing_edge, nearest_line, sat_depth, Collider, VeCandidate, DEFAULT_DELTA_C,
    NEAR_PARALLEL_ANGLE,
};
use crate::geom::{cross, Pose, Rot, Vec2};
use crate::laws::friction::{FrictionInput, FrictionLaw, FrictionModel};
use crate::laws::normal::{NormalInput, NormalLaw, NormalModel};

/// Per-body contact wrench of one sample: force (N) and torque about the COM (N·m).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wrench2 {
    /// Force (N).
    pub force: Vec2,
    /// Torque about the body's centre of mass (N·m).
    pub torque: f64,
}

/// The past body poses the contact set needs for SEH history and god-object entry points.
pub struct PastPoses<'a> {
    /// Poses at `k − 1` (empty before the first step).
    pub prev: &'a [Pose],
    /// Poses at `k − 2` (empty before the second step).
    pub prev2: &'a [Pose],
}

/// All tracked VE pairs and contact records of a world.
#[derive(Clone, Debug)]
pub struct ContactSet {
    /// Thresholds and options.
    pub params: ContactParams,
    entries: Vec<VeContact>,
    /// Law states of the records, addressed by [`VeContact::law`].
    laws: LawPool,
    merged: Vec<VeContact>,
    pending: Vec<VeContact>,
    events: Vec<ContactEvent>,
    rows: Vec<ImpactRow>,
    row_entry: Vec<usize>,
    solver: ImpactSolver,
    body_flag: Vec<bool>,
    parent: Vec<u32>,
    row_order: Vec<u32>,
    row_island: Vec<u32>,
    island_rows: Vec<ImpactRow>,
    new_count: Vec<u32>,
    nonfric: Vec<Vec2>,
    /// Kinetic energy removed by the impacts of the last sample (J).
    pub last_impact_loss: f64,
    /// Energy stored in contact and friction springs after the last step (J).
    stored: f64,
    /// Number of contact records after the last step.
    record_count: usize,
    /// Number of impact sets solved so far.
    pub impacts_solved: u64,
    /// `cos(NEAR_PARALLEL_ANGLE)`: edges with `n·n < −cos_parallel` face each other.
    cos_parallel: f64,
    /// Contact distance tolerance `δ_c` (m): also the tolerance of the depth invariant.
    delta_c: f64,
}

impl ContactSet {
    /// An empty contact set.
    pub fn new(params: ContactParams) -> Self {
        Self {
            params,
            entries: Vec::with_capacity(64),
            laws: LawPool::with_capacity(64),
            merged: Vec::with_capacity(64),
            pending: Vec::with_capacity(16),
            events: Vec::with_capacity(64),
            rows: Vec::with_capacity(16),
            row_entry: Vec::with_capacity(16),
            solver: ImpactSolver::new(),
            body_flag: Vec::new(),
            parent: Vec::new(),
            row_order: Vec::with_capacity(16),
            row_island: Vec::with_capacity(16),
            island_rows: Vec::with_capacity(16),
            new_count: Vec::new(),
            nonfric: Vec::new(),
            last_impact_loss: 0.0,
            stored: 0.0,
            record_count: 0,
            impacts_solved: 0,
            cos_parallel: NEAR_PARALLEL_ANGLE.cos(),
            delta_c: DEFAULT_DELTA_C,
        }
    }

    /// Sets the contact distance tolerance `δ_c` (m, the local stage's; default
    /// [`DEFAULT_DELTA_C`]), which is also the tolerance of the depth invariant
    /// ([`ContactSet::step`]). A non-finite or negative value is ignored.
    pub fn set_delta_c(&mut self, delta_c: f64) {
        if delta_c.is_finite() && delta_c >= 0.0 {
            self.delta_c = delta_c;
        }
    }

    /// Every tracked pair and contact record, sorted by key.
    #[inline]
    pub fn entries(&self) -> &[VeContact] {
        &self.entries
    }

    /// The contact records (Colliding or Continuous), sorted by key.
    pub fn records(&self) -> impl Iterator<Item = &VeContact> {
        self.entries.iter().filter(|e| e.is_contact())
    }

    /// The law states of record `e` (an entry of [`entries`](Self::entries)); `None` for a pair that
    /// is only tracked.
    pub fn laws(&self, e: &VeContact) -> Option<&LawState> {
        if e.is_contact() {
            self.laws.get(e.law)
        } else {
            None
        }
    }

    /// Number of contact records after the last step (counted in the force pass, so reading it
    /// every tick costs nothing).
    #[inline]
    pub fn contact_count(&self) -> usize {
        self.record_count
    }

    /// The state transitions of the last sample.
    #[inline]
    pub fn events(&self) -> &[ContactEvent] {
        &self.events
    }

    /// Impact sets whose energy check scaled an impulse so far (issue 16; 0 without friction).
    pub fn impact_energy_fallbacks(&self) -> u64 {
        self.solver.energy_fallbacks()
    }

    /// Energy stored in all contact and friction springs after the last step (J).
    pub fn stored_energy(&self) -> f64 {
        self.stored
    }

    /// Steps 4–6 of §0.5 for one sample: merge the local stage's candidates into the tracked set and
    /// measure every pair, run the state machine, resolve impacts (velocity jumps applied to `bodies`
    /// now), then compute continuous-contact forces into `wrenches` (one per body, overwritten).
    ///
    /// **Depth invariant** (issue 10). A record `(V, e)` stores `½·K_c·d_e²`, a function of the
    /// poses while its key is fixed, so the stored energy is continuous over its life; it can only
    /// jump where a record is created or changes edge. There its depth must be the vertex's real
    /// depth in the edge polygon B, up to the corner tolerance `δ_c`:
    ///
    /// ```text
    /// d_e ≥ max_j d_j(V) − δ_c      (j over B's edge lines; −max_j d_j = depth of V inside B)
    /// ```
    ///
    /// which also bounds `−d_e` by the pair's separating-axis depth `+ δ_c` (no vertex is deeper
    /// in B than the pair's penetration depth). One exception, face on face: where `V` sits at a
    /// corner of B on its side line (coincident corners of an aligned stack) and `e` *faces* an
    /// edge of A at `V` (antiparallel within [`NEAR_PARALLEL_ANGLE`], the corner-on-corner rule),
    /// the faces overlap by the pair's separating-axis depth while `V` is on B's boundary: the
    /// record is then valid up to that depth, `−d_e ≤ depth_SAT + δ_c` (a landing 10-box stack
    /// compresses its faces by 2.02 mm with `V` at `±1e-19 m` from the side line). A far edge
    /// never faces A (its normal points away from A). Candidates satisfy it where they are made (the
    /// local stage's nearest-line rule); `create` checks it for the edge it picks (the crossed-edge
    /// rule may pick another one); `hand_over` moves a record whose vertex has come nearer to
    /// another line of B by more than `δ_c` to that edge (or releases it if the vertex is outside
    /// B): its stored energy then drops, never rises. Debug builds assert the invariant for every
    /// record at the end of every sample.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        tick: u64,
        dt: f64,
        candidates: &[VeCandidate],
        colliders: &[Collider],
        bodies: &mut [Body],
        rots: &[Rot],
        past: &PastPoses<'_>,
        normal: &NormalModel,
        friction: &FrictionModel,
        wrenches: &mut [Wrench2],
    ) {
        self.events.clear();
        self.last_impact_loss = 0.0;
        self.resize_body_buffers(bodies.len());
        self.sync(tick, candidates, colliders, bodies, rots, past);
        self.release(tick);
        self.hand_over(tick, colliders, bodies, past, normal, friction);
        let any_colliding = self.create(tick, dt, colliders, bodies, past, normal, friction);
        if any_colliding {
            // Issue 16 hook: impact friction mode and coefficient (default μ = the model's μ_k).
            let mu = (self.params.impact_mu).unwrap_or_else(|| super::default_impact_mu(friction));
            self.solver.set_friction(self.params.impact_friction, mu);
            self.resolve_impacts(tick, bodies);
        }
        self.forces(dt, bodies, friction, wrenches);
        #[cfg(debug_assertions)]
        self.assert_depth_invariant(colliders);
    }

    /// Debug builds: every record satisfies the depth invariant of [`ContactSet::step`], and is no
    /// deeper than its pair's separating-axis depth plus `δ_c`.
    #[cfg(debug_assertions)]
    fn assert_depth_invariant(&self, colliders: &[Collider]) {
        // Round-off allowance on distances of a few metres at most.
        const TOL: f64 = 1e-9;
        for e in self.entries.iter().filter(|e| e.is_contact()) {
            let ca = &colliders[e.key.vertex_collider as usize];
            let cb = &colliders[e.key.edge_collider as usize];
            let p = ca.world_vertices[e.key.vertex as usize];
            let d_e = cb.edge_distance(e.key.edge as usize, p);
            let (j, max_d) = nearest_line(cb, p);
            let face = face_on_face_ok(e.key, colliders, self.delta_c, self.cos_parallel);
            debug_assert!(
                d_e >= max_d - self.delta_c - TOL || face,
                "VE record {:?}: d = {d_e:e} m on its edge, but edge {j}'s line is at {max_d:e} m \
                 (more than δ_c = {} m nearer): its stored energy exceeds the vertex's real depth",
                e.key,
                self.delta_c
            );
            let sat = sat_depth(ca, cb);
            debug_assert!(
                -d_e <= sat + self.delta_c + TOL,
                "VE record {:?}: depth {:e} m exceeds the pair's separating-axis depth {sat:e} m + δ_c",
                e.key,
                -d_e
            );
        }
    }

    /// Hands a Continuous record over to the nearer edge where the depth invariant of
    /// [`ContactSet::step`] would break: when some other line `j` of B is nearer to the vertex
    /// than the record's edge line by more than `δ_c` (`d_e < max_j d_j − δ_c`; a long-lived
    /// record of a vertex that slid or rotated deep past a corner of B). The record is released
    /// and, if the vertex is inside B (`max_j d_j ≤ δ_off`) and in the range of `j` (always so
    /// inside B), a Continuous record is started on `j` (events `Released`, then
    /// `Created(Continuous)`: it is not an impact). Its stored energy drops from `½·K_c·d_e²` to
    /// `½·K_c·d_j²`, so the hand-over dissipates and never creates energy. The `δ_c` hysteresis is
    /// the corner tolerance: at a stacked corner the vertex is equally near both lines up to
    /// round-off, and the corner-on-corner rule, not the distances, decides the edge there.
    fn hand_over(
        &mut self,
        tick: u64,
        colliders: &[Collider],
        bodies: &[Body],
        past: &PastPoses<'_>,
        normal: &NormalModel,
        friction: &FrictionModel,
    ) {
        let p = self.params;
        self.pending.clear();
        for idx in 0..self.entries.len() {
            let e = &self.entries[idx];
            if e.state != Some(ContactState::Continuous) {
                continue;
            }
            let cb = &colliders[e.key.edge_collider as usize];
            let (j, max_d) = nearest_line(cb, e.point);
            if e.d[0] >= max_d - self.delta_c
                || face_on_face_ok(e.key, colliders, self.delta_c, self.cos_parallel)
            {
                continue;
            }
            let key = VeCandidate {
                edge: j as u32,
                ..e.key
            };
            let s_j = cb.edge_coordinate(j, e.point);
            let holds =
                max_d <= p.delta_off && s_j >= -p.eps_s && s_j <= cb.local.lengths()[j] + p.eps_s;
            let e = &mut self.entries[idx];
            e.state = None;
            self.laws.release(e.law);
            e.law = NO_LAW;
            e.f_n = 0.0;
            e.f_t = 0.0;
            self.events.push(ContactEvent {
                tick,
                key: e.key,
                kind: EventKind::Released,
            });
            if !holds {
                continue;
            }
            match self.entries.binary_search_by(|x| x.key.cmp(&key)) {
                Ok(t) if !self.entries[t].is_contact() => {
                    let n = &mut self.entries[t];
                    start_handed_over(n, tick, &mut self.events);
                    n.law = self.laws.acquire(normal, friction);
                    self.laws.get_mut(n.law).begin(n.s_g);
                }
                Ok(_) => {}
                Err(_) => {
                    let mut n = new_entry(tick, key, colliders, bodies, past);
                    start_handed_over(&mut n, tick, &mut self.events);
                    n.law = self.laws.acquire(normal, friction);
                    self.laws.get_mut(n.law).begin(n.s_g);
                    self.pending.push(n);
                }
            }
        }
        if !self.pending.is_empty() {
            self.entries.extend_from_slice(&self.pending);
            self.entries.sort_unstable_by_key(|e| e.key);
            self.pending.clear();
        }
    }

    fn resize_body_buffers(&mut self, n: usize) {
        if self.body_flag.len() != n {
            self.body_flag.resize(n, false);
            self.parent.resize(n, 0);
            self.new_count.resize(n, 0);
            self.nonfric.resize(n, Vec2::ZERO);
        }
    }

    /// Merges the sorted candidates with the tracked set: existing entries are re-measured (history
    /// shifted), new candidates get a fresh entry whose history is rebuilt from the past poses, tracked
    /// pairs that are neither candidates nor records are dropped.
    fn sync(
        &mut self,
        tick: u64,
        candidates: &[VeCandidate],
        colliders: &[Collider],
        bodies: &[Body],
        rots: &[Rot],
        past: &PastPoses<'_>,
    ) {
        // Every tracked entry is re-measured in place (one pass over the set), checking on the way
        // whether merging would keep exactly the current entries: every candidate is tracked already,
        // and every tracked pair is a candidate or a record. That is the steady-contact case, and then
        // nothing is copied. (An entry that the merge drops is measured for nothing; that is harmless.)
        let mut same = true;
        let mut j = 0;
        for e in self.entries.iter_mut() {
            measure(e, bodies, rots);
            if !same {
                continue;
            }
            if j < candidates.len() && e.key == candidates[j] {
                j += 1;
            } else if !e.is_contact() || (j < candidates.len() && candidates[j] < e.key) {
                same = false;
            }
        }
        if same && j == candidates.len() {
            return;
        }
        self.merged.clear();
        let (mut i, mut j) = (0, 0);
        let old = std::mem::take(&mut self.entries);
        while i < old.len() || j < candidates.len() {
            let take_old = j >= candidates.len() || (i < old.len() && old[i].key <= candidates[j]);
            if take_old {
                let same = j < candidates.len() && old[i].key == candidates[j];
                if same || old[i].is_contact() {
                    self.merged.push(old[i]);
                }
                if same {
                    j += 1;
                }
                i += 1;
            } else {
                let e = new_entry(tick, candidates[j], colliders, bodies, past);
                self.merged.push(e);
                j += 1;
            }
        }
        self.entries = old;
        std::mem::swap(&mut self.entries, &mut self.merged);
    }

    /// §8.2 rule 4 (release) and rule 5 (re-collision, optional).
    fn release(&mut self, tick: u64) {
        let p = self.params;
        for e in self.entries.iter_mut() {
            if e.state != Some(ContactState::Continuous) {
                continue;
            }
            if e.d[0] > p.delta_off || !e.in_range(p.eps_s) {
                e.state = None;
                self.laws.release(e.law);
                e.law = NO_LAW;
                e.f_n = 0.0;
                e.f_t = 0.0;
                self.events.push(ContactEvent {
                    tick,
                    key: e.key,
                    kind: EventKind::Released,
                });
            } else if let Some(v_re) = p.v_re {
                if p.impacts && e.c0 < -v_re {
                    e.state = Some(ContactState::Colliding);
                    self.events.push(ContactEvent {
                        tick,
                        key: e.key,
                        kind: EventKind::Recollision,
                    });
                }
            }
        }
    }

    /// §8.2 rules 1–2: creation with the crossed-edge rule, then the simultaneity window.
    /// Returns true if any record is Colliding.
    #[allow(clippy::too_many_arguments)]
    fn create(
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
        // Rule 1, one vertex–collider group at a time (entries of a group are adjacent).
        let mut g = 0;
        while g < self.entries.len() {
            let mut h = g + 1;
            while h < self.entries.len() && same_group(&self.entries[g].key, &self.entries[h].key) {
                h += 1;
            }
            let group_has_record = self.entries[g..h].iter().any(|e| e.is_contact());
            let touching = self.entries[g..h]
                .iter()
                .enumerate()
                .filter(|(_, e)| e.d[0] <= p.delta_on && e.in_range(p.eps_s))
                .max_by(|a, b| a.1.d[0].total_cmp(&b.1.d[0]))
                .map(|(k, _)| g + k);
            let cos = self.cos_parallel;
            // One VE pair per coincident corner (see `twin_has_record`): checked on the proposed
            // edge first, so a suppressed twin costs no crossed-edge search.
            let touching = touching.filter(|&t| {
                !group_has_record
                    && !twin_has_record(
                        &self.entries,
                        &self.pending,
                        self.entries[t].key,
                        colliders,
                        cos,
                    )
            });
            if let (false, Some(fallback)) = (group_has_record, touching) {
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
                    g = h;
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
                    g = h;
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
                        e.law = self.laws.acquire(normal, friction);
                        self.laws.get_mut(e.law).begin(e.s_g);
                        self.new_count[e.body_a] += 1;
                    }
                    None => {
                        let key = VeCandidate { edge, ..key };
                        let mut e = new_entry(tick, key, colliders, bodies, past);
                        start_record(&mut e, p, tick, &mut self.events, false);
                        e.law = self.laws.acquire(normal, friction);
                        self.laws.get_mut(e.law).begin(e.s_g);
                        self.new_count[e.body_a] += 1;
                        self.pending.push(e);
                    }
                }
            }
            g = h;
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
            let mut g = 0;
            while g < self.entries.len() {
                let mut h = g + 1;
                while h < self.entries.len()
                    && same_group(&self.entries[g].key, &self.entries[h].key)
                {
                    h += 1;
                }
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
                                && e.in_range(p.eps_s)
                                && !twin_has_record(entries, pending, e.key, colliders, cos)
                        })
                        .map(|k| g + k);
                    if let Some(t) = pick {
                        let e = &mut self.entries[t];
                        start_record(e, p, tick, &mut self.events, true);
                        e.law = self.laws.acquire(normal, friction);
                        self.laws.get_mut(e.law).begin(e.s_g);
                        self.new_count[e.body_a] += 1;
                    }
                }
                g = h;
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

    /// §7: every Colliding record (restitution `e`) and every Continuous record touching a body of a
    /// colliding one (restitution 0) form the impact set; velocity jumps are applied to `bodies` now.
    fn resolve_impacts(&mut self, tick: u64, bodies: &mut [Body]) {
        for f in self.body_flag.iter_mut() {
            *f = false;
        }
        for e in &self.entries {
            if e.state == Some(ContactState::Colliding) {
                self.body_flag[e.body_a] |= bodies[e.body_a].is_dynamic();
                self.body_flag[e.body_b] |= bodies[e.body_b].is_dynamic();
            }
        }
        self.rows.clear();
        self.row_entry.clear();
        for (idx, e) in self.entries.iter().enumerate() {
            let restitution = match e.state {
                Some(ContactState::Colliding) => self.params.restitution,
                Some(ContactState::Continuous)
                    if self.body_flag[e.body_a] || self.body_flag[e.body_b] =>
                {
                    0.0
                }
                _ => continue,
            };
            self.rows.push(ImpactRow {
                body_a: e.body_a,
                body_b: e.body_b,
                n: e.n,
                r_a: e.point - bodies[e.body_a].pose.pos,
                r_b: e.point - bodies[e.body_b].pose.pos,
                restitution,
            });
            self.row_entry.push(idx);
        }
        let before: f64 = bodies.iter().map(|b| b.kinetic_energy()).sum();
        self.solve_islands(bodies);
        let after: f64 = bodies.iter().map(|b| b.kinetic_energy()).sum();
        self.last_impact_loss = before - after;
        self.impacts_solved += 1;
        for e in self.entries.iter_mut() {
            if e.state == Some(ContactState::Colliding) {
                e.state = Some(ContactState::Continuous);
                self.events.push(ContactEvent {
                    tick,
                    key: e.key,
                    kind: EventKind::Resolved,
                });
            }
            // Step 5: recompute C0 and S0 with the post-impact velocities.
            let v_rel =
                bodies[e.body_a].point_velocity(e.point) - bodies[e.body_b].point_velocity(e.point);
            e.c0 = e.n.dot(v_rel);
            e.s0 = e.t.dot(v_rel);
        }
    }

    /// Solves the impact set island by island: rows that share no dynamic body are independent (the
    /// Delassus matrix is block diagonal), so each connected component is its own small LCP. Islands
    /// are taken in the order of their root body, rows in key order: the result is deterministic and
    /// identical to solving the whole set at once.
    fn solve_islands(&mut self, bodies: &mut [Body]) {
        // Union–find over dynamic bodies (fixed bodies connect nothing).
        for (i, p) in self.parent.iter_mut().enumerate() {
            *p = i as u32;
        }
        fn find(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                let g = parent[parent[i as usize] as usize];
                parent[i as usize] = g;
                i = g;
            }
            i
        }
        for r in &self.rows {
            if bodies[r.body_a].is_dynamic() && bodies[r.body_b].is_dynamic() {
                let (a, b) = (
                    find(&mut self.parent, r.body_a as u32),
                    find(&mut self.parent, r.body_b as u32),
                );
                if a != b {
                    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                    self.parent[hi as usize] = lo;
                }
            }
        }
        // Island id of each row: the root of its dynamic body.
        self.row_island.clear();
        for r in &self.rows {
            let b = if bodies[r.body_a].is_dynamic() {
                r.body_a
            } else {
                r.body_b
            };
            let root = find(&mut self.parent, b as u32);
            self.row_island.push(root);
        }
        // Group rows by island (stable: rows keep key order inside an island), then solve each run.
        self.row_order.clear();
        self.row_order.extend(0..self.rows.len() as u32);
        let islands = &self.row_island;
        self.row_order
            .sort_unstable_by_key(|&r| (islands[r as usize], r));
        let mut k = 0;
        while k < self.row_order.len() {
            let island = self.row_island[self.row_order[k] as usize];
            self.island_rows.clear();
            while k < self.row_order.len() && self.row_island[self.row_order[k] as usize] == island
            {
                self.island_rows.push(self.rows[self.row_order[k] as usize]);
                k += 1;
            }
            self.solver.solve(&self.island_rows, bodies);
        }
    }

    /// Step 6: normal force, then friction, for every Continuous record; god-objects follow.
    fn forces(
        &mut self,
        dt: f64,
        bodies: &[Body],
        friction: &FrictionModel,
        wrenches: &mut [Wrench2],
    ) {
        for w in wrenches.iter_mut() {
            *w = Wrench2::default();
        }
        // The classical model needs every normal force first (its stick force cancels the other
        // forces on A); every other model runs normal then friction per contact in one pass.
        let needs_ext = friction.uses_external_force();
        let mut stored = 0.0;
        // Every record is Continuous here (Colliding ones were resolved by the impacts of step 5).
        let mut records = 0;
        for idx in 0..self.entries.len() {
            if self.entries[idx].state != Some(ContactState::Continuous) {
                continue;
            }
            records += 1;
            let e = &mut self.entries[idx];
            let law = self.laws.get_mut(e.law);
            let input = NormalInput {
                d: e.d,
                hist: e.hist,
                c0: e.c0,
                dt,
                m_eff: e.m_eff,
            };
            e.f_n = law.normal.force(&input);
            add_force(wrenches, bodies, e.body_a, e.body_b, e.n * e.f_n, e.point);
            if !needs_ext {
                friction_step(e, law, dt, 0.0, wrenches, bodies);
                stored += law.normal.stored_energy() + law.friction.stored_energy();
            }
        }
        if needs_ext {
            for (i, b) in bodies.iter().enumerate() {
                self.nonfric[i] = b.force + wrenches[i].force;
            }
            for idx in 0..self.entries.len() {
                if self.entries[idx].state != Some(ContactState::Continuous) {
                    continue;
                }
                let f_ext_t = self.external_share(idx);
                let e = &mut self.entries[idx];
                let law = self.laws.get_mut(e.law);
                friction_step(e, law, dt, f_ext_t, wrenches, bodies);
                stored += law.normal.stored_energy() + law.friction.stored_energy();
            }
        }
        self.stored = stored;
        self.record_count = records;
    }

    /// `F_ext,t,i = (t·F_A^nonfric)/n_t` for the classical model (§4.1): the non-friction force on A
    /// along this contact's tangent, shared by A's contacts with parallel tangents.
    fn external_share(&self, idx: usize) -> f64 {
        let e = &self.entries[idx];
        let n_t = self
            .entries
            .iter()
            .filter(|o| {
                o.state == Some(ContactState::Continuous)
                    && o.body_a == e.body_a
                    && o.t.dot(e.t).abs() > 0.99
            })
            .count()
            .max(1);
        e.t.dot(self.nonfric[e.body_a]) / n_t as f64
    }
}

/// Friction force of one Continuous record for this sample (after its normal force), and its
/// god-object (§8.3).
#[inline]
fn friction_step(
    e: &mut VeContact,
    law: &mut LawState,
    dt: f64,
    f_ext_t: f64,
    wrenches: &mut [Wrench2],
    bodies: &[Body],
) {
    let input = FrictionInput {
        ds: e.s - e.s_prev,
        s: e.s,
        s0: e.s0,
        fn_: e.f_n,
        dt,
        f_ext_t,
    };
    e.f_t = law.friction.update(&input);
    e.s_g = law.friction.anchor(e.s).unwrap_or(e.s.clamp(0.0, e.len));
    if e.f_t != 0.0 {
        add_force(wrenches, bodies, e.body_a, e.body_b, e.t * e.f_t, e.point);
    }
}

#[inline]
fn same_group(a: &VeCandidate, b: &VeCandidate) -> bool {
    a.vertex_collider == b.vertex_collider
        && a.vertex == b.vertex
        && a.edge_collider == b.edge_collider
}

fn add_force(w: &mut [Wrench2], bodies: &[Body], a: usize, b: usize, f: Vec2, p: Vec2) {
    w[a].force += f;
    w[a].torque += cross(p - bodies[a].pose.pos, f);
    w[b].force -= f;
    w[b].torque -= cross(p - bodies[b].pose.pos, f);
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

/// The depth invariant of [`ContactSet::step`] for the pair `key` at the current poses:
/// `d_e ≥ max_j d_j − δ_c` over the edge collider's lines `j`, or the face-on-face case
/// ([`face_on_face_ok`]).
#[inline]
fn depth_ok(key: VeCandidate, colliders: &[Collider], delta_c: f64, cos_parallel: f64) -> bool {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let p = ca.world_vertices[key.vertex as usize];
    cb.edge_distance(key.edge as usize, p) >= nearest_line(cb, p).1 - delta_c
        || face_on_face_ok(key, colliders, delta_c, cos_parallel)
}

/// The face-on-face exception of the depth invariant ([`ContactSet::step`]): edge `e` faces an
/// edge of A at the vertex (`n_e·n_A < −cos_parallel`) and the record is no deeper than the
/// pair's separating-axis depth plus `δ_c`. The SAT depth costs `O((n_a + n_b)²)`, so this runs
/// only where the nearest-line test has failed (a stack compressed past `δ_c`).
fn face_on_face_ok(
    key: VeCandidate,
    colliders: &[Collider],
    delta_c: f64,
    cos_parallel: f64,
) -> bool {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let (v, e) = (key.vertex as usize, key.edge as usize);
    let n = cb.world_normals[e];
    let faces = n.dot(ca.world_normals[v]) < -cos_parallel
        || n.dot(ca.world_normals[ca.local.prev(v)]) < -cos_parallel;
    faces && -cb.edge_distance(e, ca.world_vertices[v]) <= sat_depth(ca, cb) + delta_c
}

/// Starts the record a hand-over moves to (see `ContactSet::hand_over`): Continuous (the vertex
/// is already in contact, so this is no impact), god-object at the projection. The caller gives it
/// its law states.
fn start_handed_over(e: &mut VeContact, tick: u64, events: &mut Vec<ContactEvent>) {
    e.state = Some(ContactState::Continuous);
    e.since = tick;
    e.m_eff = 0.0;
    e.s_g = e.s.clamp(0.0, e.len);
    e.s_entry = e.s_g;
    events.push(ContactEvent {
        tick,
        key: e.key,
        kind: EventKind::Created(ContactState::Continuous),
    });
}

/// World geometry of a VE pair now: `(V, E0, n, t, L)`.
#[inline]
fn geometry(key: VeCandidate, colliders: &[Collider]) -> (Vec2, Vec2, Vec2, Vec2, f64) {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let e = key.edge as usize;
    (
        ca.world_vertices[key.vertex as usize],
        cb.world_vertices[e],
        cb.world_normals[e],
        cb.world_tangents[e],
        cb.local.lengths()[e],
    )
}

/// Signed distance and edge coordinate of a VE pair at past poses `pa` (vertex body), `pb` (edge body).
#[inline]
fn past_ds(key: VeCandidate, colliders: &[Collider], pa: &Pose, pb: &Pose) -> (f64, f64) {
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

/// Re-measures an existing entry: shifts the histories and refreshes geometry and velocities from
/// the body poses (`rots[i]` is body `i`'s rotation this sample).
#[inline]
fn measure(e: &mut VeContact, bodies: &[Body], rots: &[Rot]) {
    let (ba, bb) = (&bodies[e.body_a], &bodies[e.body_b]);
    let (ra, rb) = (rots[e.body_a], rots[e.body_b]);
    let v = ba.pose.pos + ra.apply(e.local.v);
    let e0 = bb.pose.pos + rb.apply(e.local.e0);
    let n = rb.apply(e.local.n);
    let t = rb.apply(e.local.t);
    let rel = v - e0;
    e.d = [n.dot(rel), e.d[0], e.d[1]];
    e.hist = (e.hist + 1).min(3);
    e.s_prev = e.s;
    e.s = t.dot(rel);
    e.point = v;
    e.n = n;
    e.t = t;
    let v_rel = ba.point_velocity(v) - bb.point_velocity(v);
    e.c0 = n.dot(v_rel);
    e.s0 = t.dot(v_rel);
}

/// A new tracked entry; its distance history and previous edge coordinate are rebuilt from the past
/// poses, so the SEH estimate has full history even for a pair first seen in contact.
fn new_entry(
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
        t: cb.tangents()[key.edge as usize],
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
        s: s0,
        s_prev,
        len,
        point: v,
        n,
        t,
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
    let n_e = cb.world_normals[e];
    let twins = [(cb.local.next(e), v), (e, ca.local.prev(v))];
    twins.into_iter().any(|(w, e_a)| {
        if n_e.dot(ca.world_normals[e_a]) >= -cos_parallel {
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
    for e in 0..cb.len() {
        let k = VeCandidate {
            edge: e as u32,
            ..key
        };
        let (_, e0, n, t, len) = geometry(k, colliders);
        let v = ca.world_vertices[key.vertex as usize];
        let (d_now, s_now) = (n.dot(v - e0), t.dot(v - e0));
        let (d_prev, s_prev) = past_ds(k, colliders, pa, pb);
        if d_prev > 0.0 && d_now <= 0.0 {
            let lam = d_prev / (d_prev - d_now);
            let s_cross = crossing_coordinate(d_prev, d_now, s_prev, s_now);
            if s_cross >= -eps_s && s_cross <= len + eps_s && best.is_none_or(|(l, _)| lam < l) {
                best = Some((lam, e as u32));
            }
        }
    }
    best.map(|(_, e)| e)
}
