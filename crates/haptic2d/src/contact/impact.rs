//! Simultaneous impacts with Poisson restitution (§7): Delassus assembly, compression LCP, restitution, plastic correction.
//!
//! The caller (the contact manager, §8.2) builds the impact set `𝒞`: every Colliding contact with
//! restitution `e`, plus every Continuous contact touching a body of a colliding one with restitution 0.
//! [`ImpactSolver::solve`] then runs §7.2 and applies the velocity jumps to the bodies. Friction is
//! ignored during the impulse (§7, \[REC\]) unless [`ImpactSolver::set_friction`] selects
//! [`ImpactFriction::Coulomb`]: then every set goes to the frictional solver of issue 16
//! ([`super::impact_friction`]).

use super::impact_friction::{FrictionalImpactSolver, ImpactFriction, PhaseMethod};
use super::impact_sweep::SparseIsland;
use super::last_solve::last_solve_views;
use super::lcp::{LcpReport, LcpSolver};
use crate::body::Body;
use crate::geom::{cross, Vec2};

/// Default constraint-check tolerance `ε_v` (m/s): after restitution, a row with `b⁺_i < −ε_v`
/// triggers the plastic correction (§7.2 step 3).
///
/// **Deviation:** §7.2 gives `ε_v = 1e-6 m/s`, but I4 (§7.5) requires `b⁺_i ≥ −1e-9` after the
/// algorithm. Restitution legitimately leaves approach velocities in `(−1e-6, −1e-9)` on rows with
/// `λ_i = 0` (`b⁺_i = w_i + e·(A·λ)_i` with `(A·λ)_i < 0`), which a 1e-6 trigger would keep. The
/// default is therefore 1e-9, the enumeration's `w` tolerance; [`ImpactSolver::set_eps_v`] restores
/// the spec's value if wanted.
pub const EPS_V: f64 = 1e-9;
/// Maximum number of plastic-correction passes. One pass suffices whenever its LCP is solved to
/// tolerance; further passes only mop up after an LCP on an ill-conditioned Delassus matrix.
pub const MAX_CORRECTION_PASSES: usize = 3;

/// One row of the impact set `𝒞` (§7.1): a vertex–edge contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpactRow {
    /// Index (into the `bodies` slice) of body A, the body that owns the vertex.
    pub body_a: usize,
    /// Index (into the `bodies` slice) of body B, the body that owns the edge.
    pub body_b: usize,
    /// Unit edge normal `n` (dimensionless), pointing out of B toward A (§0.4).
    pub n: Vec2,
    /// Lever arm `r_A = V − c_A` (m) from A's centre of mass to the vertex.
    pub r_a: Vec2,
    /// Lever arm `r_B = V − c_B` (m) from B's centre of mass to the vertex.
    pub r_b: Vec2,
    /// Restitution `e_i` (dimensionless, in `[0, 1]`): `e` for Colliding rows, 0 for Continuous rows.
    pub restitution: f64,
}

impl ImpactRow {
    /// The row of a contact at world point `p` (m) between `bodies[body_a]` (the vertex's) and
    /// `bodies[body_b]` (the edge's), with unit normal `n` out of B and restitution `restitution`:
    /// the lever arms are `p` less each body's position (m).
    pub fn at_point(
        bodies: &[Body],
        body_a: usize,
        body_b: usize,
        n: Vec2,
        p: Vec2,
        restitution: f64,
    ) -> Self {
        ImpactRow {
            body_a,
            body_b,
            n,
            r_a: p - bodies[body_a].pose.pos,
            r_b: p - bodies[body_b].pose.pos,
            restitution,
        }
    }

    /// The Jacobian row `G_i` as two blocks `(n, r_A × n)` for A and `(−n, −(r_B × n))` for B (§7.1).
    /// A fixed body's block is zero.
    pub(super) fn jacobian(&self, bodies: &[Body]) -> [f64; 6] {
        self.jacobian_of(
            bodies[self.body_a].is_dynamic(),
            bodies[self.body_b].is_dynamic(),
        )
    }

    /// [`jacobian`](Self::jacobian) for A dynamic or not (`dynamic_a`), and B (`dynamic_b`).
    #[inline]
    pub(super) fn jacobian_of(&self, dynamic_a: bool, dynamic_b: bool) -> [f64; 6] {
        let mut j = [0.0; 6];
        if dynamic_a {
            j[0] = self.n.x;
            j[1] = self.n.y;
            j[2] = cross(self.r_a, self.n);
        }
        if dynamic_b {
            j[3] = -self.n.x;
            j[4] = -self.n.y;
            j[5] = -cross(self.r_b, self.n);
        }
        j
    }

    /// Normal relative velocity `C0 = G_i·u = n·(v_A + ω_A·perp(r_A) − v_B − ω_B·perp(r_B))` (m/s),
    /// positive when separating, from the bodies' current twists. Fixed bodies count as at rest.
    ///
    /// # Panics
    /// If `body_a` or `body_b` is not an index into `bodies`.
    pub fn normal_velocity(&self, bodies: &[Body]) -> f64 {
        let j = self.jacobian(bodies);
        dot_twist(&j[0..3], &bodies[self.body_a]) + dot_twist(&j[3..6], &bodies[self.body_b])
    }
}

/// `J·(v_x, v_y, ω)` for one 3-entry Jacobian block.
#[inline]
fn dot_twist(j: &[f64], b: &Body) -> f64 {
    j[0] * b.vel.x + j[1] * b.vel.y + j[2] * b.omega
}

/// Summary of one [`ImpactSolver::solve`] call. Per-row data (impulses, velocities, the Delassus
/// matrix) are read from the solver's accessors until the next call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpactOutcome {
    /// Number of rows `n` in the impact set.
    pub rows: usize,
    /// Total kinetic energy of all bodies in the slice before the impact (J).
    pub kinetic_energy_before: f64,
    /// Total kinetic energy of all bodies in the slice after the impact (J).
    pub kinetic_energy_after: f64,
    /// True if the constraint check found `b⁺_i < −ε_v` and the plastic correction LCP ran (§7.2 step 3).
    pub plastic_correction: bool,
    /// Diagnostics of the compression LCP (§7.2 step 1).
    pub compression: LcpReport,
    /// Number of plastic-correction passes run (0 when `b⁺ ≥ −ε_v` after restitution; more than 1
    /// only when an LCP was not solved to tolerance).
    pub correction_passes: usize,
    /// Diagnostics of the last plastic-correction LCP, if it ran.
    pub correction: Option<LcpReport>,
    /// Smallest post-impact normal velocity `min_i b⁺_i` (m/s); `+∞` for an empty set.
    pub min_post_velocity: f64,
    /// True if a frictional solve's energy check scaled an impulse (issue 16); always false without
    /// friction.
    pub energy_fallback: bool,
}

/// Solver for simultaneous frictionless impacts with Poisson restitution (§7.2).
///
/// Owns all scratch (the Delassus matrix, velocities, impulses and the LCP solver); buffers grow only
/// when a larger impact set than any before arrives, so steady-state calls do not allocate.
#[derive(Clone, Debug)]
pub struct ImpactSolver {
    lcp: LcpSolver,
    cap: usize,
    n: usize,
    /// Jacobian rows, two 3-blocks each (A then B).
    jac: Vec<[f64; 6]>,
    /// Delassus matrix `A = G M⁻¹ Gᵀ`, row-major `n × n` (dense path only).
    a: Vec<f64>,
    /// The sparse path's gathered island (`contact/impact_sweep.rs`): its rows with the inverse
    /// `1/A_ii` of the diagonal (the sweeps multiply by it instead of dividing, so that a row's
    /// update does not wait on a division, about 13 cycles against 3 on this machine, at every
    /// sweep) and its bodies' twists.
    island: SparseIsland,
    /// Pre-impact normal velocities `b⁻` (m/s).
    b_pre: Vec<f64>,
    /// Post-restitution normal velocities, before any plastic correction (m/s).
    b_mid: Vec<f64>,
    /// Final post-impact normal velocities `b⁺` (m/s).
    b_post: Vec<f64>,
    /// Compression impulses `λ` (N·s).
    lambda: Vec<f64>,
    /// Plastic-correction impulses `λ'` (N·s); zero when the correction did not run.
    correction: Vec<f64>,
    /// Total impulses `P + λ'` (N·s).
    impulse: Vec<f64>,
    /// Impulses of one plastic-correction pass (N·s).
    step: Vec<f64>,
    /// Constraint-check tolerance `ε_v` (m/s).
    eps_v: f64,
    /// Impact friction mode (issue 16; default none).
    friction: ImpactFriction,
    /// Impact friction coefficient `μ` (dimensionless).
    mu: f64,
    /// The frictional solver, used when `friction` is Coulomb and `μ > 0`.
    fric: FrictionalImpactSolver,
    /// Sweep budget of each projected Gauss–Seidel phase of the sparse path (§7.7; default
    /// [`PGS_MAX_SWEEPS`], the world sets its own from `ContactParams::impact_sweeps`).
    sweep_budget: usize,
    /// Row updates the sparse path may still run in this sample (§7.7; `u64::MAX` = unbounded,
    /// the default; the world sets it every sample from `ContactParams::impact_row_budget`).
    rows_left: u64,
    /// Work counters of the sparse path (§7.7), since the solver was made.
    budget: BudgetCounters,
}

/// What the sparse path's work budget did (§7.7), counted since the solver was made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BudgetCounters {
    /// Row updates of the sparse projected Gauss–Seidel (both phases): its work.
    pub row_updates: u64,
    /// Sparse islands solved.
    pub islands: u64,
    /// Sparse PGS phases (compression or correction) stopped by the sweep budget before their
    /// `1e-9 N·s` convergence test.
    pub phases_cut: u64,
    /// Sparse PGS phases that ran fewer sweeps than `impact_sweeps` because the sample's row
    /// budget did not hold that many over their island (§7.7).
    pub phases_capped: u64,
    /// Islands whose restitution impulses were scaled down (the passive fallback: the full
    /// Poisson restitution would have raised the kinetic energy, as it can after a compression
    /// the budget cut short, or by round-off after one stopped at its tolerance).
    pub restitution_scaled: u64,
}

impl Default for ImpactSolver {
    fn default() -> Self {
        Self::new()
    }
}

last_solve_views! { ImpactSolver, "rows";
    /// Pre-impact normal velocities `b⁻ = G u⁻` of the last solve (m/s).
    pre_velocities => b_pre,
    /// Normal velocities after restitution and before the plastic correction (m/s).
    restitution_velocities => b_mid,
    /// Final post-impact normal velocities `b⁺ = G u⁺` of the last solve (m/s).
    post_velocities => b_post,
    /// Compression impulses `λ_i` of the last solve (N·s).
    compression_impulses => lambda,
    /// Plastic-correction impulses `λ'_i` of the last solve (N·s); all zero if it did not run.
    correction_impulses => correction,
    /// Total impulse per row applied by the last solve, `(1 + e_i)·λ_i + λ'_i` (N·s), along `n_i` on
    /// the vertex body A (and opposite on B).
    impulses => impulse,
}

impl ImpactSolver {
    /// A solver preallocated for impact sets of up to 8 rows.
    pub fn new() -> Self {
        Self::with_capacity(8)
    }

    /// A solver preallocated for impact sets of up to `rows` rows.
    pub fn with_capacity(rows: usize) -> Self {
        let mut s = Self {
            lcp: LcpSolver::with_capacity(rows),
            cap: 0,
            n: 0,
            jac: Vec::new(),
            a: Vec::new(),
            island: SparseIsland::default(),
            b_pre: Vec::new(),
            b_mid: Vec::new(),
            b_post: Vec::new(),
            lambda: Vec::new(),
            correction: Vec::new(),
            impulse: Vec::new(),
            step: Vec::new(),
            eps_v: EPS_V,
            friction: ImpactFriction::None,
            mu: 0.0,
            // Grown on first use only: the frictionless default keeps §7's memory (impact_memory.rs).
            fric: FrictionalImpactSolver::default(),
            sweep_budget: PGS_MAX_SWEEPS,
            rows_left: u64::MAX,
            budget: BudgetCounters::default(),
        };
        s.reserve(rows);
        s
    }

    /// The constraint-check tolerance `ε_v` (m/s) in use.
    pub fn eps_v(&self) -> f64 {
        self.eps_v
    }

    /// Sets the constraint-check tolerance `ε_v` (m/s, finite and `≥ 0`; default [`EPS_V`]).
    pub fn set_eps_v(&mut self, eps_v: f64) -> Result<(), String> {
        if !(eps_v.is_finite() && eps_v >= 0.0) {
            return Err(format!("eps_v must be finite and >= 0 m/s, got {eps_v}"));
        }
        self.eps_v = eps_v;
        Ok(())
    }

    /// Selects the impact friction mode and its coefficient `mu` (dimensionless; a non-finite or
    /// negative value is treated as 0, i.e. frictionless). With [`ImpactFriction::None`] or `μ = 0`
    /// the frictionless algorithm of §7.2 runs unchanged.
    pub fn set_friction(&mut self, friction: ImpactFriction, mu: f64) {
        self.friction = friction;
        self.mu = if mu.is_finite() && mu > 0.0 { mu } else { 0.0 };
        if friction == ImpactFriction::Coulomb {
            // The frictional buffers for a typical set, before the first impact needs them.
            self.fric.reserve(8);
        }
    }

    /// Sweeps each projected Gauss–Seidel phase of the sparse path (`n > DENSE_MAX_ROWS`) may run
    /// at most (§7.7; at least 1, at most `PGS_MAX_SWEEPS`; default `PGS_MAX_SWEEPS`).
    pub fn set_sweep_budget(&mut self, sweeps: usize) {
        self.sweep_budget = sweeps.clamp(1, PGS_MAX_SWEEPS);
    }

    /// Starts a sample whose sparse solves may run `rows` row updates in all, over every island
    /// and phase (§7.7; `u64::MAX` = unbounded). Each phase still runs at least one sweep.
    pub fn set_sample_rows(&mut self, rows: u64) {
        self.rows_left = rows;
    }

    /// The sparse path's sweep budget in use (§7.7).
    pub fn sweep_budget(&self) -> usize {
        self.sweep_budget
    }

    /// What the sparse path's work budget did since the solver was made (§7.7).
    pub fn budget_counters(&self) -> BudgetCounters {
        self.budget
    }

    /// The frictional solver (its impulses of the last frictional solve, its fallback counters).
    pub fn frictional(&self) -> &FrictionalImpactSolver {
        &self.fric
    }

    /// Number of impact sets whose energy check scaled an impulse so far (issue 16: restitution
    /// scaled plus whole jump scaled); 0 without friction.
    pub fn energy_fallbacks(&self) -> u64 {
        let (r, j) = self.fric.fallbacks();
        r + j
    }

    /// Largest impact set solvable without allocating.
    pub fn capacity(&self) -> usize {
        self.cap
    }

    /// Grows the sparse path's per-body buffer to `bodies` bodies (no-op if it already does), so
    /// that the first large island on that many bodies allocates nothing.
    pub fn reserve_bodies(&mut self, bodies: usize) {
        self.island.reserve_bodies(bodies);
    }

    /// Grows the buffers to hold impact sets of `rows` rows (no-op if they already do).
    pub fn reserve(&mut self, rows: usize) {
        if rows <= self.cap {
            return;
        }
        self.jac.resize(rows, [0.0; 6]);
        let dense = rows.min(DENSE_MAX_ROWS);
        if self.a.len() < dense * dense {
            self.a.resize(dense * dense, 0.0);
        }
        self.island.reserve(rows);
        for v in [
            &mut self.b_pre,
            &mut self.b_mid,
            &mut self.b_post,
            &mut self.lambda,
            &mut self.correction,
            &mut self.impulse,
            &mut self.step,
        ] {
            v.resize(rows, 0.0);
        }
        // The dense LCP only ever sees sets of at most DENSE_MAX_ROWS rows: its scratch (and the
        // Delassus matrix above) stays at DENSE_MAX_ROWS² entries however large the set, so a pile
        // landing at once (or a 50 000-vertex polygon) costs O(rows) memory, never O(rows²).
        self.lcp.reserve(rows.min(DENSE_MAX_ROWS));
        self.cap = rows;
    }

    /// The Delassus matrix `A = G M⁻¹ Gᵀ` of the last solve, row-major `n × n` (1/kg: (m/s) per N·s);
    /// empty when the last set took the sparse path (`n > DENSE_MAX_ROWS`: no matrix is built).
    pub fn delassus(&self) -> &[f64] {
        if self.n > DENSE_MAX_ROWS {
            return &[];
        }
        &self.a[..self.n * self.n]
    }

    /// Resolves the impact set `rows` (in the given order) on `bodies` (§7.2) and applies the velocity
    /// jumps to the bodies' `vel` and `omega`:
    ///
    /// 1. compression LCP `λ ≥ 0, A·λ + b⁻ ≥ 0, λ ⟂ (A·λ + b⁻)`;
    /// 2. Poisson restitution `P_i = (1 + e_i)·λ_i`, `u⁺ = u⁻ + M⁻¹GᵀP`;
    /// 3. if some `b⁺_i < −ε_v`, a plastic-correction LCP with `b = b⁺`, applied as `M⁻¹Gᵀλ'`.
    ///
    /// Fixed bodies have `M⁻¹ = 0` and are treated as at rest; they are never modified.
    ///
    /// # Panics
    /// If a row's `body_a` or `body_b` is not an index into `bodies` (a bug in the caller).
    pub fn solve(&mut self, rows: &[ImpactRow], bodies: &mut [Body]) -> ImpactOutcome {
        self.solve_with(rows, bodies, Totals::Summed)
    }

    /// [`solve`](Self::solve) for one island of a world's impact set (`contact/manager`): the same
    /// velocity jumps, bit for bit, without the outcome's kinetic-energy totals. Those are sums
    /// over every body of the slice, so a world that solved its islands through `solve` paid two
    /// passes over all its bodies per island: O(islands × bodies) a sample, about a tenth of the
    /// contact events stage of a landing pile:5000 (docs/PERFORMANCE.md, session 21).
    pub(crate) fn solve_island(&mut self, rows: &[ImpactRow], bodies: &mut [Body]) {
        self.solve_with(rows, bodies, Totals::Skipped);
    }

    fn solve_with(
        &mut self,
        rows: &[ImpactRow],
        bodies: &mut [Body],
        totals: Totals,
    ) -> ImpactOutcome {
        let n = rows.len();
        self.reserve(n);
        self.n = n;
        if self.friction == ImpactFriction::Coulomb && self.mu > 0.0 && n > 0 {
            return self.solve_frictional(rows, bodies, totals);
        }
        if n > DENSE_MAX_ROWS {
            return self.solve_sparse(rows, bodies, totals);
        }
        let ke_before = totals.kinetic(bodies);

        // Jacobian rows and pre-impact velocities b⁻ = G u⁻.
        for (i, row) in rows.iter().enumerate() {
            self.jac[i] = row.jacobian(bodies);
        }
        self.normal_velocities(rows, bodies, Buf::Pre);

        // Delassus matrix A_ij = Σ over shared bodies of J_ib · M_b⁻¹ · J_jbᵀ.
        for i in 0..n {
            for j in 0..n {
                let mut s = 0.0;
                for (pi, bi) in [(0usize, rows[i].body_a), (3, rows[i].body_b)] {
                    let body = &bodies[bi];
                    if !body.is_dynamic() {
                        continue;
                    }
                    for (pj, bj) in [(0usize, rows[j].body_a), (3, rows[j].body_b)] {
                        if bi != bj {
                            continue;
                        }
                        let (ji, jj) = (&self.jac[i], &self.jac[j]);
                        s += body.inv_mass * (ji[pi] * jj[pj] + ji[pi + 1] * jj[pj + 1])
                            + body.inv_inertia * ji[pi + 2] * jj[pj + 2];
                    }
                }
                self.a[i * n + j] = s;
            }
        }

        // 1. Compression LCP. The sizes are consistent by construction, so the error branch is
        // unreachable; it degrades to "no impulse" rather than panicking.
        let compression = match self.lcp.solve(&self.a[..n * n], &self.b_pre[..n]) {
            Ok(r) => {
                self.lambda[..n].copy_from_slice(self.lcp.lambda());
                r
            }
            Err(_) => {
                self.lambda[..n].fill(0.0);
                empty_report(n)
            }
        };

        // 2. Poisson restitution P_i = (1 + e_i)·λ_i, applied as Δu = M⁻¹GᵀP.
        for (i, row) in rows.iter().enumerate() {
            self.impulse[i] = (1.0 + row.restitution) * self.lambda[i];
            self.correction[i] = 0.0;
        }
        self.apply_impulses(rows, bodies, Buf::Impulse);
        self.normal_velocities(rows, bodies, Buf::Mid);

        // 3. Constraint check and plastic correction. A second (third) pass runs only if the LCP of
        // the previous pass was not solved to tolerance (ill-conditioned A); see MAX_CORRECTION_PASSES.
        self.b_post[..n].copy_from_slice(&self.b_mid[..n]);
        let mut correction = None;
        let mut passes = 0;
        while passes < MAX_CORRECTION_PASSES && self.b_post[..n].iter().any(|&v| v < -self.eps_v) {
            passes += 1;
            match self.lcp.solve(&self.a[..n * n], &self.b_post[..n]) {
                Ok(r) => {
                    self.step[..n].copy_from_slice(self.lcp.lambda());
                    correction = Some(r);
                }
                Err(_) => break,
            }
            self.apply_impulses(rows, bodies, Buf::Step);
            for i in 0..n {
                self.correction[i] += self.step[i];
                self.impulse[i] += self.step[i];
            }
            self.normal_velocities(rows, bodies, Buf::Post);
        }

        self.outcome(bodies, totals, ke_before, passes, compression, correction)
    }

    /// The sparse path for large impact sets (`n > DENSE_MAX_ROWS`, e.g. a pile landing): the same
    /// projected Gauss–Seidel iteration as the dense solver, `λ_i ← max(0, λ_i − (A_i·λ + b_i)/A_ii)`,
    /// but with `A_i·λ + b_i = G_i·u` read from the bodies' current twists, to which every impulse
    /// increment is applied at once ("sequential impulses"). Each row update then costs O(1) instead
    /// of O(n), and no `n × n` matrix is built. Iterates are identical to dense PGS.
    ///
    /// The island's rows and bodies are gathered once into compact arrays
    /// (`contact/impact_sweep.rs`), every phase runs on them, and the twists are written back to
    /// `bodies` before the outcome reads them: the same bits as running on the bodies.
    fn solve_sparse(
        &mut self,
        rows: &[ImpactRow],
        bodies: &mut [Body],
        totals: Totals,
    ) -> ImpactOutcome {
        let n = rows.len();
        let ke_before = totals.kinetic(bodies);
        self.island.gather(rows, bodies);
        self.island.normal_velocities(&mut self.b_pre[..n]);
        self.budget.islands += 1;
        // 1. Compression: PGS on the bodies' twists, starting from λ = 0. Every row update is
        // the exact minimiser of the kinetic energy along its row under `λ_i ≥ 0`, so the
        // kinetic energy falls at every update, wherever the budget stops it (§7.7).
        self.lambda[..n].fill(0.0);
        let compression = self.pgs_on_island(Buf::Impulse);
        // 2. Poisson restitution: the bodies already carry λ; add p_i = e_i·λ_i. The energy
        // terms of the passive check (§7.7) are read on the way: with `b_c = G·u_c` after the
        // compression (held in `b_post` for now) and `b_1` after the restitution, the
        // compression changed the kinetic energy by `½·λᵀ(b⁻ + b_c)` (≤ 0) and the restitution
        // by `c + q`, `c = pᵀ·b_c`, `q = ½·pᵀ·A·p = ½·pᵀ(b_1 − b_c)`.
        for (i, row) in rows.iter().enumerate() {
            self.step[i] = row.restitution * self.lambda[i];
            self.impulse[i] = (1.0 + row.restitution) * self.lambda[i];
            self.correction[i] = 0.0;
        }
        self.island.normal_velocities(&mut self.b_post[..n]);
        let (mut dke_compression, mut c) = (0.0, 0.0);
        for i in 0..n {
            dke_compression += 0.5 * self.lambda[i] * (self.b_pre[i] + self.b_post[i]);
            c += self.step[i] * self.b_post[i];
        }
        self.island.apply_impulses(&self.step[..n]);
        self.island.normal_velocities(&mut self.b_mid[..n]);
        let mut q = 0.0;
        for i in 0..n {
            q += 0.5 * self.step[i] * (self.b_mid[i] - self.b_post[i]);
        }
        self.b_post[..n].copy_from_slice(&self.b_mid[..n]);
        // 3. Plastic correction: PGS again from the post-restitution twists, λ' from 0 (it only
        // removes kinetic energy, for the same reason as the compression).
        let (mut correction, mut passes) = self.sparse_correction();
        // 4. The passive check (§7.7): Poisson's restitution cannot raise the kinetic energy
        // only if `λ ⟂ G·u_c`, which a compression cut short by the budget breaks (and one
        // stopped by the 1e-9 N·s test leaves a residual of). If the whole impact raised it, the
        // correction and the part of the restitution above the largest passive scale `s` are
        // taken back and the correction runs again: the compression and the scaled restitution
        // then leave at most the energy before, and the correction only removes energy.
        let mut dke_correction = 0.0;
        for i in 0..n {
            dke_correction += 0.5 * self.correction[i] * (self.b_mid[i] + self.b_post[i]);
        }
        let dke_compression = dke_compression.min(0.0);
        let q = q.max(0.0);
        if dke_compression + c + q + dke_correction > 0.0 {
            // The root of q·s² + c·s + dke = 0 that is ≥ 0 (dke ≤ 0); with q = 0 the energy is
            // linear in s and c > 0 (else s = 1 would pass, the correction being ≤ 0).
            let s = if q > 0.0 {
                (-c + (c * c - 4.0 * q * dke_compression).max(0.0).sqrt()) / (2.0 * q)
            } else if c > 0.0 {
                -dke_compression / c
            } else {
                1.0
            };
            // A hair under the root, so round-off cannot put the energy above its bound.
            let s = (s * (1.0 - 1e-9)).clamp(0.0, 1.0);
            self.budget.restitution_scaled += 1;
            for (i, row) in rows.iter().enumerate() {
                self.step[i] = (s - 1.0) * row.restitution * self.lambda[i] - self.correction[i];
            }
            self.island.apply_impulses(&self.step[..n]);
            for (i, row) in rows.iter().enumerate() {
                self.impulse[i] = (1.0 + s * row.restitution) * self.lambda[i];
                self.correction[i] = 0.0;
            }
            self.island.normal_velocities(&mut self.b_mid[..n]);
            self.b_post[..n].copy_from_slice(&self.b_mid[..n]);
            (correction, passes) = self.sparse_correction();
        }
        self.island.scatter(bodies);
        self.outcome(bodies, totals, ke_before, passes, compression, correction)
    }

    /// The sparse path's plastic correction: if some `b_post < −ε_v`, projected Gauss–Seidel from
    /// the current twists with `λ'` from 0, added to `correction` and `impulse`; `b_post` then
    /// holds the final normal velocities. Returns its report and the number of passes (0 or 1).
    fn sparse_correction(&mut self) -> (Option<LcpReport>, usize) {
        let n = self.n;
        if !self.b_post[..n].iter().any(|&v| v < -self.eps_v) {
            return (None, 0);
        }
        self.step[..n].fill(0.0);
        let report = self.pgs_on_island(Buf::Step);
        for i in 0..n {
            self.correction[i] = self.step[i];
            self.impulse[i] += self.step[i];
        }
        self.island.normal_velocities(&mut self.b_post[..n]);
        (Some(report), 1)
    }

    /// Issue 16: the frictional solve; the per-row buffers report its normal impulses.
    fn solve_frictional(
        &mut self,
        rows: &[ImpactRow],
        bodies: &mut [Body],
        totals: Totals,
    ) -> ImpactOutcome {
        let n = rows.len();
        let ke_before = totals.kinetic(bodies);
        for (i, row) in rows.iter().enumerate() {
            self.jac[i] = row.jacobian(bodies);
        }
        self.normal_velocities(rows, bodies, Buf::Pre);
        let out = self.fric.solve(rows, self.mu, self.eps_v, bodies);
        self.normal_velocities(rows, bodies, Buf::Post);
        self.b_mid[..n].copy_from_slice(&self.b_post[..n]);
        self.lambda[..n].copy_from_slice(self.fric.compression_impulses());
        self.impulse[..n].copy_from_slice(self.fric.normal_impulses());
        for i in 0..n {
            self.correction[i] = 0.0;
        }
        let method = match out.compression {
            PhaseMethod::Enumeration | PhaseMethod::Routh => super::lcp::LcpMethod::Enumeration,
            PhaseMethod::Pgs => super::lcp::LcpMethod::Pgs,
            PhaseMethod::Empty => super::lcp::LcpMethod::Empty,
        };
        let mut o = self.outcome(
            bodies,
            totals,
            ke_before,
            out.correction_passes,
            empty_report(n),
            None,
        );
        o.compression.method = method;
        o.compression.converged = out.converged;
        o.energy_fallback = out.restitution_scale.is_some() || out.jump_scale.is_some();
        o
    }

    /// Projected Gauss–Seidel applied directly to the gathered island's twists; accumulates the
    /// impulses in `lambda` (`Buf::Impulse`) or `step` (`Buf::Step`), which must start at zero.
    /// Stops when the largest increment of a sweep is below 1e-9 N·s, or after the sweep budget
    /// (§7.7).
    fn pgs_on_island(&mut self, into: Buf) -> LcpReport {
        let n = self.n;
        // The sweeps this phase may run: the sweep budget, or what the sample's rows left allow
        // over this island (at least one sweep).
        let fit = (self.rows_left / (n.max(1) as u64)).max(1);
        let cap = (self.sweep_budget as u64).min(fit) as usize;
        if cap < self.sweep_budget {
            self.budget.phases_capped += 1;
        }
        let acc = match into {
            Buf::Step => &mut self.step[..n],
            _ => &mut self.lambda[..n],
        };
        let mut sweeps = 0;
        let mut converged = false;
        while sweeps < cap {
            sweeps += 1;
            if self.island.sweep(acc) < 1e-9 {
                converged = true;
                break;
            }
        }
        self.budget.row_updates += (sweeps * n) as u64;
        self.rows_left = self.rows_left.saturating_sub((sweeps * n) as u64);
        if !converged {
            self.budget.phases_cut += 1;
        }
        LcpReport {
            n,
            method: super::lcp::LcpMethod::Pgs,
            active_mask: 0,
            iterations: sweeps,
            converged,
            enumeration_failed: false,
            pgs_failed: !converged,
        }
    }

    /// The summary of the solve just finished (both paths).
    fn outcome(
        &self,
        bodies: &[Body],
        totals: Totals,
        ke_before: f64,
        passes: usize,
        compression: LcpReport,
        correction: Option<LcpReport>,
    ) -> ImpactOutcome {
        let n = self.n;
        ImpactOutcome {
            rows: n,
            kinetic_energy_before: ke_before,
            kinetic_energy_after: totals.kinetic(bodies),
            plastic_correction: passes > 0,
            correction_passes: passes,
            compression,
            correction,
            min_post_velocity: self.b_post[..n]
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min),
            energy_fallback: false,
        }
    }

    /// Writes `G u` for the bodies' current twists into the chosen buffer.
    fn normal_velocities(&mut self, rows: &[ImpactRow], bodies: &[Body], into: Buf) {
        let out = match into {
            Buf::Pre => &mut self.b_pre,
            Buf::Mid => &mut self.b_mid,
            _ => &mut self.b_post,
        };
        for (i, row) in rows.iter().enumerate() {
            let j = &self.jac[i];
            out[i] =
                dot_twist(&j[0..3], &bodies[row.body_a]) + dot_twist(&j[3..6], &bodies[row.body_b]);
        }
    }

    /// Applies `Δu = M⁻¹Gᵀp` for the impulses `p` in the chosen buffer.
    fn apply_impulses(&self, rows: &[ImpactRow], bodies: &mut [Body], from: Buf) {
        let p = match from {
            Buf::Step => &self.step,
            _ => &self.impulse,
        };
        for (i, row) in rows.iter().enumerate() {
            let pi = p[i];
            if pi == 0.0 {
                continue;
            }
            let j = &self.jac[i];
            for (off, bi) in [(0usize, row.body_a), (3, row.body_b)] {
                let body = &mut bodies[bi];
                if !body.is_dynamic() {
                    continue;
                }
                body.vel.x += body.inv_mass * j[off] * pi;
                body.vel.y += body.inv_mass * j[off + 1] * pi;
                body.omega += body.inv_inertia * j[off + 2] * pi;
            }
        }
    }
}

/// Largest impact set solved with the dense Delassus matrix and the exact/PGS LCP of §7.3; larger
/// sets use the equivalent sparse PGS on body twists ([`ImpactSolver`]'s `solve_sparse`).
pub const DENSE_MAX_ROWS: usize = 24;

/// Sweep limit of the sparse PGS (§7.3: 200).
const PGS_MAX_SWEEPS: usize = 200;

/// Whether a solve sums the kinetic energy of every body for its [`ImpactOutcome`].
#[derive(Clone, Copy)]
enum Totals {
    /// Summed: [`ImpactSolver::solve`].
    Summed,
    /// Skipped (the outcome's totals read 0): [`ImpactSolver::solve_island`], whose caller
    /// discards the outcome.
    Skipped,
}

impl Totals {
    /// The total kinetic energy of `bodies` (J), or 0 when skipped.
    fn kinetic(self, bodies: &[Body]) -> f64 {
        match self {
            Totals::Summed => bodies.iter().map(Body::kinetic_energy).sum(),
            Totals::Skipped => 0.0,
        }
    }
}

/// Internal buffer selector.
#[derive(Clone, Copy)]
enum Buf {
    Pre,
    Mid,
    Post,
    Impulse,
    Step,
}

fn empty_report(n: usize) -> LcpReport {
    LcpReport {
        n,
        method: super::lcp::LcpMethod::Empty,
        active_mask: 0,
        iterations: 0,
        converged: false,
        enumeration_failed: false,
        pgs_failed: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Pose;

    #[test]
    fn fixed_bodies_contribute_nothing_and_are_untouched() {
        let mut bodies = vec![
            Body::fixed("wall", Pose::IDENTITY),
            Body::dynamic("box", 2.0, 0.1, Pose::new(1.0, 0.0, 0.0)),
        ];
        bodies[1].vel = Vec2::new(-1.0, 0.0);
        let row = ImpactRow {
            body_a: 1,
            body_b: 0,
            n: Vec2::new(1.0, 0.0),
            r_a: Vec2::new(-1.0, 0.0),
            r_b: Vec2::new(0.0, 0.0),
            restitution: 1.0,
        };
        let mut s = ImpactSolver::with_capacity(1);
        let out = s.solve(&[row], &mut bodies);
        assert!((s.delassus()[0] - 0.5).abs() < 1e-15);
        assert!((bodies[1].vel.x - 1.0).abs() < 1e-15);
        assert_eq!(bodies[0].vel, Vec2::ZERO);
        assert_eq!(bodies[0].omega, 0.0);
        assert!(!out.plastic_correction);
        assert!((s.impulses()[0] - 4.0).abs() < 1e-14);
    }

    #[test]
    fn two_dynamic_bodies_head_on_exchange_velocities() {
        // Equal masses, e = 1, central impact: velocities are exchanged.
        let mut bodies = vec![
            Body::dynamic("a", 1.0, 0.01, Pose::new(0.1, 0.0, 0.0)),
            Body::dynamic("b", 1.0, 0.01, Pose::new(-0.1, 0.0, 0.0)),
        ];
        bodies[0].vel = Vec2::new(-1.0, 0.0);
        bodies[1].vel = Vec2::new(0.5, 0.0);
        let row = ImpactRow {
            body_a: 0,
            body_b: 1,
            n: Vec2::new(1.0, 0.0),
            r_a: Vec2::new(-0.1, 0.0),
            r_b: Vec2::new(0.1, 0.0),
            restitution: 1.0,
        };
        let mut s = ImpactSolver::new();
        let out = s.solve(&[row], &mut bodies);
        assert!((s.delassus()[0] - 2.0).abs() < 1e-15);
        assert!((bodies[0].vel.x - 0.5).abs() < 1e-14);
        assert!((bodies[1].vel.x + 1.0).abs() < 1e-14);
        assert!((out.kinetic_energy_after - out.kinetic_energy_before).abs() < 1e-14);
    }

    #[test]
    fn steady_state_does_not_reallocate() {
        let mut bodies = vec![
            Body::fixed("wall", Pose::IDENTITY),
            Body::dynamic("box", 1.0, 0.1, Pose::new(1.0, 0.0, 0.0)),
        ];
        let row = ImpactRow {
            body_a: 1,
            body_b: 0,
            n: Vec2::new(1.0, 0.0),
            r_a: Vec2::new(-1.0, 0.0),
            r_b: Vec2::ZERO,
            restitution: 0.5,
        };
        let mut s = ImpactSolver::with_capacity(4);
        let (pa, pb) = (s.a.as_ptr(), s.impulse.as_ptr());
        for _ in 0..5 {
            bodies[1].vel = Vec2::new(-1.0, 0.0);
            s.solve(&[row, row], &mut bodies);
        }
        assert_eq!((s.a.as_ptr(), s.impulse.as_ptr()), (pa, pb));
    }

    /// `columns` columns of `boxes` boxes landing on a fixed floor (each column its own island),
    /// and their impact rows, two corner rows per interface.
    fn landing(columns: usize, boxes: usize) -> (Vec<Body>, Vec<ImpactRow>) {
        let inertia = 2.0 * (0.05f64.powi(2) * 2.0) / 12.0;
        let mut bodies = vec![Body::fixed("floor", Pose::IDENTITY)];
        let mut rows = Vec::new();
        for c in 0..columns {
            let x0 = 0.2 * c as f64;
            for k in 0..boxes {
                let mut b = Body::dynamic(
                    format!("b{c}_{k}"),
                    2.0,
                    inertia,
                    Pose::new(x0, 0.025 + 0.05 * k as f64, 0.0),
                );
                b.vel = Vec2::new(0.01 * k as f64 - 0.02 * c as f64, -0.5 - 0.1 * k as f64);
                b.omega = 0.3 * (k as f64 - 2.0);
                let upper = bodies.len();
                bodies.push(b);
                let lower = if k == 0 { 0 } else { upper - 1 };
                for dx in [-0.025, 0.025] {
                    let p = Vec2::new(x0 + dx, 0.05 * k as f64);
                    let e = if k % 2 == 0 { 0.5 } else { 0.0 };
                    let n = Vec2::new(0.0, 1.0);
                    rows.push(ImpactRow::at_point(&bodies, upper, lower, n, p, e));
                }
            }
        }
        (bodies, rows)
    }

    /// `solve_island` (a world's islands) leaves the bodies exactly as `solve` does, on the
    /// dense, the sparse and the frictional paths, and reports the same impulses; only the
    /// outcome's kinetic-energy totals, over every body of the slice, are skipped.
    #[test]
    fn an_island_solve_gives_the_bodies_of_a_full_solve_bit_for_bit() {
        for (boxes, friction) in [
            (3, ImpactFriction::None),
            (16, ImpactFriction::None),
            (3, ImpactFriction::Coulomb),
            (16, ImpactFriction::Coulomb),
        ] {
            let (start, rows) = landing(2, boxes);
            assert_eq!(rows.len() > DENSE_MAX_ROWS, boxes == 16);
            let island = &rows[..2 * boxes];
            let mut full = ImpactSolver::new();
            let mut quiet = ImpactSolver::new();
            full.set_friction(friction, 0.5);
            quiet.set_friction(friction, 0.5);
            let (mut a, mut b) = (start.clone(), start.clone());
            let out = full.solve(island, &mut a);
            quiet.solve_island(island, &mut b);
            for (x, y) in a.iter().zip(&b) {
                assert_eq!(
                    (x.vel.x.to_bits(), x.vel.y.to_bits(), x.omega.to_bits()),
                    (y.vel.x.to_bits(), y.vel.y.to_bits(), y.omega.to_bits()),
                    "{boxes} boxes, {friction:?}: {}",
                    x.name
                );
            }
            assert_eq!(full.impulses(), quiet.impulses());
            // The other column is untouched, and the full solve's totals count it.
            assert_eq!(a[boxes + 1..], start[boxes + 1..]);
            let all: f64 = start.iter().map(Body::kinetic_energy).sum();
            assert_eq!(out.kinetic_energy_before, all);
            assert!(out.kinetic_energy_after < all);
        }
    }
}
