//! The rates, margins and options of a world ([`WorldParams`]).

use crate::contact::solver::{DEFAULT_CHAIN_SWEEPS, DEFAULT_CHAIN_TAU};
use crate::contact::{ContactParams, WorkBudget};
use crate::integrate::IntegrationMode;

/// Rates, margins and options of a world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldParams {
    /// Sample period `T` (s).
    pub dt: f64,
    /// Run the global proximity stage every `N_g` samples.
    pub proximity_every: u32,
    /// Spread the global proximity stage over the `N_g` samples of its period (default) instead
    /// of running it whole every `N_g`-th sample: every sample then costs about the same (no
    /// deadline spike), and the set in use describes the poses one period earlier, which the
    /// §9.1 margin allows (`collide/broad/`). Early updates for fast bodies still run whole.
    pub proximity_spread: bool,
    /// Skip a periodic global update when the colliders cannot have changed the proximity set
    /// since the published one (default): the vertices have moved less than half the smallest
    /// slack of that update's decisions ([`BroadPhase::still_exact`](crate::collide::BroadPhase::still_exact)).
    /// The set in use is then exactly what the update would compute, so trajectories are those
    /// of running it, up to the round-off of GJK's warm starts.
    pub proximity_skip: bool,
    /// Proximity margin `δ_prox` (m), §9.1.
    pub delta_prox: f64,
    /// Contact distance tolerance `δ_c` (m), §9.5.
    pub delta_c: f64,
    /// Integration mode (§6; exact-ZOH for harness scenes).
    pub mode: IntegrationMode,
    /// Passivity guard tolerance `ε_E` (J); `None` = guard off (default).
    pub guard: Option<f64>,
    /// Contact state machine and impact options.
    pub contact: ContactParams,
    /// Damping time `τ` (s) of the implicit chain damper (`contact/solver/chain/`): contacts
    /// of bodies that touch two or more others get an extra normal damper `m_c/τ` on the
    /// end-of-sample velocity, so stacks come to rest. `None` = off. Default 0.2 ms.
    pub chain_tau: Option<f64>,
    /// Gauss–Seidel sweeps of the chain damper per sample, at most (they stop once no row's
    /// velocity changes by more than 2e-4 m/s; warm-started, a settled pile needs 1–4); default 16.
    pub chain_sweeps: u32,
    /// Work budget of the chain damper per sample, in row updates (whole sweeps, the first always
    /// runs; MODELS §6.7): by default derived from the sample period `dt`
    /// ([`WorkBudget::FromPeriod`]).
    pub chain_budget: WorkBudget,
}

/// Share of the sample period the chain damper's sweeps may take by default (dimensionless):
/// with [`CHAIN_ROW_UPDATE_NS`] it sets [`CHAIN_ROW_UPDATES_PER_S`].
pub const CHAIN_BUDGET_SHARE: f64 = 0.2;

/// Cost of one row update of the chain damper's sweeps (ns), measured on the development machine
/// under load (docs/MODELS.md §6.7: the slope of the damper stage's wall time against its row
/// updates, 5.8–13.8 ns in five measurements, median 6.9 ns, rounded).
pub const CHAIN_ROW_UPDATE_NS: f64 = 7.0;

/// Row updates per second of sample period the default budget allows (1/s):
/// `CHAIN_BUDGET_SHARE / (CHAIN_ROW_UPDATE_NS · 1e-9)`.
pub const CHAIN_ROW_UPDATES_PER_S: f64 = CHAIN_BUDGET_SHARE / (CHAIN_ROW_UPDATE_NS * 1e-9);

impl WorldParams {
    /// The chain damper's row updates per sample (`None` = unbounded): [`chain_budget`](Self::chain_budget)
    /// at this period, [`CHAIN_ROW_UPDATES_PER_S`] by default.
    pub fn chain_row_updates(&self) -> Option<u64> {
        self.chain_budget
            .row_updates(self.dt, CHAIN_ROW_UPDATES_PER_S)
    }
}

impl Default for WorldParams {
    fn default() -> Self {
        Self {
            dt: 0.002,
            proximity_every: 10,
            proximity_spread: true,
            proximity_skip: true,
            delta_prox: 0.042,
            delta_c: 0.002,
            mode: IntegrationMode::SemiImplicit,
            guard: None,
            contact: ContactParams::default(),
            chain_tau: Some(DEFAULT_CHAIN_TAU),
            chain_sweeps: DEFAULT_CHAIN_SWEEPS,
            chain_budget: WorkBudget::FromPeriod,
        }
    }
}
