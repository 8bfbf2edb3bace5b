//! [`LoggedTick`]: what the haptic loop pushes into the telemetry ring when it logs — the loop's
//! timing, the encoder angles, the tick record, and a fixed-size [`WorldSample`] of the bodies,
//! contacts and energy ledger. `Copy` and fixed-size, so it crosses the wait-free ring without
//! allocation; [`LoggedTick::capture`] is allocation-free.

use crate::logger::CsvRecord;
use crate::mcap::columns::run_csv_header;
use crate::runner::TickInfo;
use haptic2d::contact::ContactState;
use haptic2d::haptic::TickRecord;
use haptic2d::integrate::EnergyLedger;
use haptic2d::world::World;

/// Bodies kept per sample; further bodies are counted in [`WorldSample::body_count`] but not kept.
pub const MAX_LOG_BODIES: usize = 32;
/// Contacts kept per sample; further contacts are counted but not kept.
pub const MAX_LOG_CONTACTS: usize = 32;

/// One body's state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodySample {
    /// Pose `(x, y, θ)` (m, m, rad).
    pub pose: [f64; 3],
    /// Twist `(vx, vy, ω)` (m/s, m/s, rad/s).
    pub twist: [f64; 3],
}

/// One contact record's state (§8).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactSample {
    /// Body owning the vertex.
    pub body_a: u32,
    /// Body owning the edge.
    pub body_b: u32,
    /// True while colliding (resolved by an impulse this sample), false for continuous contact.
    pub colliding: bool,
    /// World position of the vertex (m).
    pub point: [f64; 2],
    /// Outward edge normal (world, unit).
    pub normal: [f64; 2],
    /// Penetration `−d_k` (m; positive inside).
    pub penetration: f64,
    /// Normal force (N).
    pub f_n: f64,
    /// Friction force on A along the edge tangent (N).
    pub f_t: f64,
    /// Tangential slip velocity (m/s).
    pub slip: f64,
}

/// The world's state after a step: bodies (first [`MAX_LOG_BODIES`]), contact records (first
/// [`MAX_LOG_CONTACTS`]) and the energy ledger.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldSample {
    /// World time (s).
    pub t: f64,
    /// Bodies in the world (may exceed [`MAX_LOG_BODIES`]).
    pub body_count: u32,
    /// Contact records in the world (may exceed [`MAX_LOG_CONTACTS`]).
    pub contact_count: u32,
    /// The first `min(body_count, MAX_LOG_BODIES)` bodies, in world order.
    pub bodies: [BodySample; MAX_LOG_BODIES],
    /// The first `min(contact_count, MAX_LOG_CONTACTS)` contact records, in the world's order.
    pub contacts: [ContactSample; MAX_LOG_CONTACTS],
    /// The energy ledger (J).
    pub ledger: EnergyLedger,
}

impl Default for WorldSample {
    fn default() -> Self {
        Self {
            t: 0.0,
            body_count: 0,
            contact_count: 0,
            bodies: [BodySample::default(); MAX_LOG_BODIES],
            contacts: [ContactSample::default(); MAX_LOG_CONTACTS],
            ledger: EnergyLedger::default(),
        }
    }
}

impl WorldSample {
    /// Fills `self` from `world` (allocation-free).
    pub fn capture(&mut self, world: &World) {
        self.t = world.time();
        self.body_count = world.bodies.len() as u32;
        for (slot, b) in self.bodies.iter_mut().zip(world.bodies.iter()) {
            *slot = BodySample {
                pose: [b.pose.pos.x, b.pose.pos.y, b.pose.angle],
                twist: [b.vel.x, b.vel.y, b.omega],
            };
        }
        let mut n = 0usize;
        for c in world.contact_records() {
            let Some(state) = c.state else { continue };
            if n < MAX_LOG_CONTACTS {
                self.contacts[n] = ContactSample {
                    body_a: c.body_a as u32,
                    body_b: c.body_b as u32,
                    colliding: state == ContactState::Colliding,
                    point: [c.point.x, c.point.y],
                    normal: [c.n.x, c.n.y],
                    penetration: -c.d[0],
                    f_n: c.f_n,
                    f_t: c.f_t,
                    slip: c.s0,
                };
            }
            n += 1;
        }
        self.contact_count = n as u32;
        self.ledger = *world.ledger();
    }

    /// The bodies kept.
    pub fn bodies(&self) -> &[BodySample] {
        &self.bodies[..(self.body_count as usize).min(MAX_LOG_BODIES)]
    }

    /// The contacts kept.
    pub fn contacts(&self) -> &[ContactSample] {
        &self.contacts[..(self.contact_count as usize).min(MAX_LOG_CONTACTS)]
    }
}

/// One logged haptic tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoggedTick {
    /// Tick index among executed ticks.
    pub index: u64,
    /// The tick's deadline, `CLOCK_MONOTONIC` ns.
    pub deadline_ns: u64,
    /// How late the tick started (ns).
    pub lateness_ns: u64,
    /// Joint angles read this tick `[q11, q12, q21, q22]` (rad; NaN when the read failed).
    pub q: [f64; 4],
    /// The tick's record (with the torques actually sent).
    pub rec: TickRecord,
    /// The world after the tick; `body_count = 0` when not captured.
    pub world: WorldSample,
}

impl LoggedTick {
    /// Fills `self` for the tick `info` (allocation-free): the loop fields, `q`, `rec`, and — when
    /// `world` is given — the world sample.
    #[inline]
    pub fn capture(
        &mut self,
        info: &TickInfo,
        q: &[f64; 4],
        rec: &TickRecord,
        world: Option<&World>,
    ) {
        self.index = info.index;
        self.deadline_ns = info.deadline_ns;
        self.lateness_ns = info.lateness_ns;
        self.q = *q;
        self.rec = *rec;
        match world {
            Some(w) => self.world.capture(w),
            None => {
                self.world.body_count = 0;
                self.world.contact_count = 0;
            }
        }
    }
}

/// The CSV tick log of `haptic2d run --log FILE.csv`: the [`TickRecord`] columns, then the
/// encoder angles `encoders.q1..q4` (rad) read that tick ([`run_csv_header`]), so that
/// `--device replay:FILE.csv` plays a run's CSV log back (issue 39) and `log convert` maps every
/// column to the tick table.
impl CsvRecord for LoggedTick {
    fn header() -> Vec<String> {
        run_csv_header()
    }

    fn write_row<W: std::io::Write>(&self, out: &mut csv::Writer<W>) -> csv::Result<()> {
        self.rec.write_row(out)?;
        for v in self.q {
            out.write_field(v.to_string())?;
        }
        Ok(())
    }
}
