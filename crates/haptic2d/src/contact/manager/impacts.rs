//! Stage 5 of the contact step (§7): the impact set (Colliding records, and Continuous ones touching
//! a colliding body), solved island by island; velocity jumps applied to the bodies now.

use super::ContactSet;
use crate::body::Body;
use crate::contact::impact::ImpactRow;
use crate::contact::record::{ContactEvent, ContactState, EventKind};

impl ContactSet {
    /// §7: every Colliding record (restitution `e`) and every Continuous record touching a body of a
    /// colliding one (restitution 0) form the impact set; velocity jumps are applied to `bodies` now.
    pub(super) fn resolve_impacts(&mut self, tick: u64, bodies: &mut [Body]) {
        for f in self.body_flag.iter_mut() {
            *f = false;
        }
        for e in &self.entries {
            if e.state == Some(ContactState::Colliding) {
                self.body_flag[e.body_a] |= bodies[e.body_a].is_dynamic();
                self.body_flag[e.body_b] |= bodies[e.body_b].is_dynamic();
            }
        }
        self.rows.clear();
        self.row_entry.clear();
        for (idx, e) in self.entries.iter().enumerate() {
            let restitution = match e.state {
                Some(ContactState::Colliding) => self.params.restitution,
                Some(ContactState::Continuous)
                    if self.body_flag[e.body_a] || self.body_flag[e.body_b] =>
                {
                    0.0
                }
                _ => continue,
            };
            self.rows.push(ImpactRow {
                body_a: e.body_a,
                body_b: e.body_b,
                n: e.n,
                r_a: e.point - bodies[e.body_a].pose.pos,
                r_b: e.point - bodies[e.body_b].pose.pos,
                restitution,
            });
            self.row_entry.push(idx);
        }
        let before: f64 = bodies.iter().map(|b| b.kinetic_energy()).sum();
        self.solve_islands(bodies);
        let after: f64 = bodies.iter().map(|b| b.kinetic_energy()).sum();
        self.last_impact_loss = before - after;
        self.impacts_solved += 1;
        for e in self.entries.iter_mut() {
            if e.state == Some(ContactState::Colliding) {
                e.state = Some(ContactState::Continuous);
                // Option (docs/MODELS.md §F.7; default off = §7.2 step 4): the restitution law has
                // set the velocity, so the depth the discrete detection found is not paid back as
                // spring impulse (the law's surface moves in to it), and the distance history
                // before the jump no longer predicts the motion, so the SEH estimate restarts from
                // this sample (`δ̃ = δ` until three post-impact samples exist, §5.5).
                if self.params.impact_surface_offset {
                    self.laws.impact_resolved(e.law, e.d, e.hist);
                    e.hist = 1;
                }
                self.events.push(ContactEvent {
                    tick,
                    key: e.key,
                    kind: EventKind::Resolved,
                });
            }
            // Step 5: recompute C0 and S0 with the post-impact velocities.
            let v_rel =
                bodies[e.body_a].point_velocity(e.point) - bodies[e.body_b].point_velocity(e.point);
            e.c0 = e.n.dot(v_rel);
            e.s0 = e.t().dot(v_rel);
        }
    }

    /// Solves the impact set island by island: rows that share no dynamic body are independent (the
    /// Delassus matrix is block diagonal), so each connected component is its own small LCP. Islands
    /// are taken in the order of their root body, rows in key order: the result is deterministic and
    /// identical to solving the whole set at once.
    fn solve_islands(&mut self, bodies: &mut [Body]) {
        // Union–find over dynamic bodies (fixed bodies connect nothing).
        for (i, p) in self.parent.iter_mut().enumerate() {
            *p = i as u32;
        }
        fn find(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                let g = parent[parent[i as usize] as usize];
                parent[i as usize] = g;
                i = g;
            }
            i
        }
        for r in &self.rows {
            if bodies[r.body_a].is_dynamic() && bodies[r.body_b].is_dynamic() {
                let (a, b) = (
                    find(&mut self.parent, r.body_a as u32),
                    find(&mut self.parent, r.body_b as u32),
                );
                if a != b {
                    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                    self.parent[hi as usize] = lo;
                }
            }
        }
        // Island id of each row: the root of its dynamic body.
        self.row_island.clear();
        for r in &self.rows {
            let b = if bodies[r.body_a].is_dynamic() {
                r.body_a
            } else {
                r.body_b
            };
            let root = find(&mut self.parent, b as u32);
            self.row_island.push(root);
        }
        // Group rows by island (stable: rows keep key order inside an island), then solve each run.
        self.row_order.clear();
        self.row_order.extend(0..self.rows.len() as u32);
        let islands = &self.row_island;
        self.row_order
            .sort_unstable_by_key(|&r| (islands[r as usize], r));
        let mut k = 0;
        while k < self.row_order.len() {
            let island = self.row_island[self.row_order[k] as usize];
            self.island_rows.clear();
            while k < self.row_order.len() && self.row_island[self.row_order[k] as usize] == island
            {
                self.island_rows.push(self.rows[self.row_order[k] as usize]);
                k += 1;
            }
            self.solver.solve_island(&self.island_rows, bodies);
        }
    }
}
