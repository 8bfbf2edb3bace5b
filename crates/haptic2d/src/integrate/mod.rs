//! Passive numerical integration (§6): per-DOF integrators, minimum mass, the energy ledger and the
//! optional passivity guard.

mod chain_damping;
mod guard;
mod ledger;
mod step;

pub use chain_damping::{ChainDamping, DEFAULT_CHAIN_SWEEPS, DEFAULT_CHAIN_TAU};
pub use guard::PassivityGuard;
pub use ledger::EnergyLedger;
pub use step::{integrate_body, min_mass, IntegrationMode};
