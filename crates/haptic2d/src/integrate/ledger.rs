//! The energy ledger of a world: kinetic energy, energy stored in contact and friction springs, and the
//! work done by applied loads (§6.5, DESIGN §3 CSV columns).

/// Energy bookkeeping, updated once per sample by the world.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyLedger {
    /// Kinetic energy of all dynamic bodies at the current state (J).
    pub kinetic: f64,
    /// Energy stored in contact (normal-law) and friction springs (J).
    pub stored: f64,
    /// Cumulative work of the applied loads and drives, `Σ F_k·Δx_k + τ_k·Δθ_k` (J).
    pub applied_work: f64,
    /// Kinetic + stored energy at the start of the run (J).
    pub initial: f64,
    /// Kinetic energy removed by impacts so far (J, ≥ 0).
    pub impact_loss: f64,
    /// Frictional impact sets (issue 16) whose energy check had to scale an impulse so that the
    /// impact did not add kinetic energy (restitution scaled, or the whole jump); 0 without friction.
    pub impact_energy_fallbacks: u64,
    /// Kinetic energy removed by the implicit chain damper so far (J, ≥ 0 up to rounding;
    /// `contact/solver/chain/`).
    pub chain_damping_loss: f64,
}

impl EnergyLedger {
    /// Kinetic + stored energy now (J).
    #[inline]
    pub fn total(&self) -> f64 {
        self.kinetic + self.stored
    }
    /// `E_now − (E_0 + W_applied)` (J): positive means the simulation generated energy.
    #[inline]
    pub fn excess(&self) -> f64 {
        self.total() - (self.initial + self.applied_work)
    }
}
