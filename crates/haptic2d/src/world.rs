//! The world: bodies, colliders, loads and contact laws, stepped once per haptic sample in the order of
//! §0.5 (steps 3–6, then 10–11), with an energy ledger.
//!
//! For a world-only simulation call [`World::step`]. Inside the haptic loop the controller sits between
//! contact forces and integration (§0.5 step 7), so the tick calls [`World::begin_step`], reads the slave
//! state and contact wrench, sets the drive with [`World::set_drive`], then calls [`World::finish_step`].

use crate::body::Body;
use crate::collide::{
    allowed_depth, body_thickness, mark_seams, speed_limit, swept_put_back, BroadPhase, Collider,
    LocalStage, SweepScratch, SweptShape, DEFAULT_DELTA_PROX,
};
use crate::contact::{ContactParams, ContactSet, PastPoses, VeContact, Wrench2};
use crate::geom::{Pose, Rot, Vec2};
use crate::integrate::{
    integrate_body, ChainDamping, EnergyLedger, IntegrationMode, PassivityGuard,
    DEFAULT_CHAIN_SWEEPS, DEFAULT_CHAIN_TAU,
};
use crate::laws::friction::FrictionModel;
use crate::laws::normal::NormalModel;
use crate::load::Load;
use crate::stage_time::{Lap, Stage, StageTimes};

/// Rates, margins and options of a world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldParams {
    /// Sample period `T` (s).
    pub dt: f64,
    /// Run the global proximity stage every `N_g` samples.
    pub proximity_every: u32,
    /// Spread the global proximity stage over the `N_g` samples of its period (default) instead
    /// of running it whole every `N_g`-th sample: every sample then costs about the same (no
    /// deadline spike), and the set in use describes the poses one period earlier, which the
    /// §9.1 margin allows (`collide/broad.rs`). Early updates for fast bodies still run whole.
    pub proximity_spread: bool,
    /// Skip a periodic global update when the colliders cannot have changed the proximity set
    /// since the published one (default): the vertices have moved less than half the smallest
    /// slack of that update's decisions ([`BroadPhase::still_exact`](crate::collide::BroadPhase::still_exact)).
    /// The set in use is then exactly what the update would compute, so trajectories are those
    /// of running it, up to the round-off of GJK's warm starts.
    pub proximity_skip: bool,
    /// Proximity margin `δ_prox` (m), §9.1.
    pub delta_prox: f64,
    /// Contact distance tolerance `δ_c` (m), §9.5.
    pub delta_c: f64,
    /// Integration mode (§6; exact-ZOH for harness scenes).
    pub mode: IntegrationMode,
    /// Passivity guard tolerance `ε_E` (J); `None` = guard off (default).
    pub guard: Option<f64>,
    /// Contact state machine and impact options.
    pub contact: ContactParams,
    /// Damping time `τ` (s) of the implicit chain damper (`integrate/chain_damping.rs`): contacts
    /// of bodies that touch two or more others get an extra normal damper `m_c/τ` on the
    /// end-of-sample velocity, so stacks come to rest. `None` = off. Default 0.2 ms.
    pub chain_tau: Option<f64>,
    /// Gauss–Seidel sweeps of the chain damper per sample, at most (they stop once no row's
    /// velocity changes by more than 2e-4 m/s; warm-started, a settled pile needs 1–4); default 16.
    pub chain_sweeps: u32,
}

impl Default for WorldParams {
    fn default() -> Self {
        Self {
            dt: 0.002,
            proximity_every: 10,
            proximity_spread: true,
            proximity_skip: true,
            delta_prox: 0.042,
            delta_c: 0.002,
            mode: IntegrationMode::SemiImplicit,
            guard: None,
            contact: ContactParams::default(),
            chain_tau: Some(DEFAULT_CHAIN_TAU),
            chain_sweeps: DEFAULT_CHAIN_SWEEPS,
        }
    }
}

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
    contacts: ContactSet,
    broad: BroadPhase,
    local: LocalStage,
    pairs: Vec<(u32, u32)>,
    /// The global stage may have written `pairs` since the local stage last read them (set by
    /// [`global_stage`](Self::global_stage), cleared once the local stage has read them).
    pairs_written: bool,
    drive: Vec<Wrench2>,
    contact_wrench: Vec<Wrench2>,
    /// Load wrench per body of the current sample.
    held: Vec<Wrench2>,
    prev: Vec<Pose>,
    prev2: Vec<Pose>,
    ledger: EnergyLedger,
    /// Wall time of each stage of the last step (zero without the `stage-timing` feature).
    stage_times: StageTimes,
    chain: ChainDamping,
    guard: Option<PassivityGuard>,
    ke_before: Vec<f64>,
    rots: Vec<Rot>,
    tick: u64,
    /// Largest vertex distance from the centre of mass, per body (m).
    radius: Vec<f64>,
    /// Minimum width of each collider (m), for the swept test.
    thickness: Vec<f64>,
    /// The smallest of `thickness` (m).
    thinnest: f64,
    /// Running bound on how far any point of each body has moved (m): `|Δp| + |Δθ|·ρ` between
    /// the poses of consecutive samples, however they changed (integration or a pose set from
    /// outside). The local stage skips separated pairs whose gap this cannot have closed.
    odometer: Vec<f64>,
    /// Poses at the last odometer reading.
    odometer_poses: Vec<Pose>,
    /// Body poses the proximity set in use was computed for.
    global_poses: Vec<Pose>,
    /// Body poses of the spread global update in progress (its snapshot).
    job_poses: Vec<Pose>,
    /// Velocities `(v, ω)` before this sample's integration, per body.
    vel_before: Vec<(Vec2, f64)>,
    /// Force and torque the passivity guard integrates, per body (pre-integration velocity).
    guard_force: Vec<Wrench2>,
    /// Point-motion bound of each body over this sample (m), for the swept test.
    motion: Vec<f64>,
    /// Fraction of the sample each body keeps after the swept test (1 = all of it).
    put_back: Vec<f64>,
    /// Scratch of the swept test.
    sweep: SweepScratch,
    /// Number of samples at which the swept test put a body back (see `collide/toi.rs`).
    swept_hits: u64,
    /// Number of global updates run early because a body had moved far (see `begin_step`).
    early_global_updates: u64,
    /// Periodic global updates skipped because the published set was still exact, and whether
    /// the last periodic one was.
    skipped_global_updates: u64,
    skipped_last_period: bool,
    /// Steps 3–6 of the current tick have run ([`World::begin_step`] or [`World::prime`]) and
    /// [`World::finish_step`] has not yet.
    begun: bool,
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
        let mut radius = vec![0.0f64; n];
        for c in &colliders {
            radius[c.body] = radius[c.body].max(c.local.radius());
        }
        let thickness: Vec<f64> = colliders.iter().map(|c| body_thickness(&c.local)).collect();
        let thinnest = thickness.iter().fold(f64::INFINITY, |a, &t| a.min(t));
        let max_vertices = colliders.iter().map(|c| c.len()).max().unwrap_or(4);
        let global_poses: Vec<Pose> = bodies.iter().map(|b| b.pose).collect();
        let mut w = Self {
            guard: params.guard.map(|eps| PassivityGuard::new(eps, &bodies)),
            bodies,
            colliders,
            loads,
            normal,
            friction,
            params,
            contacts: ContactSet::new(params.contact),
            broad: BroadPhase::with_capacity(params.delta_prox, 8 * colliders_len).unwrap_or_else(
                |_| {
                    BroadPhase::with_capacity(DEFAULT_DELTA_PROX, 8 * colliders_len)
                        .expect("the default margin is valid")
                },
            ),
            local: {
                let mut l = LocalStage::with_capacity(8 * colliders_len);
                // An invalid tolerance keeps the default; scene validation reports it.
                let _ = l.set_edge_tolerance(params.contact.eps_s);
                l
            },
            // Room for a typical contact load, so the first contacts do not allocate on the hot path.
            pairs: Vec::with_capacity(8 * colliders_len),
            pairs_written: true,
            drive: vec![Wrench2::default(); n],
            contact_wrench: vec![Wrench2::default(); n],
            held: vec![Wrench2::default(); n],
            prev: Vec::with_capacity(n),
            prev2: Vec::with_capacity(n),
            ledger: EnergyLedger::default(),
            stage_times: StageTimes::default(),
            chain: ChainDamping::default(),
            ke_before: vec![0.0; n],
            rots: vec![Rot::IDENTITY; n],
            tick: 0,
            radius,
            thickness,
            thinnest,
            odometer: vec![0.0; n],
            odometer_poses: global_poses.clone(),
            job_poses: global_poses.clone(),
            global_poses,
            vel_before: vec![(Vec2::ZERO, 0.0); n],
            guard_force: vec![Wrench2::default(); n],
            motion: vec![0.0; n],
            put_back: vec![1.0; n],
            sweep: SweepScratch::with_capacity(max_vertices),
            swept_hits: 0,
            early_global_updates: 0,
            skipped_global_updates: 0,
            skipped_last_period: false,
            begun: false,
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
        &self.pairs
    }
    /// Work counters of the last published global update (AABB pairs, proximate pairs, GJK
    /// iterations).
    pub fn broad_stats(&self) -> crate::collide::BroadStats {
        self.broad.stats()
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
    /// sample (`integrate/chain_damping.rs`).
    #[inline]
    pub fn chain_damper(&self) -> &ChainDamping {
        &self.chain
    }
    /// Number of passivity-guard triggers so far (0 if the guard is off).
    pub fn guard_triggers(&self) -> u64 {
        self.guard.as_ref().map_or(0, |g| g.triggers)
    }
    /// Looks a body up by name.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Sets the drive wrench on body `i` (N, N·m at the COM), held until changed: the slave drive
    /// `f_cs` of the teleoperation controller, or any user force.
    pub fn set_drive(&mut self, i: usize, force: Vec2, torque: f64) {
        self.drive[i] = Wrench2 { force, torque };
    }

    /// Computes the state at `t = 0` before the first row is written: proximity, contacts (with
    /// their impacts, if bodies start approaching in contact), contact forces and the stored
    /// energy, i.e. [`begin_step`](Self::begin_step) of sample 0; the next `begin_step` (or
    /// [`step`](Self::step)) then goes straight on to its integration. Afterwards the ledger's
    /// `stored` and `initial` include the energy of bodies that start interpenetrating, and
    /// [`ContactSet::contact_count`] their records, so a `t = 0` log row reports them (the built-in
    /// peg-in-hole starts with 1 mm of overlap on 4 contacts: `4·½·K_c·(1 mm)²`).
    ///
    /// Call it after the world is set up (bodies, drives, parameters) and before the first row;
    /// calling it again before a step does nothing more. Idempotent, and a no-op between
    /// `begin_step` and `finish_step`.
    pub fn prime(&mut self) {
        if !self.begun {
            self.begin_step();
        }
        self.ledger.stored = self.contacts.stored_energy();
    }

    /// One full sample: [`begin_step`](Self::begin_step) then [`finish_step`](Self::finish_step).
    pub fn step(&mut self) {
        self.begin_step();
        self.finish_step();
    }

    /// §0.5 steps 3–6: proximity (every `N_g` samples), local contacts, contact states, impacts
    /// (velocities jump now), and continuous-contact forces.
    ///
    /// Does nothing if steps 3–6 of this sample have run already ([`World::prime`]).
    pub fn begin_step(&mut self) {
        if self.begun {
            return;
        }
        self.begun = true;
        let dt = self.params.dt;
        self.stage_times = StageTimes::default();
        let mut lap = Lap::start();
        // 0. Body rotations and the world-frame features of every collider at the current poses.
        for (r, b) in self.rots.iter_mut().zip(&self.bodies) {
            *r = b.pose.rot();
        }
        for c in self.colliders.iter_mut() {
            c.update_with(&self.bodies[c.body].pose, self.rots[c.body]);
        }
        // The odometers: a running bound on how far any point of each body has moved (m), read
        // by the global stage to skip GJK where the motion cannot have changed its result.
        for ((odo, last), (b, &r)) in self
            .odometer
            .iter_mut()
            .zip(self.odometer_poses.iter_mut())
            .zip(self.bodies.iter().zip(&self.radius))
        {
            *odo += point_motion(last, &b.pose, r);
            *last = b.pose;
        }
        // 3. Global proximity stage: AABB sort-and-sweep + GJK, every N_g samples, and early when
        //    a body may have outrun the margin (`moved_past_margin`).
        lap.charge(&mut self.stage_times, Stage::Poses);
        self.global_stage();
        lap.charge(&mut self.stage_times, Stage::Global);
        // 4. Local stage: closest-feature tracking and VE candidates for proximate pairs
        //    (separated pairs whose gap the bodies' relative motion cannot have closed are
        //    skipped, and penetrating pairs' vertex scans it cannot have changed are reused;
        //    `odometer_poses` are the bodies' poses now, the odometers having just been read).
        self.local.update_known_pairs(
            &self.colliders,
            &self.pairs,
            self.pairs_written,
            self.params.delta_c,
            &self.odometer_poses,
        );
        self.pairs_written = false;
        lap.charge(&mut self.stage_times, Stage::Local);
        // Loads are evaluated once per sample (held over it). Loads and drives enter the bodies'
        // accumulators before the contact forces so the classical friction model sees them (§4.1).
        let t = self.time();
        for h in self.held.iter_mut() {
            *h = Wrench2::default();
        }
        for l in &self.loads {
            let (f, tau) = l.wrench(&self.bodies[l.body], t);
            self.held[l.body].force += f;
            self.held[l.body].torque += tau;
        }
        for ((b, d), h) in self.bodies.iter_mut().zip(&self.drive).zip(&self.held) {
            b.force = d.force + h.force;
            b.torque = d.torque + h.torque;
            // A fixed body never moves, so its velocity is zero: one set through the public
            // fields would make its surfaces move in the contacts' eyes and feed energy in.
            if !b.is_dynamic() {
                b.vel = Vec2::ZERO;
                b.omega = 0.0;
            }
        }
        if self.guard.is_some() {
            for (k, b) in self.ke_before.iter_mut().zip(&self.bodies) {
                *k = b.kinetic_energy();
            }
        }
        // 4–6. Contact records, state machine, simultaneous impacts, normal and friction forces.
        // (Parameters are re-read every sample, so edits to `params.contact` take effect at once.)
        self.contacts.params = self.params.contact;
        self.contacts.set_delta_c(self.params.delta_c);
        lap.charge(&mut self.stage_times, Stage::Loads);
        let past = PastPoses {
            prev: &self.prev,
            prev2: &self.prev2,
        };
        self.contacts.step(
            self.tick,
            dt,
            self.local.candidates(),
            self.local.from_vertex_scan(),
            &self.colliders,
            &mut self.bodies,
            &self.rots,
            &past,
            &self.normal,
            &self.friction,
            &mut self.contact_wrench,
            &mut self.stage_times,
        );
        let mut lap = Lap::start();
        // Issue 35: the contacts struck in this sample carry its loads (docs/MODELS.md §7.6).
        self.contacts
            .carry_forces(dt, &mut self.bodies, &self.held, &mut self.contact_wrench);
        self.ledger.impact_loss += self.contacts.last_impact_loss;
        self.ledger.impact_energy_fallbacks = self.contacts.impact_energy_fallbacks();
        if let Some(g) = self.guard.as_mut() {
            // An impulse changes a body's energy without a held force: count that change as the body's
            // input, so the guard checks the integrator alone (impacts only lower the total, §7).
            for (i, b) in self.bodies.iter().enumerate() {
                g.add_input(i, b.kinetic_energy() - self.ke_before[i]);
            }
        }
        if self.tick == 0 {
            self.ledger.initial = self.ledger.kinetic + self.contacts.stored_energy();
        }
        lap.charge(&mut self.stage_times, Stage::ContactEvents);
    }

    /// §0.5 step 3, the global proximity stage (`collide/broad.rs`), scheduled by sample:
    ///
    /// - early (a body may have outrun the margin since the poses of the set in use): the whole
    ///   stage now, for the current poses; with spreading on, a new spread update starts too;
    /// - every `N_g`-th sample without spreading: the whole stage now;
    /// - every `N_g`-th sample with spreading: publish the update begun `N_g` samples ago (the
    ///   whole stage now if none is in progress: the first sample, or after an early update was
    ///   abandoned) and begin the next one for the current poses;
    /// - with spreading, every sample that did not begin an update: advance the update in
    ///   progress by its share, so that it ends by the next `N_g`-th sample.
    ///
    /// The poses of the set in use (`global_poses`) are those of the update that produced it, so
    /// `moved_past_margin` measures the motion since then whatever the delay.
    fn global_stage(&mut self) {
        let n_g = self.params.proximity_every.max(1) as u64;
        let phase = self.tick % n_g;
        let periodic = phase == 0;
        let early = !periodic && self.moved_past_margin();
        let spread = self.params.proximity_spread && n_g > 1;
        let mut published = false;
        if periodic && spread && self.broad.in_progress() {
            self.broad.publish(&mut self.pairs);
            self.pairs_written = true;
            std::mem::swap(&mut self.global_poses, &mut self.job_poses);
            published = true;
        }
        if !(periodic || early) {
            // The sample that began an update has done its share (`begin`, and publishing).
            if spread {
                self.broad.advance((n_g - phase) as usize);
            }
            return;
        }
        // A periodic update whose result the colliders cannot have changed since the published
        // one is skipped (`BroadPhase::still_exact`, `skip_update`): the set in use is what it
        // would compute.
        // `global_poses` keep the poses of the published update, which only makes the early
        // update's check stricter than it needs to be.
        if periodic && self.params.proximity_skip && self.broad.skip_update(&self.colliders) {
            self.skipped_global_updates += 1;
            self.skipped_last_period = true;
            return;
        }
        // After a skip, the set in use is what the update of the last period would have
        // published now, so a spread update just begins, as after a publication.
        let after_skip = std::mem::take(&mut self.skipped_last_period) && periodic && spread;
        if !published && !after_skip {
            self.broad
                .update_with_motion(&self.colliders, &self.odometer, &mut self.pairs);
            self.pairs_written = true;
            for (g, b) in self.global_poses.iter_mut().zip(&self.bodies) {
                *g = b.pose;
            }
            self.early_global_updates += early as u64;
        }
        if spread {
            self.broad
                .begin_with_motion(&self.colliders, &self.odometer);
            for (g, b) in self.job_poses.iter_mut().zip(&self.bodies) {
                *g = b.pose;
            }
        }
    }

    /// Whether a body may have moved, by the end of this sample, more than `(δ_prox − δ_c)/2`
    /// since the last global update, so that the proximity set may miss a pair.
    ///
    /// A pair left out at the update was at least `δ_prox` apart (§9.1); its distance shrinks by
    /// at most the sum of the two bodies' point motions, each at most `D_i = |Δp_i| + |Δθ_i|·ρ_i`
    /// since the update (`ρ_i` the body's vertex radius). While every `D_i ≤ (δ_prox − δ_c)/2` the
    /// pair is still more than `δ_c` apart, so it has no VE candidate yet. This sample adds about
    /// `m_i = (|v_i| + |ω_i|·ρ_i)·T` (the velocity now; the integration changes it by `T·a`), so
    /// the stage is re-run when `D_i + m_i > (δ_prox − δ_c)/2` for some body. Slow worlds (a
    /// pile) never trigger it; a body faster than `(δ_prox − δ_c)/(2·T)` re-runs it every sample
    /// and is beyond the guarantee ([`World::speed_warnings`]). Costs one pass over the bodies.
    fn moved_past_margin(&self) -> bool {
        let limit = speed_limit(self.broad.delta_prox(), self.params.delta_c);
        let dt = self.params.dt;
        self.bodies
            .iter()
            .zip(&self.global_poses)
            .zip(&self.radius)
            .any(|((b, g), &r)| {
                b.is_dynamic() && {
                    let d = point_motion(g, &b.pose, r);
                    let m = (b.vel.length() + b.omega.abs() * r) * dt;
                    d + m > limit
                }
            })
    }

    /// Initial speeds beyond what the settings guarantee, one message per body (empty if none):
    /// a body whose rim speed `|v| + |ω|·ρ` (m/s) moves it more than `(δ_prox − δ_c)/2` per
    /// sample can reach a pair the proximity set does not hold, and pass through it
    /// (`moved_past_margin`, `collide/toi.rs`). Loads can still accelerate a body past the limit
    /// later; this checks the state the scene starts in.
    pub fn speed_warnings(&self) -> Vec<String> {
        let dt = self.params.dt;
        let (dp, dc) = (self.broad.delta_prox(), self.params.delta_c);
        let limit = speed_limit(dp, dc) / dt;
        let mut out = Vec::new();
        for (b, &r) in self.bodies.iter().zip(&self.radius) {
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
        self.skipped_global_updates
    }

    /// The largest overlap of two bodies now: the separating-axis depth of the proximate pair
    /// that overlaps most (`collide/overlap.rs`; seams left out). What the contact records
    /// report can be less where corners or edges cross; this is the truth. Costs a SAT test per
    /// proximate pair whose boxes overlap: for reports, not the haptic loop.
    pub fn max_overlap(&self) -> crate::collide::Overlap {
        // Pairs the local stage certified apart have none (`max_overlap_of_states`); before the
        // first step it has no states yet.
        if self.local.pair_states().len() == self.pairs.len() && self.tick > 0 {
            crate::collide::max_overlap_of_states(&self.colliders, self.local.pair_states())
        } else {
            crate::collide::max_overlap(&self.colliders, &self.pairs)
        }
    }

    /// Samples at which the swept test put a body back, and global updates run early, so far.
    pub fn continuous_stats(&self) -> (u64, u64) {
        (self.swept_hits, self.early_global_updates)
    }

    /// The swept test (time of impact, `collide/toi.rs`) for every proximate pair whose motion
    /// this sample could carry it past the allowed depth: bodies are put back to the fraction
    /// `λ_t` of the sample (pose and velocity interpolated), the smallest over their pairs. A
    /// cheap bound skips the pass when no body moved more than half the smallest allowed depth.
    fn sweep_fast_bodies(&mut self) {
        let dc = self.params.delta_c;
        let mut max_motion = 0.0f64;
        for (i, b) in self.bodies.iter().enumerate() {
            let p = self.prev[i];
            let m = point_motion(&p, &b.pose, self.radius[i]);
            self.motion[i] = if b.is_dynamic() { m } else { 0.0 };
            max_motion = max_motion.max(self.motion[i]);
        }
        if 2.0 * max_motion <= allowed_depth(dc, self.thinnest, self.thinnest) {
            return;
        }
        for p in self.put_back.iter_mut() {
            *p = 1.0;
        }
        let mut hit = false;
        for &(ca, cb) in &self.pairs {
            let (ca, cb) = (ca as usize, cb as usize);
            let (ia, ib) = (self.colliders[ca].body, self.colliders[cb].body);
            let side = |c: usize, i: usize| SweptShape {
                shape: &self.colliders[c].local,
                start: self.prev[i],
                end: self.bodies[i].pose,
                radius: self.radius[i],
                seams: self.colliders[c].seams,
            };
            // Swept boxes apart: the start AABBs (this sample's colliders), each grown by its
            // body's motion, do not overlap, so the pair cannot touch during the sample.
            let (ba, bb) = (&self.colliders[ca].aabb, &self.colliders[cb].aabb);
            let grow = self.motion[ia] + self.motion[ib];
            if ba.min.x - bb.max.x > grow
                || bb.min.x - ba.max.x > grow
                || ba.min.y - bb.max.y > grow
                || bb.min.y - ba.max.y > grow
            {
                continue;
            }
            let allowed = allowed_depth(dc, self.thickness[ca], self.thickness[cb]);
            if let Some(l) = swept_put_back(&side(ca, ia), &side(cb, ib), allowed, &mut self.sweep)
            {
                self.put_back[ia] = self.put_back[ia].min(l);
                self.put_back[ib] = self.put_back[ib].min(l);
                hit = true;
            }
        }
        if !hit {
            return;
        }
        self.swept_hits += 1;
        for i in 0..self.bodies.len() {
            let lam = self.put_back[i];
            let b = &mut self.bodies[i];
            if lam >= 1.0 || !b.is_dynamic() {
                continue;
            }
            let (p0, (v0, w0)) = (self.prev[i], self.vel_before[i]);
            b.pose.pos = p0.pos + (b.pose.pos - p0.pos) * lam;
            b.pose.angle = p0.angle + (b.pose.angle - p0.angle) * lam;
            b.vel = v0 + (b.vel - v0) * lam;
            b.omega = w0 + (b.omega - w0) * lam;
        }
    }

    /// §0.5 steps 10–11: integrate every body with all forces of this sample (contact + loads + drive,
    /// re-read so a drive set after `begin_step` counts), put fast bodies back to their time of
    /// impact (the swept test, `collide/toi.rs`), then update the energy ledger.
    pub fn finish_step(&mut self) {
        self.begun = false;
        let dt = self.params.dt;
        let mut lap = Lap::start();
        // Remember the poses of k−1 and k−2 (buffers reused).
        std::mem::swap(&mut self.prev, &mut self.prev2);
        self.prev.clear();
        self.prev.extend(self.bodies.iter().map(|b| b.pose));
        // 10. Integration.
        for i in 0..self.bodies.len() {
            // Held applied wrench: loads (evaluated in begin_step) + the drive as it is now.
            let b = &mut self.bodies[i];
            let cw = self.contact_wrench[i];
            b.force = self.held[i].force + self.drive[i].force + cw.force;
            b.torque = self.held[i].torque + self.drive[i].torque + cw.torque;
        }
        lap.charge(&mut self.stage_times, Stage::Assemble);
        // Implicit chain damper on the end-of-sample velocities (adds to forces and contact wrench).
        if self.params.mode == IntegrationMode::SemiImplicit {
            self.ledger.chain_damping_loss += self.chain.apply(
                self.params.chain_tau,
                self.params.chain_sweeps,
                dt,
                self.contacts.loaded(),
                &mut self.bodies,
                &mut self.contact_wrench,
            );
        }
        lap.charge(&mut self.stage_times, Stage::ChainDamper);
        for i in 0..self.bodies.len() {
            let b = &mut self.bodies[i];
            if !b.is_dynamic() {
                continue;
            }
            self.vel_before[i] = (b.vel, b.omega);
            self.guard_force[i] = Wrench2 {
                force: b.force - b.vel * b.damping,
                torque: b.torque,
            };
            integrate_body(b, dt, self.params.mode);
        }
        // Swept test: fast bodies that would pass a thin part are put back to their impact.
        self.sweep_fast_bodies();
        // 11. Energy ledger: the applied work over each body's actual motion.
        let mut applied_work = 0.0;
        for i in 0..self.bodies.len() {
            let b = &self.bodies[i];
            if !b.is_dynamic() {
                continue;
            }
            let before = self.prev[i];
            let dx = b.pose.pos - before.pos;
            let dth = b.pose.angle - before.angle;
            let applied = Wrench2 {
                force: self.held[i].force + self.drive[i].force,
                torque: self.held[i].torque + self.drive[i].torque,
            };
            applied_work += applied.force.dot(dx) + applied.torque * dth;
            if let Some(g) = self.guard.as_mut() {
                let f = self.guard_force[i];
                g.add_input(i, f.force.dot(dx) + f.torque * dth);
                g.check(i, &mut self.bodies[i]);
            }
        }
        self.ledger.applied_work += applied_work;
        self.ledger.kinetic = self.bodies.iter().map(|b| b.kinetic_energy()).sum();
        self.ledger.stored = self.contacts.stored_energy();
        self.tick += 1;
        lap.charge(&mut self.stage_times, Stage::Integrate);
    }
}

/// A bound on how far any point of a body of vertex radius `radius` (m) moves between the poses
/// `from` and `to`: `|Δp| + |Δθ|·ρ` (m), since a rotation by `Δθ` moves a point at distance `ρ`
/// from the centre by `2ρ·|sin(Δθ/2)| ≤ |Δθ|·ρ`.
#[inline]
fn point_motion(from: &Pose, to: &Pose, radius: f64) -> f64 {
    (to.pos - from.pos).length() + (to.angle - from.angle).abs() * radius
}
