//! One sample of the world as a list of numbered stages (MODELS §0.5): [`World::begin_step`] runs
//! steps 3–6, [`World::finish_step`] steps 10–12; each stage is one call, its state owned by the
//! stage (`proximity.rs`, `swept.rs`, `guard.rs`, `applied.rs`) and its inputs lent by the world.

use crate::contact::PastPoses;
use crate::integrate::{integrate_body, IntegrationMode};
use crate::scene::{divergence, Divergence};
use crate::stage_time::{Lap, Stage, StageTimes};

use super::{StepContext, World};

impl World {
    /// Computes the state at `t = 0` before the first row is written: proximity, contacts (with
    /// their impacts, if bodies start approaching in contact), contact forces and the stored
    /// energy, i.e. [`begin_step`](Self::begin_step) of sample 0; the next `begin_step` (or
    /// [`step`](Self::step)) then goes straight on to its integration. Afterwards the ledger's
    /// `stored` and `initial` include the energy of bodies that start interpenetrating, and
    /// [`ContactSet::contact_count`](crate::contact::ContactSet::contact_count) their records, so a `t = 0` log row reports them (the built-in
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
    ///
    /// Returns the divergence (§0.5 step 12) if the world has diverged, in this step or before
    /// (then nothing ran: the world stays as it was); `None` otherwise. A diverged world never
    /// panics: it reports, and the caller decides (`haptic2d simulate` exits with status 6).
    pub fn step(&mut self) -> Option<Divergence> {
        self.begin_step();
        self.finish_step();
        self.diverged.clone()
    }

    /// §0.5 steps 3–6: proximity (every `N_g` samples), local contacts, contact states, impacts
    /// (velocities jump now), and continuous-contact forces.
    ///
    /// Does nothing if steps 3–6 of this sample have run already ([`World::prime`]), or if the
    /// world has diverged ([`World::divergence`]; checked here too, for states set from outside).
    pub fn begin_step(&mut self) {
        if self.begun || self.stopped() {
            return;
        }
        self.begun = true;
        self.stage_times = StageTimes::default();
        let mut lap = Lap::start();
        // 3a. Body rotations, world-frame collider features and odometers at the current poses.
        self.update_poses();
        lap.charge(&mut self.stage_times, Stage::Poses);
        // 3b. Global proximity stage: AABB sort-and-sweep + GJK, every N_g samples (spread,
        //     skipped when still exact), and early for the bodies that may have outrun the margin.
        self.proximity
            .run(self.tick, &self.params, &self.bodies, &self.colliders);
        lap.charge(&mut self.stage_times, Stage::Global);
        // 4a. Local stage: closest-feature tracking and VE candidates for proximate pairs.
        self.local_proximity();
        lap.charge(&mut self.stage_times, Stage::Local);
        // 4b. Loads at t = kT and the drive into the accumulators, before the contact forces.
        let t = self.time();
        self.applied.evaluate(&self.loads, &mut self.bodies, t);
        self.guard.before_contacts(&self.bodies);
        lap.charge(&mut self.stage_times, Stage::Loads);
        // 5–6a. Contact records, state machine, simultaneous impacts, normal and friction forces.
        self.contact_stage();
        // 6b. The contacts struck in this sample carry its loads; impacts in the ledger and guard.
        let mut lap = Lap::start();
        self.book_impacts();
        lap.charge(&mut self.stage_times, Stage::ContactEvents);
    }

    /// §0.5 steps 10–12: integrate every body with all forces of this sample (contact + loads +
    /// drive, re-read so a drive set after `begin_step` counts), put fast bodies back to their
    /// time of impact (the swept test, `collide/toi.rs`), update the energy ledger, then check for
    /// divergence.
    ///
    /// Does nothing if the world has diverged ([`World::divergence`]).
    pub fn finish_step(&mut self) {
        if self.diverged.is_some() {
            return;
        }
        self.begun = false;
        let mut lap = Lap::start();
        // 10a. The held forces: loads, drive as it is now and contact wrench.
        self.assemble_forces();
        lap.charge(&mut self.stage_times, Stage::Assemble);
        // 10b. The implicit chain damper on the end-of-sample velocities (§6.7).
        self.damp_chains();
        lap.charge(&mut self.stage_times, Stage::ChainDamper);
        // 10c. Integration of every dynamic body (§6).
        self.integrate();
        // 10d. The swept test: fast bodies that would pass a thin part are put back (§9.7).
        self.swept.run(
            self.params.delta_c,
            &mut self.bodies,
            &self.colliders,
            &self.proximity.pairs,
            &self.past.prev,
            &self.proximity.radius,
        );
        // 11. Energy ledger and passivity guard.
        self.book_energy();
        self.tick += 1;
        lap.charge(&mut self.stage_times, Stage::Integrate);
        // 12. Divergence check.
        self.stopped();
    }

    /// §0.5 step 12: whether the world has diverged (before now, or in its state now; the first
    /// divergence found is kept). O(bodies), no allocation unless diverged.
    fn stopped(&mut self) -> bool {
        if self.diverged.is_none() {
            self.diverged = divergence(self);
        }
        self.diverged.is_some()
    }

    /// Step 3a: body rotations, the world-frame features of every collider, and the odometers.
    fn update_poses(&mut self) {
        for (r, b) in self.rots.iter_mut().zip(&self.bodies) {
            *r = b.pose.rot();
        }
        for c in self.colliders.iter_mut() {
            c.update_with(&self.bodies[c.body].pose, self.rots[c.body]);
        }
        self.proximity.read_odometers(&self.bodies);
    }

    /// Step 4a: the local stage (separated pairs whose gap the bodies' relative motion cannot have
    /// closed are skipped, and penetrating pairs' vertex scans it cannot have changed are reused;
    /// the odometer poses are the bodies' poses now, the odometers having just been read).
    fn local_proximity(&mut self) {
        self.local.update_known_pairs(
            &self.colliders,
            &self.proximity.pairs,
            self.proximity.pairs_written,
            self.params.delta_c,
            &self.proximity.odometer_poses,
        );
        self.proximity.pairs_written = false;
    }

    /// Steps 5–6a: the contact stage on a borrowed [`StepContext`]. Parameters are re-read every
    /// sample, so edits to `params.contact` take effect at once.
    fn contact_stage(&mut self) {
        self.contacts.params = self.params.contact;
        self.contacts.set_delta_c(self.params.delta_c);
        self.contacts.step(StepContext {
            tick: self.tick,
            dt: self.params.dt,
            candidates: self.local.candidates(),
            from_scan: self.local.from_vertex_scan(),
            colliders: &self.colliders,
            bodies: &mut self.bodies,
            rots: &self.rots,
            past: PastPoses {
                prev: &self.past.prev,
                prev2: &self.past.prev2,
            },
            normal: &self.normal,
            friction: &self.friction,
            wrenches: &mut self.contact_wrench,
            times: &mut self.stage_times,
        });
    }

    /// Step 6b: the contacts struck in this sample carry its loads (issue 35, MODELS §7.6); the
    /// impacts' loss into the ledger and their energy change into the guard; the initial energy
    /// at sample 0.
    fn book_impacts(&mut self) {
        self.contacts.carry_forces(
            self.params.dt,
            &mut self.bodies,
            &self.applied.held,
            &mut self.contact_wrench,
        );
        self.ledger.impact_loss += self.contacts.last_impact_loss;
        self.ledger.impact_energy_fallbacks = self.contacts.impact_energy_fallbacks();
        self.guard.after_impacts(&self.bodies);
        if self.tick == 0 {
            self.ledger.initial = self.ledger.kinetic + self.contacts.stored_energy();
        }
    }

    /// Step 10a: remembers the poses of `k − 1` and `k − 2` (buffers reused) and sets each body's
    /// force to its loads, its drive as it is now and its contact wrench.
    fn assemble_forces(&mut self) {
        std::mem::swap(&mut self.past.prev, &mut self.past.prev2);
        self.past.prev.clear();
        self.past.prev.extend(self.bodies.iter().map(|b| b.pose));
        for (i, b) in self.bodies.iter_mut().enumerate() {
            let a = self.applied.wrench(i);
            let cw = self.contact_wrench[i];
            b.force = a.force + cw.force;
            b.torque = a.torque + cw.torque;
        }
    }

    /// Step 10b: the implicit chain damper (semi-implicit mode only) adds its damping on the
    /// loaded contacts to the forces and the contact wrench; its loss goes to the ledger.
    fn damp_chains(&mut self) {
        if self.params.mode == IntegrationMode::SemiImplicit {
            self.ledger.chain_damping_loss += self.chain.apply(
                self.params.chain_tau,
                self.params.chain_sweeps,
                self.params.chain_row_updates(),
                self.params.dt,
                self.contacts.loaded(),
                &mut self.bodies,
                &mut self.contact_wrench,
            );
        }
    }

    /// Step 10c: integrates every dynamic body (§6), remembering what the swept test and the
    /// guard need of it first.
    fn integrate(&mut self) {
        for (i, b) in self.bodies.iter_mut().enumerate() {
            if !b.is_dynamic() {
                continue;
            }
            self.swept.remember(i, b);
            self.guard.remember(i, b);
            integrate_body(b, self.params.dt, self.params.mode);
        }
    }

    /// Step 11: the energy ledger (the applied work over each body's actual motion, kinetic and
    /// stored energy) and the passivity guard.
    fn book_energy(&mut self) {
        let mut applied_work = 0.0;
        for (i, b) in self.bodies.iter_mut().enumerate() {
            if !b.is_dynamic() {
                continue;
            }
            let before = self.past.prev[i];
            let dx = b.pose.pos - before.pos;
            let dth = b.pose.angle - before.angle;
            let applied = self.applied.wrench(i);
            applied_work += applied.force.dot(dx) + applied.torque * dth;
            self.guard.check(i, b, dx, dth);
        }
        self.ledger.applied_work += applied_work;
        self.ledger.kinetic = self.bodies.iter().map(|b| b.kinetic_energy()).sum();
        self.ledger.stored = self.contacts.stored_energy();
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::builtin;
    use crate::world::World;

    fn pile() -> World {
        builtin("pile:20", None).unwrap().unwrap().world
    }

    #[test]
    fn a_healthy_world_reports_no_divergence() {
        let mut w = pile();
        for _ in 0..200 {
            assert_eq!(w.step(), None);
        }
        assert!(w.divergence().is_none());
    }

    #[test]
    fn a_non_finite_state_is_reported_by_the_step_and_the_world_stays_as_it_was() {
        let mut w = pile();
        for _ in 0..50 {
            w.step();
        }
        let box0 = w.bodies.iter().position(|b| b.is_dynamic()).unwrap();
        w.bodies[box0].vel.x = f64::NAN;
        let d = w.step().expect("a NaN velocity is a divergence");
        assert_eq!(d.body.as_deref(), Some(w.bodies[box0].name.as_str()));
        assert!(d.what.starts_with("vx = NaN"), "{d}");
        // Nothing more runs, and nothing panics, however often it is stepped.
        let (tick, poses): (u64, Vec<_>) = (w.tick(), w.bodies.iter().map(|b| b.pose).collect());
        for _ in 0..10 {
            assert_eq!(w.step().as_ref(), Some(&d));
            w.begin_step();
            w.finish_step();
        }
        assert_eq!(w.tick(), tick);
        let after: Vec<_> = w.bodies.iter().map(|b| b.pose).collect();
        assert_eq!(after, poses);
    }

    #[test]
    fn every_number_of_a_body_beyond_its_bound_or_not_finite_is_a_divergence_and_at_it_is_not() {
        use crate::scene::bounds::{
            DIVERGENCE_FACTOR, MAX_ANGLE_RAD, MAX_LENGTH_M, MAX_OMEGA_RAD_S, MAX_SPEED_M_S,
        };
        type Field = fn(&mut crate::body::Body) -> &mut f64;
        let fields: [(&str, Field, f64); 6] = [
            ("x", |b| &mut b.pose.pos.x, MAX_LENGTH_M),
            ("y", |b| &mut b.pose.pos.y, MAX_LENGTH_M),
            ("theta", |b| &mut b.pose.angle, MAX_ANGLE_RAD),
            ("vx", |b| &mut b.vel.x, MAX_SPEED_M_S),
            ("vy", |b| &mut b.vel.y, MAX_SPEED_M_S),
            ("omega", |b| &mut b.omega, MAX_OMEGA_RAD_S),
        ];
        let w0 = pile();
        let last = w0.bodies.len() - 1;
        for (name, field, bound) in fields {
            let max = bound * DIVERGENCE_FACTOR;
            for (x, diverged) in [
                (max, false),
                (-max, false),
                (max * (1.0 + 1e-15), true),
                (-max * (1.0 + 1e-15), true),
                (f64::NAN, true),
                (f64::INFINITY, true),
                (f64::NEG_INFINITY, true),
            ] {
                let mut w = w0.clone();
                *field(&mut w.bodies[last]) = x;
                let d = crate::scene::divergence(&w);
                assert_eq!(d.is_some(), diverged, "{name} = {x}: {d:?}");
                if let Some(d) = d {
                    assert_eq!(d.body.as_deref(), Some(w.bodies[last].name.as_str()));
                    assert!(d.what.starts_with(&format!("{name} = ")), "{d}");
                }
            }
        }
    }

    #[test]
    fn a_runaway_speed_beyond_the_divergence_bound_is_reported_by_the_step() {
        // The bound is the input bound × 1e3 (scene/bounds.rs): 1e3 m/s × 1e3 = 1e6 m/s.
        let mut w = pile();
        let box0 = w.bodies.iter().position(|b| b.is_dynamic()).unwrap();
        w.bodies[box0].vel.y = -2e6;
        let d = w.step().expect("2e6 m/s is beyond the bound");
        assert!(d.what.starts_with("vy = -2000000"), "{d}");
        assert_eq!(w.divergence(), Some(&d));
        assert_eq!(
            w.tick(),
            0,
            "the state set from outside is caught before the step runs"
        );
    }
}
