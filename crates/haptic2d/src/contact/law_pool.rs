//! The pool of per-contact law states: one [`LawState`] slot per contact record, reused through a
//! free list, so records stay small and creating or releasing a contact never allocates after warm-up.

use super::record::{LawState, NO_LAW};
use crate::laws::friction::FrictionModel;
use crate::laws::normal::{ContactNormal, NormalModel};

/// Slots of law states, addressed by [`VeContact::law`](super::VeContact::law).
#[derive(Clone, Debug, Default)]
pub(crate) struct LawPool {
    /// Every slot ever handed out (free ones hold stale states).
    states: Vec<LawState>,
    /// Free slots, reused last-in first-out.
    free: Vec<u32>,
    /// The other buffer of [`repack`](Self::repack).
    spare: Vec<LawState>,
}

impl LawPool {
    /// An empty pool with room for `n` records.
    pub(crate) fn with_capacity(n: usize) -> Self {
        Self {
            states: Vec::with_capacity(n),
            free: Vec::with_capacity(n),
            spare: Vec::with_capacity(n),
        }
    }

    /// A slot holding copies of the prototypes `normal` and `friction`.
    pub(crate) fn acquire(&mut self, normal: &NormalModel, friction: &FrictionModel) -> u32 {
        let fresh = LawState {
            normal: ContactNormal::new(*normal),
            friction: *friction,
        };
        match self.free.pop() {
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

    /// Returns `slot` to the pool; [`NO_LAW`] is ignored.
    pub(crate) fn release(&mut self, slot: u32) {
        if slot != NO_LAW {
            self.free.push(slot);
        }
    }

    /// Moves the states of `records` (every entry whose `law` is a slot) into slots `0, 1, 2, …`
    /// in their order, and drops the free slots: the per-sample force pass, which walks the
    /// records in key order, then reads the pool front to back instead of at random (a law state
    /// is 272 bytes, a cache miss each when scattered). The states themselves are unchanged.
    pub(crate) fn repack(&mut self, records: &mut [super::VeContact]) {
        self.spare.clear();
        for e in records.iter_mut() {
            if e.law != NO_LAW {
                self.spare.push(self.states[e.law as usize]);
                e.law = (self.spare.len() - 1) as u32;
            }
        }
        std::mem::swap(&mut self.states, &mut self.spare);
        self.free.clear();
    }

    /// The state in `slot`, if it is one.
    #[inline]
    pub(crate) fn get(&self, slot: u32) -> Option<&LawState> {
        self.states.get(slot as usize)
    }

    /// The state in `slot` (a slot handed out by [`acquire`](Self::acquire) and not released).
    #[inline]
    pub(crate) fn get_mut(&mut self, slot: u32) -> &mut LawState {
        &mut self.states[slot as usize]
    }
}
