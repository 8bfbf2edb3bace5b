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
        }
    }

    /// Repacking puts the records' slots in their order and keeps every record's state.
    #[test]
    fn repack_orders_slots_and_keeps_states() {
        let mut pool = LawPool::with_capacity(8);
        let normal = |kc: f64| NormalModel::Paper(PaperLaw::new(kc, 1.0));
        // Slots handed out, some released and reused, so the records' slots are scattered.
        let mut slots: Vec<u32> = (0..6)
            .map(|i| pool.acquire(&normal(100.0 + i as f64), &FrictionModel::None))
            .collect();
        pool.release(slots[1]);
        pool.release(slots[4]);
        slots[1] = pool.acquire(&normal(201.0), &FrictionModel::None);
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
        assert_eq!(pool.acquire(&normal(1.0), &FrictionModel::None), 6);
    }
}
