//! The world: bodies, colliders, loads and contact laws, stepped once per haptic sample in the order of
//! MODELS §0.5 (steps 3–6, then 10–12), with an energy ledger.
//!
//! For a world-only simulation call [`World::step`]. Inside the haptic loop the controller sits between
//! contact forces and integration (§0.5 step 7), so the tick calls [`World::begin_step`], reads the slave
//! state and contact wrench, sets the drive with [`World::set_drive`], then calls [`World::finish_step`].
//!
//! The folder holds one concept a file: the two halves of a sample as a list of
//! numbered stages (`step.rs`), the borrowed [`StepContext`] the contact stage runs on
//! (`context.rs`), and the state each stage keeps between samples: the proximity stage's schedule
//! (`proximity.rs`), the swept test (`swept.rs`), the passivity guard (`guard.rs`) and the
//! applied loads and drives (`applied.rs`). Every step ends with the divergence check (§0.5
//! step 12): a world that has diverged reports it ([`World::divergence`]) and stays as it was.

mod applied;
mod context;
mod guard;
mod params;
mod proximity;
mod step;
mod swept;

pub use context::StepContext;
pub use params::{WorldParams, CHAIN_BUDGET_SHARE, CHAIN_ROW_UPDATES_PER_S, CHAIN_ROW_UPDATE_NS};

use crate::body::Body;
use crate::collide::{mark_seams, speed_limit, Collider, LocalStage};
use crate::contact::solver::ChainDamping;
use crate::contact::{ContactSet, VeContact, Wrench2};
use crate::geom::{Pose, Rot, Vec2};
use crate::integrate::EnergyLedger;
use crate::laws::friction::FrictionModel;
use crate::laws::normal::NormalModel;
use crate::load::Load;
use crate::scene::Divergence;
use crate::stage_time::StageTimes;

use applied::Applied;
use guard::GuardStage;
use proximity::Proximity;
use swept::SweptTest;

/// A planar world of rigid bodies simulated passively at the control rate.
#[derive(Clone, Debug)]
pub struct World {
    /// Bodies; index = body id.
    pub bodies: Vec<Body>,
    /// Convex collision shapes; several may belong to one body.
    pub colliders: Vec<Collider>,
    /// Applied loads.
    pub loads: Vec<Load>,
    /// Prototype of the normal law; every new contact gets a copy.
    pub normal: NormalModel,
    /// Prototype of the friction model; every new contact gets a copy.
    pub friction: FrictionModel,
    /// Parameters.
    pub params: WorldParams,
    /// Step 3: the global proximity stage, its schedule, the pairs in use and the odometers.
    proximity: Proximity,
    /// Step 4: the local stage (closest features, VE candidates).
    local: LocalStage,
    /// Steps 4–6: contact records, states, impacts and forces.
    contacts: ContactSet,
    /// The loads of this sample and the drive, per body.
    applied: Applied,
    /// The contact wrench per body of the last step (N, N·m).
    contact_wrench: Vec<Wrench2>,
    /// Step 10b: the implicit chain damper.
    chain: ChainDamping,
    /// Step 10d: the swept test.
    swept: SweptTest,
    /// Step 11: the optional passivity guard.
    guard: GuardStage,
    /// Body poses at `k − 1` and `k − 2`.
    past: PoseHistory,
    /// Each body's rotation at the current pose.
    rots: Vec<Rot>,
    /// Step 11: the energy ledger.
    ledger: EnergyLedger,
    /// Wall time of each stage of the last step (zero without the `stage-timing` feature).
    stage_times: StageTimes,
    /// The sample index `k` of the next step.
    tick: u64,
    /// Steps 3–6 of the current tick have run ([`World::begin_step`] or [`World::prime`]) and
    /// [`World::finish_step`] has not yet.
    begun: bool,
    /// Step 12: the first divergence found; the world does not step after it.
    diverged: Option<Divergence>,
}

/// The body poses of the two samples before this one (buffers reused).
#[derive(Clone, Debug, Default)]
struct PoseHistory {
    /// Poses at `k − 1` (empty before the first step).
    prev: Vec<Pose>,
    /// Poses at `k − 2` (empty before the second step).
    prev2: Vec<Pose>,
}

impl World {
    /// A world with the given bodies (each with its pieces, in the body frame) and laws.
    ///
    /// `shapes[i]` lists the convex pieces of body `i`, expressed in its centre-of-mass frame.
    pub fn new(
        bodies: Vec<Body>,
        shapes: Vec<Vec<crate::geom::ConvexPolygon>>,
        loads: Vec<Load>,
        normal: NormalModel,
        friction: FrictionModel,
        params: WorldParams,
    ) -> Self {
        let mut colliders = Vec::new();
        for (i, pieces) in shapes.into_iter().enumerate() {
            for p in pieces {
                colliders.push(Collider::new(i, bodies[i].is_dynamic(), p, &bodies[i].pose));
            }
        }
        // Internal edges of multi-piece bodies are never contact normals (`collide/seam.rs`).
        mark_seams(&mut colliders);
        let n = bodies.len();
        let colliders_len = colliders.len().max(4);
        let mut w = Self {
            guard: GuardStage::new(params.guard, &bodies),
            proximity: Proximity::new(&bodies, &colliders, &params),
            swept: SweptTest::new(n, &colliders),
            local: {
                let mut l = LocalStage::with_capacity(8 * colliders_len);
                // An invalid tolerance keeps the default; scene validation reports it.
                let _ = l.set_edge_tolerance(params.contact.eps_s);
                l
            },
            contacts: ContactSet::new(params.contact),
            applied: Applied::new(n),
            contact_wrench: vec![Wrench2::default(); n],
            chain: ChainDamping::default(),
            past: PoseHistory {
                prev: Vec::with_capacity(n),
                prev2: Vec::with_capacity(n),
            },
            rots: vec![Rot::IDENTITY; n],
            ledger: EnergyLedger::default(),
            stage_times: StageTimes::default(),
            tick: 0,
            begun: false,
            diverged: None,
            bodies,
            colliders,
            loads,
            normal,
            friction,
            params,
        };
        w.ledger.kinetic = w.bodies.iter().map(|b| b.kinetic_energy()).sum();
        w.ledger.initial = w.ledger.kinetic;
        w
    }

    /// The sample index `k` of the next step.
    #[inline]
    pub fn tick(&self) -> u64 {
        self.tick
    }
    /// Simulated time `k·T` (s).
    #[inline]
    pub fn time(&self) -> f64 {
        self.tick as f64 * self.params.dt
    }
    /// The energy ledger after the last step.
    #[inline]
    pub fn ledger(&self) -> &EnergyLedger {
        &self.ledger
    }
    /// Wall time of each stage of the last step (ns), for profiling: all zero unless the crate
    /// is built with the `stage-timing` feature ([`crate::stage_time`]). A step split by
    /// [`World::prime`] times its two halves separately, each when it runs.
    #[inline]
    pub fn stage_times(&self) -> &StageTimes {
        &self.stage_times
    }
    /// The contact set (tracked pairs and records).
    #[inline]
    pub fn contacts(&self) -> &ContactSet {
        &self.contacts
    }

    /// The contact set, for the crate's tests.
    #[cfg(test)]
    pub(crate) fn contacts_mut(&mut self) -> &mut ContactSet {
        &mut self.contacts
    }
    /// Whether impacts carry Coulomb friction (the scene's `contact.impact_friction`).
    pub fn impact_friction(&self) -> crate::contact::ImpactFriction {
        self.contacts.params.impact_friction
    }
    /// Sets the impact friction mode (the display's switch); impacts resolved from the next
    /// sample on use it. The coefficient stays the scene's `impact_mu` (default: the friction
    /// model's `μ_k`).
    pub fn set_impact_friction(&mut self, mode: crate::contact::ImpactFriction) {
        self.contacts.params.impact_friction = mode;
    }
    /// Contact records of the last step.
    pub fn contact_records(&self) -> impl Iterator<Item = &VeContact> {
        self.contacts.records()
    }
    /// The proximate collider pairs of the last global update.
    #[inline]
    pub fn proximate_pairs(&self) -> &[(u32, u32)] {
        &self.proximity.pairs
    }
    /// Work counters of the last published global update (AABB pairs, proximate pairs, GJK
    /// iterations).
    pub fn broad_stats(&self) -> crate::collide::BroadStats {
        self.proximity.stats()
    }
    /// The local stage (its pair states, trackers and the pairs it skipped in the last sample).
    pub fn local_stage(&self) -> &LocalStage {
        &self.local
    }
    /// The contact wrench on body `i` at the last step (N, N·m): the sum of normal and friction forces.
    /// The wrench the body applies to the environment, `f_e` of §11, is its negative.
    #[inline]
    pub fn contact_wrench(&self, i: usize) -> Wrench2 {
        self.contact_wrench[i]
    }
    /// The implicit chain damper: rows damped, sweeps run and warm-start scale of the last
    /// sample (`contact/solver/chain/`).
    #[inline]
    pub fn chain_damper(&self) -> &ChainDamping {
        &self.chain
    }

    /// Records the contact stage is given room for before a real-time loop
    /// ([`reserve_contacts`](Self::reserve_contacts)): twice the colliders' vertices. A contact
    /// record is a vertex against an edge it touches; a vertex touches one edge, two at a corner
    /// (pile:100 and pile:1000 peak at 0.84 and 0.97 records a vertex in their collapse).
    pub fn contact_room(&self) -> usize {
        2 * self
            .colliders
            .iter()
            .map(|c| c.world_vertices().len())
            .sum::<usize>()
    }

    /// Grows the contact stage's and the chain damper's per-record buffers to hold `records`
    /// records, so that the samples after it allocate nothing while the records stay within it
    /// (a landing pile's collapse grows them otherwise, inside a real-time loop's ticks). Changes
    /// no result: only capacities. Allocates.
    pub fn reserve_contacts(&mut self, records: usize) {
        self.contacts
            .reserve(records, self.colliders.len(), self.bodies.len());
        self.chain.reserve(records, self.bodies.len());
    }

    /// Number of passivity-guard triggers so far (0 if the guard is off).
    pub fn guard_triggers(&self) -> u64 {
        self.guard.guard.as_ref().map_or(0, |g| g.triggers)
    }
    /// Looks a body up by name.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Sets the drive wrench on body `i` (N, N·m at the COM), held until changed: the slave drive
    /// `f_cs` of the teleoperation controller, or any user force.
    pub fn set_drive(&mut self, i: usize, force: Vec2, torque: f64) {
        self.applied.drive[i] = Wrench2 { force, torque };
    }

    /// The divergence that stopped this world (§0.5 step 12), if any: the first body whose state
    /// became non-finite or left the divergence bounds ([`crate::scene::divergence`]), or a
    /// non-finite energy. Once set, [`step`](Self::step), [`begin_step`](Self::begin_step) and
    /// [`finish_step`](Self::finish_step) leave the world as it is.
    #[inline]
    pub fn divergence(&self) -> Option<&Divergence> {
        self.diverged.as_ref()
    }

    /// Initial speeds beyond what the settings guarantee, one message per body (empty if none):
    /// a body whose rim speed `|v| + |ω|·ρ` (m/s) moves it more than `(δ_prox − δ_c)/2` per
    /// sample can reach a pair the proximity set does not hold, and pass through it
    /// (`moved_past_margin`, `collide/toi.rs`). Loads can still accelerate a body past the limit
    /// later; this checks the state the scene starts in.
    pub fn speed_warnings(&self) -> Vec<String> {
        let dt = self.params.dt;
        let (dp, dc) = (self.proximity.delta_prox(), self.params.delta_c);
        let limit = speed_limit(dp, dc) / dt;
        let mut out = Vec::new();
        for (b, &r) in self.bodies.iter().zip(&self.proximity.radius) {
            let speed = b.vel.length() + b.omega.abs() * r;
            if b.is_dynamic() && speed > limit {
                out.push(format!(
                    "body \"{}\" starts at {speed:.3} m/s (|v| + |ω|·ρ), faster than the {limit:.3} m/s that \
                     rate {:.0} Hz, delta_prox {dp} m and delta_c {dc} m guarantee against tunnelling \
                     ((delta_prox − delta_c)/2 per sample); fix: raise world.rate or world.delta_prox",
                    b.name,
                    1.0 / dt
                ));
            }
        }
        out
    }

    /// Periodic global updates skipped so far because the proximity set in use was still exact
    /// ([`BroadPhase::still_exact`](crate::collide::BroadPhase::still_exact)).
    pub fn skipped_global_updates(&self) -> u64 {
        self.proximity.skipped_updates
    }

    /// The largest overlap of two bodies now: the separating-axis depth of the proximate pair
    /// that overlaps most (`collide/overlap.rs`; seams left out). What the contact records
    /// report can be less where corners or edges cross; this is the truth. Costs a SAT test per
    /// proximate pair whose boxes overlap: for reports, not the haptic loop.
    pub fn max_overlap(&self) -> crate::collide::Overlap {
        // Pairs the local stage certified apart have none (`max_overlap_of_states`); before the
        // first step it has no states yet.
        if self.local.pair_states().len() == self.proximity.pairs.len() && self.tick > 0 {
            crate::collide::max_overlap_of_states(&self.colliders, self.local.pair_states())
        } else {
            crate::collide::max_overlap(&self.colliders, &self.proximity.pairs)
        }
    }

    /// Samples at which the swept test put a body back, and whole global updates run early
    /// (because many bodies had moved past the margin), so far.
    pub fn continuous_stats(&self) -> (u64, u64) {
        (self.swept.hits, self.proximity.early_updates)
    }

    /// Partial global updates run so far (the pairs of the bodies that moved past the margin
    /// decided again, `collide/broad/partial.rs`), and the bodies they updated in all.
    pub fn partial_global_updates(&self) -> (u64, u64) {
        (
            self.proximity.partial_updates,
            self.proximity.partial_bodies,
        )
    }
}

/// A bound on how far any point of a body of vertex radius `radius` (m) moves between the poses
/// `from` and `to`: `|Δp| + |Δθ|·ρ` (m), since a rotation by `Δθ` moves a point at distance `ρ`
/// from the centre by `2ρ·|sin(Δθ/2)| ≤ |Δθ|·ρ`.
#[inline]
fn point_motion(from: &Pose, to: &Pose, radius: f64) -> f64 {
    (to.pos - from.pos).length() + (to.angle - from.angle).abs() * radius
}
