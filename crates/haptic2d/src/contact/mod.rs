//! Contact records, the contact state machine, god-objects and simultaneous impacts (§7, §8).

mod compact_law;
mod god_object;
pub mod impact;
pub mod impact_friction;
pub mod impact_mlcp;
mod last_solve;
mod law_pool;
pub mod lcp;
mod lean_law;
mod manager;
mod params;
mod record;
pub mod solver;
#[cfg(test)]
mod test_pile;

pub use god_object::entry_point;
pub use impact_friction::{default_impact_mu, ImpactFriction};
pub use manager::{ContactSet, PastPoses, Wrench2};
pub use params::{ContactParams, DEFAULT_IMPACT_ROWS_PER_MS, DEFAULT_IMPACT_SWEEPS};
pub use record::{
    ContactEvent, ContactState, EventKind, LawState, Loaded, LoadedContact, VeContact, NO_LAW,
};
