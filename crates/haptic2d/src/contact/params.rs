//! Parameters of the contact state machine (§8.2) and of impacts (§7).

use super::WorkBudget;

/// Thresholds and options of the contact pipeline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactParams {
    /// Collision velocity threshold `v_c` (m/s): a new contact approaching faster is Colliding.
    pub v_c: f64,
    /// Edge-range tolerance `ε_s` (m).
    pub eps_s: f64,
    /// Creation threshold `δ_on` (m): a record is created at `d ≤ δ_on`.
    pub delta_on: f64,
    /// Release threshold `δ_off` (m): a record is deleted at `d > δ_off`.
    pub delta_off: f64,
    /// Whether collisions are resolved by impulses (§7). When false every contact starts Continuous
    /// (the pure wall laws of Fig. 4).
    pub impacts: bool,
    /// Poisson restitution coefficient `e` for Colliding contacts.
    pub restitution: f64,
    /// Re-collision inside contact (§8.2 rule 5): promote a Continuous record approaching faster than this
    /// (m/s) back to Colliding. `None` = off (default).
    pub v_re: Option<f64>,
    /// Plastic-correction threshold `ε_v` (m/s) of the impact solver.
    pub eps_v: f64,
    /// Friction during impacts (issue 16): none (default, §7) or Coulomb.
    pub impact_friction: super::ImpactFriction,
    /// Impact friction coefficient `μ` (dimensionless); `None` = the contact friction model's `μ_k`.
    pub impact_mu: Option<f64>,
    /// Whether the restitution law alone sets the rebound (issue 35; default `true`,
    /// docs/MODELS.md §7.6): a resolved impact's record starts its normal law at the depth found
    /// at detection (the law's surface moves in to the depth gained in the detection sample and
    /// its SEH history restarts, [`ContactNormal`](crate::laws::normal::ContactNormal)), so no
    /// spring pays that depth back, and the struck contacts carry the impact sample's other forces
    /// (loads, drive), so the sample ends at `−e` times the arrival velocity. `false` is the
    /// paper's §7.2 step 4 (the §5.9 law acts on the whole remaining penetration from the impact
    /// sample on; the Fig. 4 2-D reproduction uses it, as its 1-D harness does).
    pub impact_surface_offset: bool,
    /// Work budget of an impact sample (docs/MODELS.md §7.7): the sweeps each projected
    /// Gauss–Seidel phase (compression, plastic correction) of a large island (more than
    /// `DENSE_MAX_ROWS` = 24 rows: the sparse path) may run, 1 to 200. A phase that runs out
    /// stops where it is (it has only removed kinetic energy) and the island's restitution is
    /// scaled so that the impact cannot create energy. Default [`DEFAULT_IMPACT_SWEEPS`]; 200 is
    /// the limit of §7.3 (before issue 42's budget).
    pub impact_sweeps: u32,
    /// Row updates the sparse path's projected Gauss–Seidel may run in one sample, over all its
    /// islands and phases (docs/MODELS.md §7.7, issue 42): by default unbounded (a budget cut
    /// short the impacts of pile:5000's collapse and made it bounce, §7.7); `FromPeriod` derives
    /// it from the sample period at [`IMPACT_ROW_UPDATES_PER_S`]
    /// ([`ContactParams::impact_row_budget`]). A phase whose island does not fit what is left runs
    /// `⌊left / rows⌋` sweeps, at least one.
    pub impact_budget: WorkBudget,
}

/// Row updates of the sparse impact solve per second of the sample period when its budget is
/// [`WorkBudget::FromPeriod`] (§7.7), 12 000 per millisecond: at 1 kHz an impact sample's sweeps
/// may cost about 1.1 M instructions (about 90 a row update, callgrind), a quarter of a settled
/// pile:1000 step's 4.5–5 M (docs/PERFORMANCE.md, session 30: it cut the landing's worst 1 % of
/// steps from 19.6 M to 16.1 M instructions). Scales with the period: a real-time loop at 500 Hz
/// has twice the time for a sample.
pub const IMPACT_ROW_UPDATES_PER_S: f64 = 12.0e6;

/// Default sweep budget of a large island's impact phases (§7.7): the two phases together get
/// the chain damper's default of 16 sweeps, so an impact sample's solve costs about `2 × 8` row
/// updates per contact record of the island (at most `3 × 8` where the energy check fires).
/// Measured on a landing pile:1000 (docs/PERFORMANCE.md): worst 1 % of landing steps 6.0× the
/// settled median at 8, 7.1× at 16, 9.4–10.2× at 32, 30–34× at 200; 4 gains nothing over 8.
pub const DEFAULT_IMPACT_SWEEPS: u32 = 8;

impl Default for ContactParams {
    fn default() -> Self {
        Self {
            v_c: 0.02,
            eps_s: 1e-4,
            delta_on: 0.0,
            delta_off: 0.0,
            impacts: true,
            restitution: 0.5,
            v_re: None,
            eps_v: 1e-6,
            impact_friction: super::ImpactFriction::None,
            impact_mu: None,
            impact_surface_offset: true,
            impact_sweeps: DEFAULT_IMPACT_SWEEPS,
            impact_budget: WorkBudget::Unbounded,
        }
    }
}

impl ContactParams {
    /// The sparse impact solve's row updates for a sample of period `dt` (s), `u64::MAX` when
    /// unbounded (§7.7): [`impact_budget`](Self::impact_budget) at this period.
    pub fn impact_row_budget(&self, dt: f64) -> u64 {
        (self.impact_budget)
            .row_updates(dt, IMPACT_ROW_UPDATES_PER_S)
            .unwrap_or(u64::MAX)
    }
}
