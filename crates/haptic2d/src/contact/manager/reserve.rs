//! Room for a number of records, made before a real-time loop (`World::reserve_contacts`): the
//! contact set's per-record buffers grow during a landing pile's collapse otherwise (pile:1000:
//! about 250 allocations, up to 1.1 MB at once, inside the loop's ticks).

use super::ContactSet;
use crate::buffers::room;

impl ContactSet {
    /// Grows every per-record buffer of the set (the records, their law slots, the force pass's
    /// loaded contacts, the impact set and its solver, the crossing pairs) to hold `records`
    /// records, and the per-collider and per-body ones to `colliders` and `bodies`, so that a
    /// sample with at most that many records allocates nothing. Changes no result: only
    /// capacities.
    pub fn reserve(&mut self, records: usize, colliders: usize, bodies: usize) {
        room(&mut self.entries, records);
        room(&mut self.pending, records);
        room(&mut self.changes, records);
        self.laws.reserve(records);
        room(&mut self.loaded, records);
        room(&mut self.loaded_keys, records);
        room(&mut self.events, records);
        room(&mut self.dropped, records);
        room(&mut self.pool, records);
        room(&mut self.crossing, records);
        room(&mut self.crossing_info, records);
        if self.crossing_mark.len() < colliders {
            self.crossing_mark.resize(colliders, false);
        }
        room(&mut self.rows, records);
        room(&mut self.row_entry, records);
        room(&mut self.struck_entry, records);
        room(&mut self.carry_rows, records);
        room(&mut self.island_rows, records);
        room(&mut self.row_order, records);
        room(&mut self.row_island, records);
        self.solver.reserve(records);
        self.solver.reserve_bodies(bodies);
    }
}
