//! The lean law slot: the paper's pair of laws (the [`PaperLaw`] spring–damper and the
//! [`ResetIntegrator`]) with their parameters kept once for the whole pool, and only the
//! per-contact state in each slot: 40 bytes instead of the compact slot's 144.
//!
//! A law slot is a copy of the world's prototypes, taken when the record is created, so every
//! slot carries the laws' parameters (`Kc`, `Bc`, `Kr`, `μs`, `μk`, `β`, …: 104 of the compact
//! slot's 144 bytes) besides their state. While every live record has the same parameters, which
//! is the case unless the prototypes change while records live, those copies are all the same.
//! The contact set's pool then keeps the slots in this form ([`LawPool`](super::law_pool::LawPool)),
//! and the force pass, which streams every contact's slot each sample, reads 40 bytes a contact
//! instead of 144 (pile:1000: 3 870 contacts, 155 kB instead of 557 kB a sample; docs/PERFORMANCE.md,
//! issue 17). The force pass rebuilds each contact's laws from the shared parameters and the slot's
//! state, and runs the laws' own code on them: the forces and states are bit for bit those of the
//! compact form.

use super::compact_law::CompactNormal;
use super::law_pool::Store;
use super::record::{LawState, VeContact};
use crate::laws::friction::{FrictionMode, FrictionModel, ResetIntegrator};
use crate::laws::normal::{ContactNormal, NormalModel, PaperLaw};

/// The paper's pair of laws in `normal` and `friction`, if that is what they are.
pub(crate) fn lean_pair<'a>(
    normal: &'a NormalModel,
    friction: &'a FrictionModel,
) -> Option<(&'a PaperLaw, &'a ResetIntegrator)> {
    match (normal, friction) {
        (NormalModel::Paper(paper), FrictionModel::ResetIntegrator(reset)) => Some((paper, reset)),
        _ => None,
    }
}

/// The per-contact state of the paper's pair of laws (`repr(C)`, 40 bytes, the offset first: it is
/// read every sample).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct LeanState {
    /// The impact surface offset `σ` (m, [`ContactNormal::offset`]).
    offset: f64,
    /// The paper law's stored energy of the last sample (J).
    stored: f64,
    /// The reset integrator's strain (m), stiffness of the last sample (N/m) and mode.
    p: f64,
    k_used: f64,
    mode: FrictionMode,
}

impl LeanState {
    /// The state of `law`.
    #[inline(always)]
    fn of(law: &LawState<PaperLaw, ResetIntegrator>) -> Self {
        let (p, k_used, mode) = law.friction.state();
        Self {
            offset: law.normal.offset(),
            stored: law.normal.model.state(),
            p,
            k_used,
            mode,
        }
    }
}

/// Lean slots: the shared parameters and one [`LeanState`] per slot.
#[derive(Clone, Debug)]
pub(crate) struct LeanStore {
    /// The parameters of every slot (their own states are not used).
    paper: PaperLaw,
    friction: ResetIntegrator,
    /// The slots' states.
    slots: Store<LeanState>,
}

impl LeanStore {
    /// Room for `n` slots.
    pub(crate) fn reserve(&mut self, n: usize) {
        self.slots.reserve(n);
    }

    /// An empty store with room for `n` slots; its parameters are set by the first
    /// [`put`](Self::put).
    pub(crate) fn with_capacity(n: usize) -> Self {
        Self {
            paper: PaperLaw::new(0.0, 0.0),
            friction: ResetIntegrator::new(0.0, 0.0, 0.0, 0.0),
            slots: Store::with_capacity(n),
        }
    }

    /// Whether a record with the prototypes `normal` and `friction` can have a lean slot here: they
    /// are the paper's pair of laws, and either they have this store's parameters or no slot is
    /// live (`free` of them are free), so the store can take theirs.
    pub(crate) fn takes(&self, normal: &PaperLaw, friction: &ResetIntegrator, free: usize) -> bool {
        free == self.slots.len()
            || (self.paper.same_params(normal) && self.friction.same_params(friction))
    }

    /// Puts copies of `normal` and `friction`, begun at the god-object entry point `s_entry`
    /// (m, [`LawState::begin`]), in a free slot or a new one; the store takes their parameters
    /// (see [`takes`](Self::takes), which must hold).
    pub(crate) fn put(
        &mut self,
        free: &mut Vec<u32>,
        normal: &PaperLaw,
        friction: &ResetIntegrator,
        s_entry: f64,
    ) -> u32 {
        self.paper = *normal;
        self.friction = *friction;
        let mut fresh = LawState {
            friction: *friction,
            normal: ContactNormal::new(*normal),
        };
        fresh.begin(s_entry);
        self.slots.put(free, LeanState::of(&fresh))
    }

    /// The laws of `slot`: the shared parameters with the slot's state.
    #[inline(always)]
    pub(crate) fn laws(&self, slot: u32) -> LawState<PaperLaw, ResetIntegrator> {
        let s = self.slots.get(slot);
        LawState {
            friction: self.friction.with_state((s.p, s.k_used, s.mode)),
            normal: ContactNormal::with_offset(self.paper.with_state(s.stored), s.offset),
        }
    }

    /// Stores the state of `law` in `slot`.
    #[inline(always)]
    pub(crate) fn store(&mut self, slot: u32, law: &LawState<PaperLaw, ResetIntegrator>) {
        *self.slots.get_mut(slot) = LeanState::of(law);
    }

    /// The laws of `slot` in the whole form.
    pub(crate) fn whole(&self, slot: u32) -> Option<LawState> {
        ((slot as usize) < self.slots.len()).then(|| {
            let l = self.laws(slot);
            LawState {
                friction: FrictionModel::ResetIntegrator(l.friction),
                normal: l.normal.map(NormalModel::Paper),
            }
        })
    }

    /// Every slot (free ones too, so slot numbers stay) in the compact form.
    pub(crate) fn compact(&self) -> Vec<LawState<CompactNormal>> {
        (0..self.slots.len() as u32)
            .map(|slot| {
                let l = self.laws(slot);
                LawState {
                    friction: FrictionModel::ResetIntegrator(l.friction),
                    normal: l.normal.map(CompactNormal::Paper),
                }
            })
            .collect()
    }

    /// The slots in record order (see [`LawPool::repack`](super::law_pool::LawPool::repack)).
    pub(crate) fn repack(&mut self, records: &mut [VeContact]) {
        self.slots.repack(records);
    }

    /// Room for the slots and the repack buffer (for the compact form's store).
    pub(crate) fn capacity(&self) -> usize {
        self.slots.capacity()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::law_pool::SlotForm;
    use crate::contact::test_pile::{assert_same_poses, shove, toss_top_box};

    #[test]
    fn lean_state_is_40_bytes() {
        assert_eq!(std::mem::size_of::<LeanState>(), 40);
    }

    /// A world whose law slots are lean moves bit for bit like one whose slots are compact, and
    /// keeps doing so when it leaves the lean form mid-run, with live records, because the
    /// friction prototype changes (pile:20, whose laws are the paper's pair, thrown down at
    /// 1 m/s at step 0, shoved sideways at step 300 so that the friction springs carry load; at
    /// step 700 `Kr` drops by a fifth and the top box is tossed up, so that it lands with the new
    /// prototype while the others keep their records). With the impact surface offset on
    /// (docs/MODELS.md §E.7), the landings' impacts leave some slots with an offset.
    #[test]
    fn leaving_the_lean_slots_mid_run_changes_no_trajectory() {
        let world = crate::scene::builtin("pile:20", None)
            .unwrap()
            .unwrap()
            .world;
        const SWITCH: usize = 700;
        let (mut lean, mut compact) = (world.clone(), world);
        compact.contacts_mut().compact_law_slots();
        for w in [&mut lean, &mut compact] {
            w.params.contact.impact_surface_offset = true;
        }
        let mut offsets = 0;
        for k in 0..1500 {
            for w in [&mut lean, &mut compact] {
                if k == 0 {
                    // Thrown down at 1 m/s: the landings' impacts set surface offsets.
                    for b in w.bodies.iter_mut().filter(|b| b.inv_mass > 0.0) {
                        b.vel.y -= 1.0;
                    }
                }
                if k == 300 {
                    shove(w);
                }
            }
            if k == SWITCH {
                assert_eq!(lean.contacts().law_slot_form(), SlotForm::Lean);
                assert!(lean.contacts().contact_count() > 20, "records live");
                for w in [&mut lean, &mut compact] {
                    let FrictionModel::ResetIntegrator(r) = &mut w.friction else {
                        panic!("pile:20 has reset-integrator friction")
                    };
                    r.set_param("kr", 4.0e4).unwrap();
                    toss_top_box(w);
                }
            }
            lean.step();
            compact.step();
            assert_eq!(compact.contacts().law_slot_form(), SlotForm::Compact);
            assert_same_poses(&lean, &compact, k);
            assert_eq!(
                lean.contacts().stored_energy().to_bits(),
                compact.contacts().stored_energy().to_bits(),
                "step {k}"
            );
            offsets += lean
                .contacts()
                .records()
                .filter_map(|e| lean.contacts().laws(e))
                .filter(|l| l.normal.offset() > 0.0)
                .count();
        }
        assert_eq!(lean.contacts().law_slot_form(), SlotForm::Compact);
        assert!(offsets > 0, "no record carried a surface offset");
    }
}
