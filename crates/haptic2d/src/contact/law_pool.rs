//! The pool of per-contact law states: one [`LawState`] slot per contact record, reused through a
//! free list, so records stay small and creating or releasing a contact never allocates after
//! warm-up.
//!
//! The slots come in three forms, each holding the same laws with the same states:
//! - **lean** (40 bytes, `contact/lean_law.rs`): while every live record has the paper's pair of
//!   laws ([`PaperLaw`] and [`ResetIntegrator`]) with the same parameters, kept once;
//! - **compact** (144 bytes, `contact/compact_law.rs`): any law but the hysteretic wall;
//! - **whole** (272 bytes): any law.
//!
//! The pool starts lean and moves on to the next form when the prototypes need it (another law,
//! or other parameters while records live, in a lean pool; the hysteretic wall in a compact one),
//! converting every slot once and keeping slot numbers; it never moves back. Converting allocates
//! once, at the start of the sample that first runs with such prototypes
//! ([`LawPool::prepare`]): a scene's first sample, or the one after the prototypes are changed
//! mid-run.

use super::compact_law::CompactNormal;
use super::lean_law::{lean_pair, LeanStore};
use super::record::{LawState, VeContact, NO_LAW};
use crate::buffers::room;
use crate::laws::friction::{FrictionLaw, FrictionModel, ResetIntegrator};
use crate::laws::normal::{ContactNormal, NormalLaw, NormalModel, PaperLaw};

/// Slots of law states, addressed by [`VeContact::law`].
#[derive(Clone, Debug)]
pub(crate) struct LawPool {
    /// The slots, in one of their three forms.
    slots: Slots,
    /// Free slots, reused last-in first-out.
    free: Vec<u32>,
}

/// The pool's slots: lean while every live record has the paper's laws with the same parameters,
/// compact while no record needs the hysteretic wall, whole afterwards.
#[derive(Clone, Debug)]
pub(crate) enum Slots {
    /// The paper's pair of laws with shared parameters, 40 bytes a slot.
    Lean(LeanStore),
    /// Every law but the hysteretic wall, 144 bytes a slot.
    Compact(Store<LawState<CompactNormal>>),
    /// Any law, 272 bytes a slot.
    Whole(Store<LawState>),
}

/// The form of the slots (for tests).
#[cfg(test)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SlotForm {
    /// [`Slots::Lean`].
    Lean,
    /// [`Slots::Compact`].
    Compact,
    /// [`Slots::Whole`].
    Whole,
}

/// What the force pass needs of a form of slots: the laws of a slot, lent to `f`.
pub(crate) trait SlotAccess {
    /// The normal law's type in this form.
    type Normal: NormalLaw + Copy;
    /// The friction model's type in this form.
    type Friction: FrictionLaw + Copy;
    /// Runs `f` on the laws of `slot` (a slot handed out by [`LawPool::acquire`] and not
    /// released), keeping what it changes.
    fn with<R>(
        &mut self,
        slot: u32,
        f: impl FnOnce(&mut LawState<Self::Normal, Self::Friction>) -> R,
    ) -> R;
}

/// The slots of one form (`T`: a [`LawState`], or the lean form's per-slot state).
#[derive(Clone, Debug)]
pub(crate) struct Store<T> {
    /// Every slot ever handed out (free ones hold stale states).
    states: Vec<T>,
    /// The other buffer of [`repack`](LawPool::repack).
    spare: Vec<T>,
}

impl<T: Copy> Store<T> {
    pub(crate) fn with_capacity(n: usize) -> Self {
        Self {
            states: Vec::with_capacity(n),
            spare: Vec::with_capacity(n),
        }
    }

    /// Room for `n` slots in both buffers (no-op when they have it).
    pub(crate) fn reserve(&mut self, n: usize) {
        room(&mut self.states, n);
        room(&mut self.spare, n);
    }

    /// Puts `fresh` in a free slot, or a new one.
    pub(crate) fn put(&mut self, free: &mut Vec<u32>, fresh: T) -> u32 {
        match free.pop() {
            Some(slot) => {
                self.states[slot as usize] = fresh;
                slot
            }
            None => {
                self.states.push(fresh);
                (self.states.len() - 1) as u32
            }
        }
    }

    /// See [`LawPool::repack`].
    pub(crate) fn repack(&mut self, records: &mut [VeContact]) {
        self.spare.clear();
        for e in records.iter_mut() {
            if e.law != NO_LAW {
                self.spare.push(self.states[e.law as usize]);
                e.law = (self.spare.len() - 1) as u32;
            }
        }
        std::mem::swap(&mut self.states, &mut self.spare);
    }

    /// Slots handed out so far (free ones included).
    #[inline]
    pub(crate) fn len(&self) -> usize {
        self.states.len()
    }

    /// The state in `slot` (a slot handed out by [`LawPool::acquire`] and not released).
    #[inline]
    pub(crate) fn get(&self, slot: u32) -> &T {
        &self.states[slot as usize]
    }

    /// The state in `slot`, to change (see [`get`](Self::get)).
    #[inline]
    pub(crate) fn get_mut(&mut self, slot: u32) -> &mut T {
        &mut self.states[slot as usize]
    }

    /// Room for the slots and the repack buffer (what a store of another form needs).
    pub(crate) fn capacity(&self) -> usize {
        self.states.capacity().max(self.spare.capacity())
    }
}

impl<N: NormalLaw + Copy> SlotAccess for Store<LawState<N>> {
    type Normal = N;
    type Friction = FrictionModel;
    #[inline(always)]
    fn with<R>(&mut self, slot: u32, f: impl FnOnce(&mut LawState<N>) -> R) -> R {
        f(self.get_mut(slot))
    }
}

impl SlotAccess for LeanStore {
    type Normal = PaperLaw;
    type Friction = ResetIntegrator;
    #[inline(always)]
    fn with<R>(
        &mut self,
        slot: u32,
        f: impl FnOnce(&mut LawState<PaperLaw, ResetIntegrator>) -> R,
    ) -> R {
        let mut laws = self.laws(slot);
        let r = f(&mut laws);
        self.store(slot, &laws);
        r
    }
}

impl LawPool {
    /// An empty pool of lean slots with room for `n` records.
    pub(crate) fn with_capacity(n: usize) -> Self {
        Self {
            slots: Slots::Lean(LeanStore::with_capacity(n)),
            free: Vec::with_capacity(n),
        }
    }

    /// A slot holding copies of the prototypes `normal` and `friction`, begun at the god-object
    /// entry point `s_entry` (m, [`LawState::begin`]). A record that the slots' form cannot hold
    /// moves the pool on to the next form (module docs).
    pub(crate) fn acquire(
        &mut self,
        normal: &NormalModel,
        friction: &FrictionModel,
        s_entry: f64,
    ) -> u32 {
        if let Slots::Lean(store) = &mut self.slots {
            let free = self.free.len();
            if let Some((paper, reset)) =
                lean_pair(normal, friction).filter(|(p, r)| store.takes(p, r, free))
            {
                return store.put(&mut self.free, paper, reset, s_entry);
            }
            self.leave_lean();
        }
        if let Slots::Compact(store) = &mut self.slots {
            if let Some(model) = CompactNormal::from_model(normal) {
                let mut fresh = LawState {
                    friction: *friction,
                    normal: ContactNormal::new(model),
                };
                fresh.begin(s_entry);
                return store.put(&mut self.free, fresh);
            }
            self.widen();
        }
        let Slots::Whole(store) = &mut self.slots else {
            unreachable!("widened above")
        };
        let mut fresh = LawState {
            friction: *friction,
            normal: ContactNormal::new(*normal),
        };
        fresh.begin(s_entry);
        store.put(&mut self.free, fresh)
    }

    /// Moves the pool on to the form that records with the prototypes `normal` and `friction`
    /// need, unless it is in that form or a later one already. The contact set calls it at the
    /// start of every sample, so that a conversion (which allocates once) happens in a scene's
    /// first sample, before any contact, or in the sample where the prototypes change, not in
    /// the sample that creates the first record needing it.
    pub(crate) fn prepare(&mut self, normal: &NormalModel, friction: &FrictionModel) {
        if let Slots::Lean(store) = &self.slots {
            let free = self.free.len();
            if !lean_pair(normal, friction).is_some_and(|(p, r)| store.takes(p, r, free)) {
                self.leave_lean();
            }
        }
        if matches!(self.slots, Slots::Compact(_)) && CompactNormal::from_model(normal).is_none() {
            self.widen();
        }
    }

    /// The form of the slots.
    #[cfg(test)]
    pub(crate) fn form(&self) -> SlotForm {
        match self.slots {
            Slots::Lean(_) => SlotForm::Lean,
            Slots::Compact(_) => SlotForm::Compact,
            Slots::Whole(_) => SlotForm::Whole,
        }
    }

    /// Converts every lean slot (free ones too, so slot numbers stay) to the compact form.
    pub(crate) fn leave_lean(&mut self) {
        if let Slots::Lean(store) = &self.slots {
            let mut compact = Store::with_capacity(store.capacity());
            compact.states.extend(store.compact());
            self.slots = Slots::Compact(compact);
        }
    }

    /// Converts every lean or compact slot (free ones too, so slot numbers stay) to the whole
    /// form.
    pub(crate) fn widen(&mut self) {
        self.leave_lean();
        if let Slots::Compact(store) = &self.slots {
            let mut whole = Store::with_capacity(store.capacity());
            whole
                .states
                .extend(store.states.iter().map(LawState::<CompactNormal>::widen));
            self.slots = Slots::Whole(whole);
        }
    }

    /// Returns `slot` to the pool; [`NO_LAW`] is ignored.
    pub(crate) fn release(&mut self, slot: u32) {
        if slot != NO_LAW {
            self.free.push(slot);
        }
    }

    /// The impact of the record holding `slot` was resolved, with its distance history `d` (m) and
    /// valid length `hist` ([`ContactNormal::impact_resolved`]).
    pub(crate) fn impact_resolved(&mut self, slot: u32, d: [f64; 3], hist: u8) {
        match &mut self.slots {
            Slots::Lean(s) => s.with(slot, |l| l.normal.impact_resolved(d, hist)),
            Slots::Compact(s) => s.get_mut(slot).normal.impact_resolved(d, hist),
            Slots::Whole(s) => s.get_mut(slot).normal.impact_resolved(d, hist),
        }
    }

    /// Room for `n` slots in the current form and its free list, so that up to `n` live records
    /// allocate nothing (a form change, to a larger slot, still does).
    pub(crate) fn reserve(&mut self, n: usize) {
        match &mut self.slots {
            Slots::Lean(s) => s.reserve(n),
            Slots::Compact(s) => s.reserve(n),
            Slots::Whole(s) => s.reserve(n),
        }
        room(&mut self.free, n);
    }

    /// Moves the states of `records` (every entry whose `law` is a slot) into slots `0, 1, 2, …`
    /// in their order, and drops the free slots: the per-sample force pass, which walks the
    /// records in key order, then reads the pool front to back instead of at random (a law state
    /// is 40, 144 or 272 bytes, up to 5 cache lines, missed each when scattered). The states
    /// themselves are unchanged.
    pub(crate) fn repack(&mut self, records: &mut [VeContact]) {
        match &mut self.slots {
            Slots::Lean(s) => s.repack(records),
            Slots::Compact(s) => s.repack(records),
            Slots::Whole(s) => s.repack(records),
        }
        self.free.clear();
    }

    /// The state in `slot`, if it is one, in the whole form.
    pub(crate) fn get(&self, slot: u32) -> Option<LawState> {
        let i = slot as usize;
        match &self.slots {
            Slots::Lean(s) => s.whole(slot),
            Slots::Compact(s) => s.states.get(i).map(LawState::<CompactNormal>::widen),
            Slots::Whole(s) => s.states.get(i).copied(),
        }
    }

    /// The slots, for the force pass (which runs once per form, not per slot).
    #[inline]
    pub(crate) fn slots_mut(&mut self) -> &mut Slots {
        &mut self.slots
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::VeContact;
    use crate::laws::normal::PaperLaw;

    fn record() -> VeContact {
        use crate::collide::VeCandidate;
        use crate::contact::record::LocalGeom;
        use crate::geom::Vec2;
        VeContact {
            key: VeCandidate {
                vertex_collider: 0,
                vertex: 0,
                edge_collider: 1,
                edge: 0,
            },
            body_a: 0,
            nearest_edge: false,
            loaded: false,
            body_b: 1,
            state: None,
            d: [0.0; 3],
            hist: 1,
            s: 0.0,
            s_prev: 0.0,
            len: 1.0,
            point: Vec2::ZERO,
            n: Vec2::new(0.0, 1.0),
            c0: 0.0,
            s0: 0.0,
            s_g: 0.0,
            s_entry: 0.0,
            m_eff: 0.0,
            law: NO_LAW,
            f_n: 0.0,
            f_t: 0.0,
            since: 0,
            local: LocalGeom {
                v: Vec2::ZERO,
                e0: Vec2::ZERO,
                n: Vec2::new(0.0, 1.0),
            },
            own_axis: (f64::NAN, f64::NAN, f64::NAN),
        }
    }

    /// Repacking puts the records' slots in their order and keeps every record's state.
    #[test]
    fn repack_orders_slots_and_keeps_states() {
        let mut pool = LawPool::with_capacity(8);
        let normal = |kc: f64| NormalModel::Paper(PaperLaw::new(kc, 1.0));
        // Slots handed out, some released and reused, so the records' slots are scattered.
        let mut slots: Vec<u32> = (0..6)
            .map(|i| pool.acquire(&normal(100.0 + i as f64), &FrictionModel::None, 0.0))
            .collect();
        pool.release(slots[1]);
        pool.release(slots[4]);
        slots[1] = pool.acquire(&normal(201.0), &FrictionModel::None, 0.0);
        slots.swap(0, 5);
        let kc_of = |pool: &LawPool, slot: u32| match pool.get(slot).unwrap().normal.model {
            NormalModel::Paper(l) => l.kc,
            _ => unreachable!(),
        };
        let mut records: Vec<VeContact> = Vec::new();
        let template = record();
        for &s in &slots {
            records.push(VeContact { law: s, ..template });
        }
        records.insert(
            2,
            VeContact {
                law: NO_LAW,
                ..template
            },
        );
        let before: Vec<f64> = slots.iter().map(|&s| kc_of(&pool, s)).collect();
        pool.repack(&mut records);
        let after: Vec<u32> = records.iter().map(|e| e.law).collect();
        assert_eq!(after, vec![0, 1, NO_LAW, 2, 3, 4, 5]);
        let kcs: Vec<f64> = records
            .iter()
            .filter(|e| e.law != NO_LAW)
            .map(|e| kc_of(&pool, e.law))
            .collect();
        assert_eq!(kcs, before);
        // The pool hands out new slots after the packed ones.
        assert_eq!(pool.acquire(&normal(1.0), &FrictionModel::None, 0.0), 6);
    }

    fn paper_pair(kr: f64) -> (NormalModel, FrictionModel) {
        (
            NormalModel::Paper(PaperLaw::new(1e5, 40.0)),
            FrictionModel::ResetIntegrator(ResetIntegrator::new(kr, 0.5, 0.45, 20.0)),
        )
    }

    /// A record whose prototype has other parameters moves a lean pool to the compact form:
    /// every slot keeps its number and its state (offset, law, friction), free slots stay free,
    /// and the new slot has the new parameters.
    #[test]
    fn a_changed_prototype_leaves_the_lean_form_keeping_every_slot() {
        let mut pool = LawPool::with_capacity(2);
        let (normal, friction) = paper_pair(5e4);
        let slots: Vec<u32> = (0..5)
            .map(|i| pool.acquire(&normal, &friction, 0.01 * i as f64))
            .collect();
        assert_eq!(pool.form(), SlotForm::Lean);
        pool.impact_resolved(slots[3], [-0.002, 0.001, 0.0], 3);
        pool.release(slots[2]);
        let before: Vec<LawState> = slots.iter().map(|&s| pool.get(s).unwrap()).collect();
        assert_eq!(before[3].normal.offset(), 0.002);
        let (_, other) = paper_pair(4e4);
        assert_eq!(pool.acquire(&normal, &other, 0.5), slots[2]);
        assert_eq!(pool.form(), SlotForm::Compact);
        for (i, &s) in slots.iter().enumerate().filter(|(i, _)| *i != 2) {
            let after = pool.get(s).unwrap();
            assert_eq!(after.normal.offset(), before[i].normal.offset(), "slot {s}");
            assert_eq!(after.normal.model, before[i].normal.model, "slot {s}");
            assert_eq!(after.friction, before[i].friction, "slot {s}");
        }
        assert_eq!(pool.get(slots[2]).unwrap().friction, other);
        // A record with the first parameters still gets a slot, now compact.
        assert_eq!(pool.acquire(&normal, &friction, 0.0), 5);
        assert_eq!(pool.get(5).unwrap().friction, friction);
    }

    /// A lean pool with no live slot takes the next record's parameters and stays lean; with a
    /// live slot it does not.
    #[test]
    fn a_lean_pool_without_live_slots_takes_new_parameters() {
        let mut pool = LawPool::with_capacity(2);
        let (normal, friction) = paper_pair(5e4);
        let (_, other) = paper_pair(4e4);
        let (a, b) = (
            pool.acquire(&normal, &friction, 0.0),
            pool.acquire(&normal, &friction, 0.0),
        );
        pool.release(a);
        pool.release(b);
        let c = pool.acquire(&normal, &other, 0.0);
        assert_eq!(pool.form(), SlotForm::Lean);
        assert_eq!(pool.get(c).unwrap().friction, other);
        pool.acquire(&normal, &friction, 0.0);
        assert_eq!(pool.form(), SlotForm::Compact);
        assert_eq!(pool.get(c).unwrap().friction, other);
    }

    /// The first hysteretic wall widens the pool: every slot keeps its number and its state
    /// (offset, law, friction), free slots stay free, and both kinds of law get slots afterwards.
    #[test]
    fn a_hysteretic_wall_widens_the_pool_keeping_every_slot() {
        use crate::laws::friction::ResetIntegrator;
        use crate::laws::normal::HystereticLaw;
        let mut pool = LawPool::with_capacity(2);
        let friction = FrictionModel::ResetIntegrator(ResetIntegrator::per_contact());
        let slots: Vec<u32> = (0..5)
            .map(|i| {
                let normal = NormalModel::Paper(PaperLaw::new(1e4 + i as f64, 3.0));
                let friction = FrictionModel::ResetIntegrator(ResetIntegrator::new(
                    2e3 + i as f64,
                    0.5,
                    0.4,
                    9.0,
                ));
                pool.acquire(&normal, &friction, 0.01 * i as f64)
            })
            .collect();
        pool.impact_resolved(slots[3], [-0.002, 0.001, 0.0], 3);
        pool.release(slots[2]);
        assert!(matches!(pool.slots, Slots::Compact(_)));
        let Slots::Compact(store) = &pool.slots else {
            unreachable!()
        };
        let before: Vec<LawState<CompactNormal>> = store.states.clone();
        assert_eq!(before[3].normal.offset(), 0.002);
        let wall = NormalModel::Hysteretic(HystereticLaw::per_contact());
        // The released slot is reused by the wall; the others keep their states.
        assert_eq!(pool.acquire(&wall, &friction, 0.5), slots[2]);
        assert!(matches!(pool.slots, Slots::Whole(_)));
        for (i, &s) in slots.iter().enumerate().filter(|(i, _)| *i != 2) {
            let after = pool.get(s).unwrap();
            assert_eq!(after.normal.offset(), before[i].normal.offset(), "slot {s}");
            assert_eq!(
                after.normal.model,
                before[i].normal.model.to_model(),
                "slot {s}"
            );
            assert_eq!(after.friction, before[i].friction, "slot {s}");
        }
        assert_eq!(pool.get(slots[2]).unwrap().normal.model, wall);
        let paper = NormalModel::Paper(PaperLaw::new(7.0, 1.0));
        assert_eq!(pool.acquire(&paper, &friction, 0.0), 5);
        assert_eq!(pool.get(5).unwrap().normal.model, paper);
    }
}
