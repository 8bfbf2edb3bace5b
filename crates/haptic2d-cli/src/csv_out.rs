//! The world CSV writer (schema: docs/CSV.md).

use haptic2d::world::World;
use haptic2d_rt::float_text::push_f64;
use std::fmt::Write as _;
use std::io::Write;

/// Writes world states as CSV rows; the column set is fixed at construction.
pub struct WorldCsv<W: Write> {
    out: W,
    dynamic: Vec<usize>,
    line: String,
}

impl<W: Write> WorldCsv<W> {
    /// Writes the header for `world`'s dynamic bodies.
    pub fn new(mut out: W, world: &World) -> std::io::Result<Self> {
        let dynamic: Vec<usize> = (0..world.bodies.len())
            .filter(|&i| world.bodies[i].is_dynamic())
            .collect();
        let mut header =
            String::from("t,energy.kinetic,energy.stored,work.applied,contacts,overlap");
        for &i in &dynamic {
            let n = &world.bodies[i].name;
            for c in ["x", "y", "theta", "vx", "vy", "omega"] {
                let _ = write!(header, ",{n}.{c}");
            }
        }
        header.push('\n');
        out.write_all(header.as_bytes())?;
        Ok(Self {
            out,
            dynamic,
            line: String::with_capacity(4096),
        })
    }

    /// Writes one row for the current state of `world`, whose largest overlap of two bodies now
    /// is `overlap_m` (m, [`World::max_overlap`]'s depth: the caller's summary has just taken it,
    /// so the row does not run the separating-axis tests a second time).
    pub fn row(&mut self, world: &World, overlap_m: f64) -> std::io::Result<()> {
        let l = &mut self.line;
        l.clear();
        let e = world.ledger();
        // Each number as `{}` writes it (`float_text`: the same characters, a fraction of the
        // cost; a row of a thousand bodies is six thousand numbers).
        push_f64(l, world.time());
        for x in [e.kinetic, e.stored, e.applied_work] {
            l.push(',');
            push_f64(l, x);
        }
        let _ = write!(l, ",{}", world.contacts().contact_count());
        l.push(',');
        push_f64(l, overlap_m);
        for &i in &self.dynamic {
            for x in world.bodies[i].state() {
                l.push(',');
                push_f64(l, x);
            }
        }
        l.push('\n');
        self.out.write_all(l.as_bytes())
    }

    /// Flushes the output.
    pub fn finish(mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}
