//! The column set of `haptic2d simulate`'s CSV (docs/CSV.md), assembled from the core's public API so
//! `World.run` returns the same names and the same numbers as the CLI's file.
//!
//! Columns: `t, energy.kinetic, energy.stored, work.applied, contacts, overlap` (the largest
//! separating-axis overlap of two bodies, m), then per dynamic body `NAME`
//! (in body order) `NAME.x, NAME.y, NAME.theta, NAME.vx, NAME.vy, NAME.omega`.

use haptic2d::world::World;

/// Column buffers for one run, sized up front so recording a row never reallocates.
pub struct WorldColumns {
    /// Column names, in CSV order.
    pub names: Vec<String>,
    /// Every column but `contacts` (f64), in CSV order without it.
    pub values: Vec<Vec<f64>>,
    /// The `contacts` column (number of contact records).
    pub contacts: Vec<i64>,
    dynamic: Vec<usize>,
}

/// Number of global columns before the per-body ones (`contacts` included).
pub const GLOBAL: [&str; 6] = [
    "t",
    "energy.kinetic",
    "energy.stored",
    "work.applied",
    "contacts",
    "overlap",
];

impl WorldColumns {
    /// Empty columns for `world`'s dynamic bodies, with room for `rows` rows.
    pub fn new(world: &World, rows: usize) -> Self {
        let dynamic: Vec<usize> = (0..world.bodies.len())
            .filter(|&i| world.bodies[i].is_dynamic())
            .collect();
        let mut names: Vec<String> = GLOBAL.iter().map(|s| s.to_string()).collect();
        for &i in &dynamic {
            let n = &world.bodies[i].name;
            for c in ["x", "y", "theta", "vx", "vy", "omega"] {
                names.push(format!("{n}.{c}"));
            }
        }
        let nf = names.len() - 1;
        Self {
            names,
            values: (0..nf).map(|_| Vec::with_capacity(rows)).collect(),
            contacts: Vec::with_capacity(rows),
            dynamic,
        }
    }

    /// Records the current state of `world` as one row.
    #[inline]
    pub fn push(&mut self, world: &World) {
        let e = world.ledger();
        let v = &mut self.values;
        v[0].push(world.time());
        v[1].push(e.kinetic);
        v[2].push(e.stored);
        v[3].push(e.applied_work);
        self.contacts.push(world.contacts().contact_count() as i64);
        v[4].push(world.max_overlap().depth);
        for (j, &i) in self.dynamic.iter().enumerate() {
            let b = &world.bodies[i];
            let c = 5 + 6 * j;
            v[c].push(b.pose.pos.x);
            v[c + 1].push(b.pose.pos.y);
            v[c + 2].push(b.pose.angle);
            v[c + 3].push(b.vel.x);
            v[c + 4].push(b.vel.y);
            v[c + 5].push(b.omega);
        }
    }
}
