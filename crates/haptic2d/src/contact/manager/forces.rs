//! Stage 6 of the contact step (§0.5 step 6): continuous-contact forces, normal then friction, per
//! Continuous record (§1–§4, §5.9); god-objects follow (§8.3).

use super::ContactSet;
use super::Wrench2;
use crate::body::Body;
use crate::collide::VeCandidate;
use crate::contact::law_pool::{SlotAccess, Slots};
use crate::contact::record::{ContactState, LawState, LoadedContact, VeContact};
use crate::geom::{cross, Vec2};
use crate::laws::friction::{FrictionInput, FrictionLaw, FrictionModel};
use crate::laws::normal::{NormalInput, NormalLaw};

impl ContactSet {
    /// Step 6: normal force, then friction, for every Continuous record; god-objects follow.
    pub(super) fn forces(
        &mut self,
        dt: f64,
        bodies: &[Body],
        friction: &FrictionModel,
        wrenches: &mut [Wrench2],
    ) {
        for w in wrenches.iter_mut() {
            *w = Wrench2::default();
        }
        // Without a contact event the records and their order are the last sample's, so the
        // loaded keys are too up to the first record whose `f_n > 0` flips; with one, every
        // key is written again.
        let pass = ForcePass {
            entries: &mut self.entries,
            loaded: &mut self.loaded,
            keys: &mut self.loaded_keys,
            rewrite: !self.events.is_empty(),
            nonfric: &mut self.nonfric,
            impact_entries: &self.struck_entry,
            v_damp: self.params.v_c,
            dt,
            bodies,
            needs_ext: friction.uses_external_force(),
            wrenches,
        };
        // One pass per form of the law slots (`LawPool`), so the per-record loop has no branch on
        // it.
        // The classical model's two loops are a second instance of the pass (`EXT`), so neither
        // instance tests the model per record.
        let (stored, records, breaks, rewritten) = match (self.laws.slots_mut(), pass.needs_ext) {
            (Slots::Lean(store), false) => pass.run::<_, false>(store),
            (Slots::Compact(store), false) => pass.run::<_, false>(store),
            (Slots::Whole(store), false) => pass.run::<_, false>(store),
            (Slots::Lean(store), true) => pass.run::<_, true>(store),
            (Slots::Compact(store), true) => pass.run::<_, true>(store),
            (Slots::Whole(store), true) => pass.run::<_, true>(store),
        };
        self.stored = stored;
        self.record_count = records;
        if rewritten {
            self.loaded_generation += 1;
        }
        // Scattered law slots cost a cache miss per record every sample: put them back in
        // record order once an eighth of the records are out of sequence (new records take
        // free or new slots).
        if breaks > 1 && breaks * 8 > records {
            self.laws.repack(&mut self.entries);
        }
    }
}

/// What the force pass reads and writes besides the law slots.
struct ForcePass<'a> {
    entries: &'a mut [VeContact],
    loaded: &'a mut Vec<LoadedContact>,
    /// The keys of `loaded` (rewritten from the first change on) and whether to rewrite them all.
    keys: &'a mut Vec<VeCandidate>,
    rewrite: bool,
    nonfric: &'a mut [Vec2],
    /// The entries of this sample's colliding records (ascending) and the approach speed `v_c` (m/s):
    /// the chain damper acts on neither (issue 35, docs/MODELS.md §6.7), so they are not listed
    /// as loaded.
    impact_entries: &'a [usize],
    v_damp: f64,
    dt: f64,
    bodies: &'a [Body],
    /// The classical model needs every normal force first (its stick force cancels the other
    /// forces on A); every other model runs normal then friction per contact in one pass.
    needs_ext: bool,
    wrenches: &'a mut [Wrench2],
}

impl ForcePass<'_> {
    /// Runs the pass with the law slots `laws`: returns the stored energy (J), the number of
    /// Continuous records, how many of them have a law slot that does not follow the previous
    /// record's (see `LawPool::repack`), and whether the loaded keys were rewritten.
    ///
    /// Kept out of line: in a release build where LLVM inlined it into `forces` (session 28,
    /// after the duplicate clean-up moved code between modules), `simulate pile:100 --duration 5`
    /// ran 0.36 % more instructions (callgrind: 2.8037 G against 2.7937 G); out of line, 2.7936 G.
    ///
    /// `EXT` is `needs_ext` (the caller picks the instance).
    #[inline(never)]
    fn run<S: SlotAccess, const EXT: bool>(self, laws: &mut S) -> (f64, usize, usize, bool) {
        debug_assert_eq!(EXT, self.needs_ext);
        let (dt, needs_ext) = (self.dt, EXT);
        // The bodies and their wrenches cut to one length (they are the same; a record's body
        // out of range still panics), so that the compiler checks a record's body index once for
        // both instead of once each.
        let n = self.bodies.len().min(self.wrenches.len());
        let (bodies, wrenches) = (&self.bodies[..n], &mut self.wrenches[..n]);
        let mut stored = 0.0;
        // Every record is Continuous here (Colliding ones were resolved by the impacts of step 5).
        let mut records = 0;
        let (mut last_slot, mut breaks) = (u32::MAX, 0usize);
        self.loaded.clear();
        let mut rewrite = self.rewrite;
        if rewrite {
            self.keys.clear();
        }
        // The next struck entry at or after the current one (`usize::MAX` past the last).
        let mut impacts = self.impact_entries.iter();
        let mut next_impact = impacts.next().copied().unwrap_or(usize::MAX);
        for (idx, e) in self.entries.iter_mut().enumerate() {
            if e.state != Some(ContactState::Continuous) {
                continue;
            }
            records += 1;
            breaks += (e.law != last_slot.wrapping_add(1)) as usize;
            last_slot = e.law;
            let input = NormalInput {
                d: e.d,
                hist: e.hist,
                c0: e.c0,
                dt,
                m_eff: e.m_eff,
            };
            // Normal force, then (one pass per contact unless the model needs every normal force
            // first) friction, on the slot's laws.
            let energy = laws.with(e.law, |law| {
                e.f_n = law.normal.force(&input);
                if needs_ext {
                    return None;
                }
                friction_step(e, law, dt, 0.0);
                Some(law.normal.stored_energy() + law.friction.stored_energy())
            });
            if let Some(u) = energy {
                stored += u;
            }
            // Loaded: pushing, not struck in this sample, not approaching faster than v_c.
            while next_impact < idx {
                next_impact = impacts.next().copied().unwrap_or(usize::MAX);
            }
            let in_impact = next_impact == idx;
            let loaded = e.f_n > 0.0 && !in_impact && e.c0 >= -self.v_damp;
            if loaded != e.loaded && !rewrite {
                // The first change: the keys before it are the last sample's.
                rewrite = true;
                self.keys.truncate(self.loaded.len());
            }
            e.loaded = loaded;
            if loaded {
                if rewrite {
                    self.keys.push(e.key);
                }
                self.loaded.push(LoadedContact {
                    body_a: e.body_a as u32,
                    body_b: e.body_b as u32,
                    point: e.point,
                    n: e.n,
                    f_n: e.f_n,
                });
            }
            // The normal and the friction force act at the same point: one wrench (the classical
            // model adds its friction in the second loop below, after every normal force).
            let f = if needs_ext {
                e.n * e.f_n
            } else {
                e.n * e.f_n + e.t() * e.f_t
            };
            add_force(wrenches, bodies, e.body_a, e.body_b, f, e.point);
        }
        debug_assert_eq!(
            self.keys.len(),
            self.loaded.len(),
            "one key per loaded record"
        );
        if needs_ext {
            for (i, b) in bodies.iter().enumerate() {
                self.nonfric[i] = b.force + wrenches[i].force;
            }
            for idx in 0..self.entries.len() {
                if self.entries[idx].state != Some(ContactState::Continuous) {
                    continue;
                }
                let f_ext_t = external_share(self.entries, self.nonfric, idx);
                let e = &mut self.entries[idx];
                stored += laws.with(e.law, |law| {
                    friction_step(e, law, dt, f_ext_t);
                    law.normal.stored_energy() + law.friction.stored_energy()
                });
                if e.f_t != 0.0 {
                    add_force(wrenches, bodies, e.body_a, e.body_b, e.t() * e.f_t, e.point);
                }
            }
        }
        (stored, records, breaks, rewrite)
    }
}

/// `F_ext,t,i` for the classical model (§4.1): the non-friction force on A along this
/// contact's tangent, shared by A's contacts with parallel tangents in proportion to their
/// normal forces, `(t·F_A^nonfric)·F_n,i/Σ F_n,j` (equally, `/n_t`, if none pushes). Each
/// contact then sticks iff `|t·F_A^nonfric| ≤ μ_s·Σ F_n,j`, rigid Coulomb's condition for the
/// body; the equal share let the unloaded corner of a tall block slip below it (issue 16,
/// docs/MODELS.md §4.1). `nonfric` holds every body's non-friction force (N).
fn external_share(entries: &[VeContact], nonfric: &[Vec2], idx: usize) -> f64 {
    let e = &entries[idx];
    let (mut n_t, mut fn_sum) = (0usize, 0.0);
    for o in entries.iter().filter(|o| {
        o.state == Some(ContactState::Continuous)
            && o.body_a == e.body_a
            && o.t().dot(e.t()).abs() > 0.99
    }) {
        n_t += 1;
        fn_sum += o.f_n;
    }
    let demand = e.t().dot(nonfric[e.body_a]);
    if fn_sum > 0.0 {
        demand * (e.f_n / fn_sum)
    } else {
        demand / n_t.max(1) as f64
    }
}

/// Friction force of one Continuous record for this sample (after its normal force), into
/// `e.f_t`, and its god-object (§8.3).
#[inline(always)]
fn friction_step<N, F: FrictionLaw>(
    e: &mut VeContact,
    law: &mut LawState<N, F>,
    dt: f64,
    f_ext_t: f64,
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
    // `unwrap_or_else`: the clamp (and its check that `0 ≤ len`) only for a model without an
    // anchor, not for every record.
    e.s_g = law
        .friction
        .anchor(e.s)
        .unwrap_or_else(|| e.s.clamp(0.0, e.len));
}

#[inline(always)]
fn add_force(w: &mut [Wrench2], bodies: &[Body], a: usize, b: usize, f: Vec2, p: Vec2) {
    w[a].force += f;
    w[a].torque += cross(p - bodies[a].pose.pos, f);
    w[b].force -= f;
    w[b].torque -= cross(p - bodies[b].pose.pos, f);
}

#[cfg(test)]
mod tests {
    use crate::contact::test_pile::{shove, toss_top_box};
    use crate::contact::ContactState;

    /// The loaded list's keys are every sample those of the Continuous records with `f_n > 0` that
    /// were neither struck in the sample nor approach faster than `v_c` (issue 35),
    /// in key order, and their generation changes whenever they do, on a pile:20 shoved sideways at
    /// step 300 and with its top box tossed up at step 700: records are created and released,
    /// and some records' normal force drops to zero and comes back without an event (the keys
    /// are then rewritten from that record on). Without an event, the generation changes
    /// exactly when the keys do, so a pile at rest keeps its damper rows.
    #[test]
    fn the_loaded_keys_and_their_generation_follow_the_loaded_records() {
        let mut w = crate::scene::builtin("pile:20", None)
            .unwrap()
            .unwrap()
            .world;
        let (mut prev_keys, mut prev_generation) = (Vec::new(), 0);
        let (mut changes, mut flips_without_events) = (0, 0);
        for k in 0..1500 {
            if [300, 600, 900, 1200].contains(&k) {
                shove(&mut w);
            }
            if [450, 750, 1050, 1350].contains(&k) {
                toss_top_box(&mut w);
            }
            w.step();
            let c = w.contacts();
            let pushing = |e: &&crate::contact::VeContact| {
                e.state == Some(ContactState::Continuous) && e.f_n > 0.0
            };
            let expected: Vec<_> = c
                .entries()
                .iter()
                .enumerate()
                .filter(|(i, e)| pushing(e) && e.c0 >= -c.params.v_c && !c.struck_entry.contains(i))
                .map(|(_, e)| e)
                .collect();
            let loaded = c.loaded();
            let keys: Vec<_> = expected.iter().map(|e| e.key).collect();
            assert_eq!(loaded.keys, &keys[..], "step {k}");
            assert_eq!(loaded.contacts.len(), expected.len(), "step {k}");
            for (l, e) in loaded.contacts.iter().zip(&expected) {
                assert_eq!(
                    (l.body_a as usize, l.body_b as usize, l.f_n),
                    (e.body_a, e.body_b, e.f_n),
                    "step {k}"
                );
            }
            if c.events().is_empty() {
                // Without an event the generation changes exactly when the keys do.
                assert_eq!(
                    loaded.generation != prev_generation,
                    keys != prev_keys,
                    "step {k}"
                );
            }
            if keys != prev_keys {
                assert_ne!(loaded.generation, prev_generation, "step {k}: keys changed");
                changes += 1;
                if c.events().is_empty() {
                    flips_without_events += 1;
                }
            }
            (prev_keys, prev_generation) = (keys, loaded.generation);
        }
        assert!(changes > 10, "{changes} changes of the loaded keys");
        assert!(
            flips_without_events > 0,
            "no record's normal force dropped to zero without an event"
        );
    }
}
