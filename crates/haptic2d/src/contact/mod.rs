//! Contact records, the contact state machine, god-objects and simultaneous impacts (§7, §8).

mod compact_law;
mod god_object;
pub mod impact;
pub mod impact_friction;
pub mod impact_mlcp;
mod impact_sweep;
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
mod work_budget;

pub use god_object::entry_point;
pub use impact_friction::{default_impact_mu, ImpactFriction};
pub use manager::{ContactSet, PastPoses, Wrench2};
pub use params::{ContactParams, DEFAULT_IMPACT_SWEEPS, IMPACT_ROW_UPDATES_PER_S};
pub use record::{
    ContactEvent, ContactState, EventKind, LawState, Loaded, LoadedContact, VeContact, NO_LAW,
};
pub use work_budget::WorkBudget;
