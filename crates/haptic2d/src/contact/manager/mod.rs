//! The contact set: tracked VE pairs and contact records, their state machine (§8.2), god-objects
//! (§8.3), simultaneous impacts (§7) and continuous-contact forces (§5.9, §1–§4).
//!
//! Entries are kept sorted by `(vertex collider, vertex, edge collider, edge)`; every loop runs in that
//! order, so the result does not depend on anything but the inputs. After warm-up no step allocates:
//! the buffers are swapped and reused.
//!
//! The step runs in stages, one file each, in the order of the spec (called in this order by
//! [`ContactSet::step`]): [`sync`] (merge and measure), [`release`] (§8.2 rules 4–5), [`hand_over`]
//! (the depth invariant), [`create`] (§8.2 rules 1–2, §8.3), [`clip`] (crossing corners held on the separating axis, §9.5b), [`impacts`] (§7), [`forces`] (§1–§4,
//! §5.9); [`invariant`] holds the depth invariant's checks.
//!
//! The merge's pass, which measures every pair, also applies the tests of release, hand-over
//! and create to what it measured (`sync::StageWork`); a stage none of whose tests passes is not
//! run, so a contact set at rest makes two passes over its records a sample (merge and measure,
//! forces) instead of five. The merge changes the set in place, moving only the entries
//! between its changes.

mod clip;
mod create;
mod forces;
mod hand_over;
mod impacts;
mod invariant;
mod release;
mod reserve;
mod sync;

use crate::collide::{VeCandidate, DEFAULT_DELTA_C, NEAR_PARALLEL_ANGLE};
use crate::contact::impact::{ImpactRow, ImpactSolver};
use crate::contact::law_pool::LawPool;
use crate::contact::params::ContactParams;
use crate::contact::record::{
    ContactEvent, ContactState, EventKind, LawState, Loaded, LoadedContact, VeContact, NO_LAW,
};
use crate::geom::{Pose, Vec2};
use crate::stage_time::{Lap, Stage};
use crate::world::StepContext;

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
    /// The Continuous records that pushed in the last force pass (not struck in it, not approaching
    /// faster than `v_c`), in key order, their keys, and
    /// the number of the keys' version ([`Loaded`]).
    loaded: Vec<LoadedContact>,
    loaded_keys: Vec<VeCandidate>,
    loaded_generation: u64,
    /// Law states of the records, addressed by [`VeContact::law`].
    laws: LawPool,
    /// The differences the last merge found (`sync`), reused.
    changes: Vec<sync::Change>,
    pending: Vec<VeContact>,
    /// Scratch of `clip_crossing`: the pairs to test, and one pair's clip keys.
    crossing: Vec<(u32, u32)>,
    /// Per pair of `crossing`: deepest record (m), any Colliding, any record clearing it.
    crossing_info: Vec<(f64, bool, bool)>,
    /// Per collider: whether it is in a pair of `crossing` (all false between samples).
    crossing_mark: Vec<bool>,
    clip_keys: Vec<VeCandidate>,
    /// Effective depths handed from released records to a crossing pair's clip records (`clip`),
    /// and the records released out of their edge range this sample, with their pair (a < b).
    pool: Vec<f64>,
    dropped: Vec<((u32, u32), f64)>,
    events: Vec<ContactEvent>,
    rows: Vec<ImpactRow>,
    /// The entries (indices) of this sample's impact set, ascending (empty without an impact).
    row_entry: Vec<usize>,
    /// The entries of this sample's colliding records, ascending: the chain damper leaves them
    /// alone (issue 35).
    struck_entry: Vec<usize>,
    /// The colliding rows of this sample's impact set with restitution 0: the contacts that carry
    /// the sample's forces (`carry_forces`), and scratch twists of the carry.
    carry_rows: Vec<ImpactRow>,
    carry_saved: Vec<(Vec2, f64)>,
    carry_delta: Vec<(Vec2, f64)>,
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
    /// Run release, hand-over and create every sample, whatever the merge saw (for tests).
    #[cfg(test)]
    every_stage: bool,
    /// Samples in which the merge saw nothing for release, hand-over and create (for tests).
    #[cfg(test)]
    idle_samples: u64,
}

impl ContactSet {
    /// An empty contact set.
    pub fn new(params: ContactParams) -> Self {
        Self {
            params,
            entries: Vec::with_capacity(64),
            loaded: Vec::with_capacity(64),
            loaded_keys: Vec::with_capacity(64),
            loaded_generation: 0,
            laws: LawPool::with_capacity(64),
            changes: Vec::with_capacity(64),
            pending: Vec::with_capacity(16),
            crossing: Vec::with_capacity(16),
            crossing_info: Vec::with_capacity(16),
            crossing_mark: Vec::new(),
            clip_keys: Vec::with_capacity(16),
            pool: Vec::with_capacity(16),
            dropped: Vec::with_capacity(16),
            events: Vec::with_capacity(64),
            rows: Vec::with_capacity(16),
            row_entry: Vec::with_capacity(16),
            struck_entry: Vec::with_capacity(16),
            carry_rows: Vec::with_capacity(16),
            carry_saved: Vec::new(),
            carry_delta: Vec::new(),
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
            #[cfg(test)]
            every_stage: false,
            #[cfg(test)]
            idle_samples: 0,
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

    /// The Continuous records whose normal law pushed in the last sample (`f_n > 0`), were not
    /// struck in it and do not approach faster than `v_c` (issue 35, docs/MODELS.md §7.6), in key
    /// order, with what later passes need of them (the chain damper).
    #[inline]
    pub fn loaded(&self) -> Loaded<'_> {
        Loaded {
            contacts: &self.loaded,
            keys: &self.loaded_keys,
            generation: self.loaded_generation,
        }
    }

    /// The contact records (Colliding or Continuous), sorted by key.
    pub fn records(&self) -> impl Iterator<Item = &VeContact> {
        self.entries.iter().filter(|e| e.is_contact())
    }

    /// Stores the law states in the whole form from now on (`LawPool`), for the crate's tests.
    #[cfg(test)]
    pub(crate) fn widen_law_slots(&mut self) {
        self.laws.widen();
    }

    /// Stores the law states in the compact form from now on (`LawPool`), for the crate's tests.
    #[cfg(test)]
    pub(crate) fn compact_law_slots(&mut self) {
        self.laws.leave_lean();
    }

    /// Runs release, hand-over and create in every sample from now on, as if the merge had seen
    /// work for each (`StageWork`), for the crate's tests.
    #[cfg(test)]
    pub(crate) fn run_every_stage(&mut self) {
        self.every_stage = true;
    }

    /// Samples so far in which the merge saw nothing for release, hand-over and create.
    #[cfg(test)]
    pub(crate) fn idle_samples(&self) -> u64 {
        self.idle_samples
    }

    /// Counts a sample whose merge saw nothing for release, hand-over and create, and returns
    /// the stages to run: all of them with [`run_every_stage`](Self::run_every_stage).
    #[cfg(test)]
    fn observed(&mut self, work: sync::StageWork) -> sync::StageWork {
        self.idle_samples += u64::from(work == sync::StageWork::default());
        if self.every_stage {
            return sync::StageWork {
                release: true,
                hand_over: true,
                create: true,
            };
        }
        work
    }

    /// The form the law states are stored in (`LawPool`).
    #[cfg(test)]
    pub(crate) fn law_slot_form(&self) -> crate::contact::law_pool::SlotForm {
        self.laws.form()
    }

    /// A copy of the law states of record `e` (an entry of [`entries`](Self::entries)); `None` for
    /// a pair that is only tracked.
    pub fn laws(&self, e: &VeContact) -> Option<LawState> {
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

    /// Number of differences the last sample's merge found between the tracked pairs and the
    /// local stage's candidates (pairs dropped plus pairs added; 0 when the set was kept as it
    /// was), for profiling.
    #[inline]
    pub fn last_merge_changes(&self) -> usize {
        self.changes.len()
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

    /// What the impact solver's work budget did so far (docs/MODELS.md §7.7): row updates of
    /// large islands, phases the budget cut short, islands whose restitution it scaled.
    pub fn impact_budget(&self) -> crate::contact::impact::BudgetCounters {
        self.solver.budget_counters()
    }

    /// Energy stored in all contact and friction springs after the last step (J).
    pub fn stored_energy(&self) -> f64 {
        self.stored
    }

    /// Steps 4–6 of §0.5 for one sample: merge the local stage's candidates into the tracked set and
    /// measure every pair, run the state machine, resolve impacts (velocity jumps applied to `bodies`
    /// now), then compute continuous-contact forces into `wrenches` (one per body, overwritten).
    /// `from_scan` (parallel to `candidates`, as
    /// [`LocalStage::from_vertex_scan`](crate::collide::LocalStage::from_vertex_scan) gives it;
    /// empty = none) marks the candidates of the local stage's vertex scan, whose records need no
    /// hand-over check.
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
    /// in B than the pair's penetration depth; `j` over B's surface lines, seams left out,
    /// `collide/seam.rs`). Or the overlap bound (issue 35): `−d_e ≤ depth_SAT + δ_c` for any
    /// edge. It covers faces on faces (a landing 10-box stack compresses its faces by 2.02 mm
    /// with `V` at `±1e-19 m` from the side line) and crossing corners, where a record on the
    /// edge its vertex crossed keeps pushing within the pair's overlap instead of being handed
    /// to a shallower line; a far edge breaks it. Candidates satisfy it where they are made (the
    /// local stage's nearest-line rule); `create` checks it for the edge it picks (the crossed-edge
    /// rule may pick another one); `hand_over` moves a record whose vertex has come nearer to
    /// another line of B by more than `δ_c` to that edge (or releases it if the vertex is outside
    /// B): its stored energy then drops, never rises. Debug builds assert the invariant for every
    /// record at the end of every sample.
    ///
    /// Everything the stage reads and writes of the world comes in one borrowed
    /// [`StepContext`] (Box2D's `b2StepContext`).
    pub fn step(&mut self, ctx: StepContext<'_>) {
        let StepContext {
            tick,
            dt,
            candidates,
            from_scan,
            colliders,
            bodies,
            rots,
            past,
            normal,
            friction,
            wrenches,
            times,
        } = ctx;
        let past = &past;
        let mut lap = Lap::start();
        self.events.clear();
        self.dropped.clear();
        self.last_impact_loss = 0.0;
        self.row_entry.clear();
        self.struck_entry.clear();
        self.carry_rows.clear();
        self.resize_body_buffers(bodies.len());
        self.laws.prepare(normal, friction);
        let work = self.sync(tick, candidates, from_scan, colliders, bodies, rots, past);
        lap.charge(times, Stage::ContactSync);
        #[cfg(test)]
        let work = self.observed(work);
        // Each of the next three stages is a pass over every record; the merge's pass has
        // already seen whether it would change anything (`StageWork`).
        if work.release {
            self.release(tick, colliders);
        }
        if work.hand_over {
            self.hand_over(tick, colliders, bodies, past, normal, friction);
        }
        // `create` also runs after a release or hand-over event: a vertex that lost its record
        // may start another one in the same sample.
        let any_colliding = (work.create || !self.events.is_empty())
            && self.create(tick, dt, colliders, bodies, past, normal, friction);
        // Crossing corners: a pair overlapping deeper than its records is held on its
        // separating axis (`clip`, issue 35).
        self.clip_crossing(tick, colliders, bodies, past, normal, friction);
        if any_colliding {
            // Impact friction mode and coefficient (default μ = the friction model's μ_k; docs/MODELS.md §E).
            let mu = (self.params.impact_mu)
                .unwrap_or_else(|| crate::contact::default_impact_mu(friction));
            self.solver.set_friction(self.params.impact_friction, mu);
            self.solver
                .set_sweep_budget(self.params.impact_sweeps as usize);
            self.solver
                .set_sample_rows(self.params.impact_row_budget(dt));
            self.resolve_impacts(tick, bodies);
        }
        lap.charge(times, Stage::ContactEvents);
        self.forces(dt, bodies, friction, wrenches);
        lap.charge(times, Stage::ContactForces);
        #[cfg(debug_assertions)]
        self.assert_depth_invariant(colliders);
    }

    fn resize_body_buffers(&mut self, n: usize) {
        if self.body_flag.len() != n {
            self.body_flag.resize(n, false);
            self.parent.resize(n, 0);
            self.new_count.resize(n, 0);
            self.nonfric.resize(n, Vec2::ZERO);
            self.carry_saved.reserve(n);
            self.carry_delta.reserve(n);
        }
    }
}

/// Ends the contact of record `e` at `tick` (§8.2 rule 4, and the record a hand-over or a clip
/// leaves): no state, its law slot back to `laws`, zero forces (N), a `Released` event.
#[inline]
fn release_record(
    e: &mut VeContact,
    laws: &mut LawPool,
    events: &mut Vec<ContactEvent>,
    tick: u64,
) {
    e.state = None;
    laws.release(e.law);
    e.law = NO_LAW;
    e.f_n = 0.0;
    e.f_t = 0.0;
    events.push(ContactEvent {
        tick,
        key: e.key,
        kind: EventKind::Released,
    });
}

/// Starts the record a hand-over or a clip moves to (`ContactSet::hand_over`, `clip.rs`):
/// Continuous (the vertex is already in contact, so this is no impact), god-object at the
/// projection, a `Created(Continuous)` event. The caller gives it its law states.
#[inline]
fn start_continuous(e: &mut VeContact, tick: u64, events: &mut Vec<ContactEvent>) {
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

/// A 0.1 m box (body and collider 0, at `box_pose`) over a fixed 2 m × 0.2 m floor (body and
/// collider 1, at `floor_pose`), and the key of the box's vertex 1 against the floor's top edge
/// (edge 2), for the stages' tests.
#[cfg(test)]
fn box_on_floor(
    box_pose: Pose,
    floor_pose: Pose,
) -> (
    Vec<crate::body::Body>,
    Vec<crate::collide::Collider>,
    VeCandidate,
) {
    use crate::{body::Body, collide::Collider, geom::ConvexPolygon};
    let bodies = vec![
        Body::dynamic("box", 1.0, 1e-3, box_pose),
        Body::fixed("floor", floor_pose),
    ];
    let colliders = vec![
        Collider::new(
            0,
            true,
            ConvexPolygon::rectangle(0.1, 0.1).unwrap(),
            &box_pose,
        ),
        Collider::new(
            1,
            false,
            ConvexPolygon::rectangle(2.0, 0.2).unwrap(),
            &floor_pose,
        ),
    ];
    let key = VeCandidate {
        vertex_collider: 0,
        vertex: 1,
        edge_collider: 1,
        edge: 2,
    };
    (bodies, colliders, key)
}

/// The tracked pair `key` measured now, without past poses (`sync::new_entry`), for the stages'
/// tests.
#[cfg(test)]
fn fresh_entry(
    key: VeCandidate,
    colliders: &[crate::collide::Collider],
    bodies: &[crate::body::Body],
) -> VeContact {
    let past = PastPoses {
        prev: &[],
        prev2: &[],
    };
    sync::new_entry(0, key, colliders, bodies, &past)
}

#[cfg(test)]
mod tests {
    use crate::contact::record::{ContactState, EventKind};
    use crate::contact::test_pile::{assert_same_poses, shove, toss_top_box};
    use crate::world::World;

    /// Steps `fast` (stages skipped when the merge saw nothing for them) and `every` (every
    /// stage every sample) `n` times, applying `poke` to both before step `k`, and asserts
    /// that their tracked pairs, records and events are the same, sample by sample. Returns the
    /// samples in which `fast` skipped all three stages, and the events `every` saw.
    fn same_with_every_stage(
        world: World,
        n: usize,
        poke: impl Fn(usize, &mut World),
    ) -> (u64, Vec<EventKind>) {
        let (mut fast, mut every) = (world.clone(), world);
        every.contacts_mut().run_every_stage();
        let mut kinds = Vec::new();
        for k in 0..n {
            poke(k, &mut fast);
            poke(k, &mut every);
            fast.step();
            every.step();
            let (a, b) = (fast.contacts(), every.contacts());
            assert_eq!(a.events(), b.events(), "events at step {k}");
            assert_eq!(
                format!("{:?}", a.entries()),
                format!("{:?}", b.entries()),
                "entries at step {k}"
            );
            assert_same_poses(&fast, &every, k);
            kinds.extend(b.events().iter().map(|e| e.kind));
        }
        assert_eq!(
            every.contacts().idle_samples(),
            fast.contacts().idle_samples()
        );
        (fast.contacts().idle_samples(), kinds)
    }

    /// Skipping release, hand-over and create where the merge's pass saw nothing for them changes
    /// no record, event or pose: a pile:20 that falls, settles, is shoved sideways and has its
    /// top box tossed up (impacts, releases, creations), 50 random polygons dropped in a box
    /// (the repro of issue 10's energy gain), and a triangle's record handed over to a nearer
    /// edge of a square.
    #[test]
    fn skipping_stages_with_nothing_to_do_changes_no_record() {
        let pile = crate::scene::builtin("pile:20", None)
            .unwrap()
            .unwrap()
            .world;
        let (idle, kinds) = same_with_every_stage(pile, 2500, |k, w| match k {
            1200 => shove(w),
            1800 => toss_top_box(w),
            _ => {}
        });
        let count = |f: fn(&EventKind) -> bool| kinds.iter().filter(|k| f(k)).count();
        assert!(count(|k| matches!(k, EventKind::Released)) > 0, "releases");
        assert!(
            count(|k| matches!(k, EventKind::Created(_))) > 20,
            "creations"
        );
        assert!(
            idle > 1000,
            "the settled pile skips the stages ({idle} samples)"
        );

        let text = include_str!("../../../tests/repro/r8-polygon-drop-energy.toml");
        let polygons = crate::scene::Scene::from_toml(text, "r8", None)
            .unwrap()
            .world;
        let (idle, kinds) = same_with_every_stage(polygons, 1500, |_, _| {});
        assert!(kinds.len() > 20, "{} events", kinds.len());
        assert!(
            idle > 100,
            "polygons at rest skip the stages ({idle} samples)"
        );

        // A hand-over: the tip of a triangle resting on a square's top edge is carried 11 mm
        // below it, 1 mm inside the right edge (`tests/it/repro_contacts.rs`).
        let text = include_str!("../../../tests/repro/hand-over-triangle.toml");
        let tri = crate::scene::Scene::from_toml(text, "hand-over", None)
            .unwrap()
            .world;
        let (_, kinds) = same_with_every_stage(tri, 200, |k, w| {
            if k == 100 {
                w.bodies[1].pose.pos += crate::geom::Vec2::new(0.004, -0.0115);
                w.bodies[1].vel = crate::geom::Vec2::ZERO;
            }
        });
        // The hand-over's events: the record released, then one started Continuous (with
        // impacts off a plain creation is Continuous too, but no release comes before it).
        let handed = [
            EventKind::Released,
            EventKind::Created(ContactState::Continuous),
        ];
        assert!(
            kinds.windows(2).any(|w| w == handed),
            "handed over: {kinds:?}"
        );
    }
}
