//! Stage 3 of the contact step: a Continuous record whose vertex has come nearer to another line of
//! its edge polygon is handed over to that edge (the depth invariant of [`ContactSet::step`]).

use super::invariant::overlap_ok;
use super::sync::new_entry;
use super::PastPoses;
use super::{release_record, start_continuous, ContactSet};
use crate::body::Body;
use crate::collide::{nearest_line, Collider, VeCandidate};
use crate::contact::record::ContactState;
use crate::laws::friction::FrictionModel;
use crate::laws::normal::NormalModel;

impl ContactSet {
    /// Hands a Continuous record over to the nearer edge where the depth invariant of
    /// [`ContactSet::step`] would break: when some other line `j` of B is nearer to the vertex
    /// than the record's edge line by more than `δ_c` (`d_e < max_j d_j − δ_c`; a long-lived
    /// record of a vertex that slid or rotated deep past a corner of B). The record is released
    /// and, if the vertex is inside B (`max_j d_j ≤ δ_off`) and in the range of `j` (always so
    /// inside B), a Continuous record is started on `j` (events `Released`, then
    /// `Created(Continuous)`: it is not an impact). Its stored energy drops from `½·K_c·d_e²` to
    /// `½·K_c·d_j²`, so the hand-over dissipates and never creates energy. The `δ_c` hysteresis is
    /// the corner tolerance: at a stacked corner the vertex is equally near both lines up to
    /// round-off, and the corner-on-corner rule, not the distances, decides the edge there.
    pub(super) fn hand_over(
        &mut self,
        tick: u64,
        colliders: &[Collider],
        bodies: &[Body],
        past: &PastPoses<'_>,
        normal: &NormalModel,
        friction: &FrictionModel,
    ) {
        let p = self.params;
        self.pending.clear();
        for idx in 0..self.entries.len() {
            let e = &self.entries[idx];
            // A key from this sample's vertex scan holds the invariant (`nearest_edge`).
            if e.state != Some(ContactState::Continuous) || e.nearest_edge {
                continue;
            }
            let cb = &colliders[e.key.edge_collider as usize];
            let (j, max_d) = nearest_line(cb, e.point);
            if e.d[0] >= max_d - self.delta_c || overlap_ok(e.key, colliders, self.delta_c) {
                continue;
            }
            let key = VeCandidate {
                edge: j as u32,
                ..e.key
            };
            let s_j = cb.edge_coordinate(j, e.point);
            // Never onto a seam (the vertex is then outside B, in the next piece).
            let holds = !cb.is_seam(j)
                && max_d <= p.delta_off
                && s_j >= cb.edge_range(j).0 - p.eps_s
                && s_j <= cb.edge_range(j).1 + p.eps_s;
            let e = &mut self.entries[idx];
            release_record(e, &mut self.laws, &mut self.events, tick);
            if !holds {
                continue;
            }
            match self.entries.binary_search_by(|x| x.key.cmp(&key)) {
                Ok(t) if !self.entries[t].is_contact() => {
                    let n = &mut self.entries[t];
                    start_continuous(n, tick, &mut self.events);
                    n.law = self.laws.acquire(normal, friction, n.s_g);
                }
                Ok(_) => {}
                Err(_) => {
                    let mut n = new_entry(tick, key, colliders, bodies, past);
                    start_continuous(&mut n, tick, &mut self.events);
                    n.law = self.laws.acquire(normal, friction, n.s_g);
                    self.pending.push(n);
                }
            }
        }
        if !self.pending.is_empty() {
            self.entries.extend_from_slice(&self.pending);
            self.entries.sort_unstable_by_key(|e| e.key);
            self.pending.clear();
        }
    }
}
