//! The work budget of an iterative solve per sample, in row updates (issue 42 item 2): the chain
//! damper's sweeps (`WorldParams::chain_budget`, MODELS §6.7) and the large impact islands'
//! projected Gauss–Seidel (`ContactParams::impact_budget`, MODELS §7.7) each stop where a sample's
//! budget runs out. Both solves lower a convex function at every row update, so a cut sample is
//! passive; counting row updates, not time, keeps the result independent of the machine.

/// A per-sample budget of row updates (one row update: one projected Gauss–Seidel update of one
/// row). `FromPeriod` derives it from the sample period, at a rate each solve sets, so a
/// real-time loop at a longer period gets proportionally more work per sample. Each solve's
/// parameter has its own default (the chain damper's `FromPeriod`, the impact islands'
/// `Unbounded`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WorkBudget {
    /// `round(dt × rate)` row updates, `dt` the sample period (s) and `rate` the solve's row
    /// updates per second of period (the type's `Default`).
    #[default]
    FromPeriod,
    /// At most this many row updates per sample (each solve says what it always runs).
    RowUpdates(u64),
    /// No budget: only the solve's own sweep limit and convergence test stop it.
    Unbounded,
}

impl WorkBudget {
    /// The budget a setting `n` names (`[world] chain_budget = n`, `[contact] impact_budget = n`,
    /// the bench's `--set`): 0 = [`Unbounded`](Self::Unbounded), else `n` row updates.
    pub fn from_setting(n: u64) -> Self {
        if n == 0 {
            Self::Unbounded
        } else {
            Self::RowUpdates(n)
        }
    }

    /// Row updates allowed per sample at sample period `dt` (s) for a solve whose default rate is
    /// `per_s` row updates per second of period; `None` = unbounded. A period that is NaN or not
    /// positive gives 0 (the solve's minimum a sample).
    pub fn row_updates(self, dt: f64, per_s: f64) -> Option<u64> {
        match self {
            Self::FromPeriod => Some((dt * per_s).round().max(0.0) as u64),
            Self::RowUpdates(n) => Some(n),
            Self::Unbounded => None,
        }
    }
}
