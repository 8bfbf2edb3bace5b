//! Passive numerical integration (§6): per-DOF integrators, minimum mass, the energy ledger and the
//! optional passivity guard.

mod guard;
mod ledger;
mod step;

pub use guard::PassivityGuard;
pub use ledger::EnergyLedger;
pub use step::{integrate_body, min_mass, IntegrationMode};
