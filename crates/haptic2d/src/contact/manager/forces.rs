//! Stage 6 of the contact step (§0.5 step 6): continuous-contact forces, normal then friction, per
//! Continuous record (§1–§4, §5.9); god-objects follow (§8.3).

use super::ContactSet;
use super::Wrench2;
use crate::body::Body;
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
        // The classical model needs every normal force first (its stick force cancels the other
        // forces on A); every other model runs normal then friction per contact in one pass.
        let needs_ext = friction.uses_external_force();
        let mut stored = 0.0;
        // Every record is Continuous here (Colliding ones were resolved by the impacts of step 5).
        let mut records = 0;
        // Records whose law slot does not follow the previous record's (see `LawPool::repack`).
        let (mut last_slot, mut breaks) = (u32::MAX, 0usize);
        self.loaded.clear();
        for idx in 0..self.entries.len() {
            if self.entries[idx].state != Some(ContactState::Continuous) {
                continue;
            }
            records += 1;
            let e = &mut self.entries[idx];
            breaks += (e.law != last_slot.wrapping_add(1)) as usize;
            last_slot = e.law;
            let law = self.laws.get_mut(e.law);
            let input = NormalInput {
                d: e.d,
                hist: e.hist,
                c0: e.c0,
                dt,
                m_eff: e.m_eff,
            };
            e.f_n = law.normal.force(&input);
            if e.f_n > 0.0 {
                self.loaded.push(LoadedContact {
                    key: e.key,
                    body_a: e.body_a as u32,
                    body_b: e.body_b as u32,
                    point: e.point,
                    n: e.n,
                    f_n: e.f_n,
                });
            }
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
        // Scattered law slots cost a cache miss per record every sample: put them back in
        // record order once an eighth of the records are out of sequence (new records take
        // free or new slots).
        if breaks > 1 && breaks * 8 > records {
            self.laws.repack(&mut self.entries);
        }
    }

    /// `F_ext,t,i` for the classical model (§4.1): the non-friction force on A along this
    /// contact's tangent, shared by A's contacts with parallel tangents in proportion to their
    /// normal forces, `(t·F_A^nonfric)·F_n,i/Σ F_n,j` (equally, `/n_t`, if none pushes). Each
    /// contact then sticks iff `|t·F_A^nonfric| ≤ μ_s·Σ F_n,j`, rigid Coulomb's condition for the
    /// body; the equal share let the unloaded corner of a tall block slip below it (issue 16,
    /// docs/MODELS.md §4.1).
    fn external_share(&self, idx: usize) -> f64 {
        let e = &self.entries[idx];
        let (mut n_t, mut fn_sum) = (0usize, 0.0);
        for o in self.entries.iter().filter(|o| {
            o.state == Some(ContactState::Continuous)
                && o.body_a == e.body_a
                && o.t().dot(e.t()).abs() > 0.99
        }) {
            n_t += 1;
            fn_sum += o.f_n;
        }
        let demand = e.t().dot(self.nonfric[e.body_a]);
        if fn_sum > 0.0 {
            demand * (e.f_n / fn_sum)
        } else {
            demand / n_t.max(1) as f64
        }
    }
}

/// Friction force of one Continuous record for this sample (after its normal force), and its
/// god-object (§8.3).
#[inline(always)]
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
        add_force(wrenches, bodies, e.body_a, e.body_b, e.t() * e.f_t, e.point);
    }
}

#[inline(always)]
fn add_force(w: &mut [Wrench2], bodies: &[Body], a: usize, b: usize, f: Vec2, p: Vec2) {
    w[a].force += f;
    w[a].torque += cross(p - bodies[a].pose.pos, f);
    w[b].force -= f;
    w[b].torque -= cross(p - bodies[b].pose.pos, f);
}
