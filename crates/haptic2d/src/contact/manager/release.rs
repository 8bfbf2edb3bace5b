//! Stage 2 of the contact step: §8.2 rule 4 (release of a record that left its edge) and rule 5
//! (re-collision, optional).

use super::sync::in_range;
use super::{release_record, ContactSet};
use crate::collide::Collider;
use crate::contact::record::{ContactEvent, ContactState, EventKind};

impl ContactSet {
    /// §8.2 rule 4 (release) and rule 5 (re-collision, optional).
    /// The edge range extends across the seams that face a partly covered edge (`in_range`).
    pub(super) fn release(&mut self, tick: u64, colliders: &[Collider]) {
        let p = self.params;
        for e in self.entries.iter_mut() {
            if e.state != Some(ContactState::Continuous) {
                continue;
            }
            if e.d[0] > p.delta_off || !in_range(e, colliders, p.eps_s) {
                // A loaded record leaving its edge's range: its effective depth may go to its
                // pair's clip records (crossing corners, `clip.rs`) in this sample.
                if e.d[0] <= p.delta_off {
                    let offset = self.laws.get(e.law).map_or(0.0, |l| l.normal.offset());
                    let depth = -e.d[0] - offset;
                    if depth > 0.0 {
                        let (a, b) = (e.key.vertex_collider, e.key.edge_collider);
                        self.dropped.push(((a.min(b), a.max(b)), depth));
                    }
                }
                release_record(e, &mut self.laws, &mut self.events, tick);
            } else if let Some(v_re) = p.v_re {
                if p.impacts && e.c0 < -v_re {
                    e.state = Some(ContactState::Colliding);
                    self.events.push(ContactEvent {
                        tick,
                        key: e.key,
                        kind: EventKind::Recollision,
                    });
                }
            }
        }
    }
}
