//! Passive numerical integration (§6): per-DOF integrators, minimum mass, the energy ledger.
