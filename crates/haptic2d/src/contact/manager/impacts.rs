//! Stage 5 of the contact step (§7): the impact set (Colliding records, and Continuous ones touching
//! a colliding body), solved island by island; velocity jumps applied to the bodies now.

use super::{ContactSet, Wrench2};
use crate::body::Body;
use crate::contact::impact::ImpactRow;
use crate::contact::record::{ContactEvent, ContactState, EventKind};
use crate::contact::ImpactFriction;
use crate::geom::cross;

impl ContactSet {
    /// §7: every Colliding record (restitution `e`) and every Continuous record of the same island
    /// of touching bodies (restitution 0; issue 35: the whole island, not one level of
    /// neighbours, §7.1) form the impact set; velocity jumps are applied to `bodies` now.
    pub(super) fn resolve_impacts(&mut self, tick: u64, bodies: &mut [Body]) {
        // Islands of touching bodies: union–find over every record between two dynamic bodies
        // (fixed bodies connect nothing); an island is struck if one of its records collides.
        singletons(&mut self.parent);
        for e in &self.entries {
            if e.state.is_some() && bodies[e.body_a].is_dynamic() && bodies[e.body_b].is_dynamic() {
                union(&mut self.parent, e.body_a, e.body_b);
            }
        }
        for f in self.body_flag.iter_mut() {
            *f = false;
        }
        for e in &self.entries {
            if e.state == Some(ContactState::Colliding) {
                let b = if bodies[e.body_a].is_dynamic() {
                    e.body_a
                } else {
                    e.body_b
                };
                let root = find(&mut self.parent, b as u32) as usize;
                self.body_flag[root] = true;
            }
        }
        self.rows.clear();
        self.row_entry.clear();
        self.struck_entry.clear();
        self.carry_rows.clear();
        // An island can hold every record: room for all of them, grown with the records (whose
        // own growth allocates anyway), so a landing pile's impacts allocate nothing new.
        let most = self.entries.len();
        self.rows.reserve(most);
        self.row_entry.reserve(most);
        self.carry_rows.reserve(most);
        self.struck_entry.reserve(most);
        self.island_rows.reserve(most);
        self.row_order.reserve(most);
        self.row_island.reserve(most);
        self.solver.reserve(most);
        for idx in 0..self.entries.len() {
            let e = &self.entries[idx];
            let restitution = match e.state {
                Some(ContactState::Colliding) => self.params.restitution,
                Some(ContactState::Continuous) => {
                    let b = if bodies[e.body_a].is_dynamic() {
                        e.body_a
                    } else {
                        e.body_b
                    };
                    if !bodies[b].is_dynamic()
                        || !self.body_flag[find(&mut self.parent, b as u32) as usize]
                    {
                        continue;
                    }
                    0.0
                }
                _ => continue,
            };
            let e = &self.entries[idx];
            let row = ImpactRow {
                body_a: e.body_a,
                body_b: e.body_b,
                n: e.n,
                r_a: e.point - bodies[e.body_a].pose.pos,
                r_b: e.point - bodies[e.body_b].pose.pos,
                restitution,
            };
            if e.state == Some(ContactState::Colliding) {
                self.struck_entry.push(idx);
                self.carry_rows.push(ImpactRow {
                    restitution: 0.0,
                    ..row
                });
            }
            self.rows.push(row);
            self.row_entry.push(idx);
        }
        let before: f64 = bodies.iter().map(|b| b.kinetic_energy()).sum();
        // The rows are every record of the struck islands, so their islands are those islands:
        // `parent` already holds them (see `solve_islands`).
        self.solve_islands(bodies, None, Forest::Built);
        let after: f64 = bodies.iter().map(|b| b.kinetic_energy()).sum();
        self.last_impact_loss = before - after;
        self.impacts_solved += 1;
        for e in self.entries.iter_mut() {
            if e.state == Some(ContactState::Colliding) {
                e.state = Some(ContactState::Continuous);
                // Option (docs/MODELS.md §E.7; default off = §7.2 step 4): the restitution law has
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

    /// Issue 35 item 3 (with `impact_surface_offset`, docs/MODELS.md §7.6): the contacts struck
    /// in this sample carry the sample's other forces, so the restitution law sets the velocity
    /// at the *end* of the impact sample, `u_{k+1} = −e·u_k` on each colliding contact, instead
    /// of `−e·u_k` less the sample's loads (`e·|v| − g·T` for a drop).
    ///
    /// Called by the world after the contact step (`World::begin_step`), with the sample's load
    /// wrenches `loads` (N, N·m per body) and the contact wrenches `wrenches` of the force pass:
    /// with `Δu = T·M⁻¹·F` the velocity change those forces and the plant damping would give the
    /// bodies over the sample, the carried impulses `p ≥ 0` on the colliding rows solve the
    /// compression LCP `w = G·Δu + A·p ≥ 0`, `p ⟂ w` (the impact solver, restitution 0, frictionless),
    /// so no colliding contact's normal velocity drops over the sample while `p > 0`, and `p = 0`
    /// where the forces already separate it. They are added to `wrenches` as forces `p/T` held over
    /// the sample (the contact wrench a device reads includes them). The bodies' velocities are
    /// restored: only the wrenches change. Nothing to do unless this sample resolved an impact
    /// (and `impact_surface_offset` is on: the paper's §7.2 step 4 carries nothing).
    ///
    /// The drive (a device's coupling force `f_cs`, §11) is not carried: it is the hand's push on
    /// the slave, which the impact sample should feel, and carrying it would let the contact do
    /// work on the device port (the box-in-walls coupling run's passivity observer went to
    /// −0.04 J with it).
    pub fn carry_forces(
        &mut self,
        dt: f64,
        bodies: &mut [Body],
        loads: &[Wrench2],
        wrenches: &mut [Wrench2],
    ) {
        if self.carry_rows.is_empty() || dt <= 0.0 || !self.params.impact_surface_offset {
            return;
        }
        self.carry_saved.clear();
        self.carry_delta.clear();
        for ((b, w), l) in bodies.iter_mut().zip(wrenches.iter()).zip(loads) {
            self.carry_saved.push((b.vel, b.omega));
            if b.is_dynamic() {
                let f = l.force + w.force - b.vel * b.damping;
                b.vel = f * (dt * b.inv_mass);
                b.omega = (l.torque + w.torque) * dt * b.inv_inertia;
            }
            self.carry_delta.push((b.vel, b.omega));
        }
        std::mem::swap(&mut self.rows, &mut self.carry_rows);
        // Frictionless: the carry is normal only (the next impact sets the mode again).
        self.solver.set_friction(ImpactFriction::None, 0.0);
        self.solve_islands(bodies, Some((&mut *wrenches, dt)), Forest::Build);
        std::mem::swap(&mut self.rows, &mut self.carry_rows);
        let inv_dt = 1.0 / dt;
        for (i, b) in bodies.iter_mut().enumerate() {
            let ((v, omega), (dv, domega)) = (self.carry_saved[i], self.carry_delta[i]);
            if b.is_dynamic() {
                wrenches[i].force += (b.vel - dv) * (b.mass * inv_dt);
                wrenches[i].torque += (b.omega - domega) * (b.inertia * inv_dt);
            }
            b.vel = v;
            b.omega = omega;
        }
    }

    /// Solves the impact set island by island: rows that share no dynamic body are independent (the
    /// Delassus matrix is block diagonal), so each connected component is its own small LCP. Islands
    /// are taken in the order of their root body, rows in key order: the result is deterministic and
    /// identical to solving the whole set at once.
    ///
    /// With [`Forest::Built`], `parent` already holds the union–find forest of the records of
    /// `resolve_impacts`: its rows are every Continuous or Colliding record (both bodies dynamic
    /// or not) of each struck island, so the rows join exactly the bodies those records join, and
    /// a root is the smallest body index of its set whatever the order of the unions: the same
    /// roots as a forest built over the rows.
    fn solve_islands(
        &mut self,
        bodies: &mut [Body],
        mut reactions: Option<(&mut [Wrench2], f64)>,
        forest: Forest,
    ) {
        match forest {
            Forest::Build => {
                singletons(&mut self.parent);
                rows_forest(&mut self.parent, &self.rows, bodies);
            }
            // The unit tests (piles landing) check the claim on every impact sample.
            #[cfg(test)]
            Forest::Built => self.assert_forest_is_the_rows(bodies),
            #[cfg(not(test))]
            Forest::Built => {}
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
        // One island (a landing pile's collapse): the rows in key order are its rows; no grouping.
        if self.row_island.windows(2).all(|w| w[0] == w[1]) {
            if !self.rows.is_empty() {
                self.solver.solve_island(&self.rows, bodies);
                if let Some((w, dt)) = reactions {
                    fixed_reactions(&self.rows, self.solver.impulses(), bodies, w, dt);
                }
            }
            return;
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
            if let Some((w, dt)) = reactions.as_mut() {
                fixed_reactions(&self.island_rows, self.solver.impulses(), bodies, w, *dt);
            }
        }
    }
}

/// The fixed bodies' share of an island's impulses `impulses` (N·s, one per row of `rows`), added
/// to their wrenches `w` as forces held over `dt` (s) (the carry).
fn fixed_reactions(
    rows: &[ImpactRow],
    impulses: &[f64],
    bodies: &[Body],
    w: &mut [Wrench2],
    dt: f64,
) {
    for (r, &p) in rows.iter().zip(impulses) {
        let f = r.n * (p / dt);
        if !bodies[r.body_a].is_dynamic() {
            w[r.body_a].force += f;
            w[r.body_a].torque += cross(r.r_a, f);
        }
        if !bodies[r.body_b].is_dynamic() {
            w[r.body_b].force -= f;
            w[r.body_b].torque -= cross(r.r_b, f);
        }
    }
}

/// Union–find over the dynamic bodies of `rows` (fixed bodies connect nothing) into `parent`.
fn rows_forest(parent: &mut [u32], rows: &[ImpactRow], bodies: &[Body]) {
    for r in rows {
        if bodies[r.body_a].is_dynamic() && bodies[r.body_b].is_dynamic() {
            union(parent, r.body_a, r.body_b);
        }
    }
}

#[cfg(test)]
impl ContactSet {
    /// Asserts that `parent` gives every row's body the root a forest built over the rows gives it.
    fn assert_forest_is_the_rows(&mut self, bodies: &[Body]) {
        let mut fresh: Vec<u32> = (0..self.parent.len() as u32).collect();
        rows_forest(&mut fresh, &self.rows, bodies);
        for r in &self.rows {
            for b in [r.body_a, r.body_b] {
                let (kept, built) = (find(&mut self.parent, b as u32), find(&mut fresh, b as u32));
                assert_eq!(kept, built, "body {b}'s island");
            }
        }
    }
}

/// Whether `solve_islands` finds `parent` holding its rows' islands already.
#[derive(Clone, Copy)]
enum Forest {
    /// Built by the caller over records joining exactly the bodies the rows join.
    Built,
    /// To be built over the rows.
    Build,
}

/// Makes every body its own set (union–find roots: `parent[i] = i`).
#[inline]
fn singletons(parent: &mut [u32]) {
    for (i, p) in parent.iter_mut().enumerate() {
        *p = i as u32;
    }
}

/// Joins the sets of bodies `a` and `b`; the root of the union is the smaller root.
#[inline]
fn union(parent: &mut [u32], a: usize, b: usize) {
    let (a, b) = (find(parent, a as u32), find(parent, b as u32));
    if a != b {
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        parent[hi as usize] = lo;
    }
}

/// The root of `i` in the union–find forest `parent` (path halving).
fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let g = parent[parent[i as usize] as usize];
        parent[i as usize] = g;
        i = g;
    }
    i
}
