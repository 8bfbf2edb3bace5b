//! Simultaneous impacts with Coulomb friction and Poisson restitution, passive by construction
//! (issue 16; derivation in docs/MODELS.md "Frictional impacts (issue 16)", §E).
//!
//! Per contact `i` (normal `n_i`, tangent `t_i = perp(n_i)`) the impulse is `p_n,i·n_i + p_t,i·t_i`
//! with `p_n,i ≥ 0` and `|p_t,i| ≤ μ·p_n,i` (the 2-D friction cone is an exact interval). The impact
//! runs in two phases (Poisson):
//!
//! 1. **Compression**: the mixed LCP `0 ≤ p_n ⟂ w_n ≥ 0`, `p_t ∈ −μ·p_n·∂|w_t|` on the velocities
//!    `w = b + A·p` reached at the end of compression (`A` the `2n × 2n` Delassus matrix).
//! 2. **Restitution**: normal impulses prescribed, `P_i = e_i·p_n,i(compression)`; the tangential
//!    impulses solve the same friction conditions with the bound `μ·P_i`.
//!
//! A single contact is integrated exactly in impulse space (Routh's method: slip, stick or reversal
//! events inside a phase); two to [`MLCP_ENUMERATION_MAX`] contacts solve each phase's mixed LCP by
//! exact enumeration; larger sets (or an enumeration that finds no solution) by projected
//! Gauss–Seidel on the body twists with the convergence test of [`PGS_TOL`].
//!
//! **Energy guarantee.** Compression is dissipative (proved in §E.4), restitution with friction is
//! not always (Stronge). After restitution the kinetic energy is checked; if it rose, the
//! restitution impulse is scaled by the largest `α ∈ [0, 1]` that returns it to the pre-impact value
//! (closed form below). The plastic correction is a compression (dissipative). A last check scales
//! the whole velocity jump to the kinetic-energy minimiser along it (rounding or a non-converged
//! iteration). Every fallback is counted ([`FrictionalImpactSolver::fallbacks`]).

use super::impact::ImpactRow;
use super::impact_mlcp::{ImpactPhase, MixedLcp, MLCP_ENUMERATION_MAX};
use super::last_solve::last_solve_views;
use crate::body::Body;
use crate::geom::{cross, perp};
use crate::laws::friction::FrictionModel;

/// Projected Gauss–Seidel convergence test: a sweep whose largest impulse change is below this
/// (N·s) ends the iteration (the §7.3 rule of the frictionless solver).
pub const PGS_TOL: f64 = 1e-9;
/// Projected Gauss–Seidel sweep limit (§7.3).
pub const PGS_MAX_SWEEPS: usize = 200;
/// Relative kinetic-energy tolerance of the energy checks: `T⁺ ≤ T⁻·(1 + KE_REL_TOL) + KE_ABS_TOL`.
pub const KE_REL_TOL: f64 = 1e-12;
/// Absolute kinetic-energy tolerance of the energy checks (J).
pub const KE_ABS_TOL: f64 = 1e-15;
/// Tangential speeds below this (m/s) count as zero in the single-contact integration.
const VT_ZERO: f64 = 1e-12;
/// Maximum plastic-correction passes (as the frictionless solver).
const MAX_CORRECTION_PASSES: usize = 3;

/// Whether impacts carry friction (`[contact] impact_friction`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ImpactFriction {
    /// Frictionless impulses along the normals (§7, the paper's model; default).
    #[default]
    None,
    /// Coulomb friction during the impulse (issue 16).
    Coulomb,
}

impl ImpactFriction {
    /// The names accepted in scene files.
    pub const NAMES: &'static [&'static str] = &["none", "coulomb"];

    /// The mode called `name`; the error lists the valid names.
    pub fn from_name(name: &str) -> Result<Self, String> {
        match name {
            "none" => Ok(Self::None),
            "coulomb" => Ok(Self::Coulomb),
            _ => Err(format!(
                "unknown impact friction '{name}'; valid: {}",
                Self::NAMES.join(", ")
            )),
        }
    }

    /// The scene-file name.
    pub fn name(&self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Coulomb => "coulomb",
        }
    }
}

/// The default impact friction coefficient: the contact friction model's kinetic coefficient `μ_k`
/// (dimensionless), 0 for the model `none`.
pub fn default_impact_mu(model: &FrictionModel) -> f64 {
    match model {
        FrictionModel::None => 0.0,
        FrictionModel::ResetIntegrator(m) => m.mu_k,
        FrictionModel::HaywardArmstrong(m) => m.mu_k,
        FrictionModel::FingerPad(m) => m.mu_k,
        FrictionModel::Karnopp(m) => m.mu_k,
        FrictionModel::SalcudeanVlaar(m) => m.mu_k,
    }
}

/// How one phase was solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhaseMethod {
    /// Nothing to do (no approach, or no prescribed impulse).
    Empty,
    /// Single contact, exact impulse-space integration (Routh).
    Routh,
    /// Exact enumeration of the mixed LCP.
    Enumeration,
    /// Projected Gauss–Seidel on the body twists.
    Pgs,
}

/// Summary of one [`FrictionalImpactSolver::solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionalOutcome {
    /// Number of contacts.
    pub rows: usize,
    /// Kinetic energy of the bodies touched by the set, before (J).
    pub kinetic_energy_before: f64,
    /// Kinetic energy of the bodies touched by the set, after (J).
    pub kinetic_energy_after: f64,
    /// Method of the compression phase.
    pub compression: PhaseMethod,
    /// Method of the restitution phase.
    pub restitution: PhaseMethod,
    /// False if a projected Gauss–Seidel phase stopped at its sweep limit.
    pub converged: bool,
    /// Plastic-correction passes run.
    pub correction_passes: usize,
    /// `Some(α)` when the restitution impulse was scaled by `α < 1` (energy fallback 1).
    pub restitution_scale: Option<f64>,
    /// `Some(β)` when the whole velocity jump was scaled by `β < 1` (energy fallback 2).
    pub jump_scale: Option<f64>,
}

/// Solver of one island's frictional impact. Owns its scratch; steady-state calls do not allocate.
#[derive(Clone, Debug, Default)]
pub struct FrictionalImpactSolver {
    cap: usize,
    n: usize,
    /// Normal and tangent Jacobian rows (A block then B block).
    jn: Vec<[f64; 6]>,
    jt: Vec<[f64; 6]>,
    /// Diagonal Delassus entries `A_nn,ii`, `A_tt,ii`.
    dnn: Vec<f64>,
    dtt: Vec<f64>,
    /// Total impulses of the solve (N·s).
    pn: Vec<f64>,
    pt: Vec<f64>,
    /// Impulses of the current phase (N·s).
    qn: Vec<f64>,
    qt: Vec<f64>,
    /// Compression normal impulses and restitution targets `P_i` (N·s).
    pc: Vec<f64>,
    target: Vec<f64>,
    /// Dense Delassus matrix and start velocities of a phase (enumeration only).
    a: Vec<f64>,
    b: Vec<f64>,
    mlcp: MixedLcp,
    /// Dynamic bodies touched by the set, their twists before the impact and after compression.
    touched: Vec<usize>,
    mark: Vec<bool>,
    u0: Vec<[f64; 3]>,
    uc: Vec<[f64; 3]>,
    /// Impact sets whose restitution impulse was scaled (fallback 1).
    restitution_fallbacks: u64,
    /// Impact sets whose whole velocity jump was scaled (fallback 2).
    jump_fallbacks: u64,
}

last_solve_views! { FrictionalImpactSolver, "contacts";
    /// Total normal impulses `p_n,i` of the last solve (N·s, along `n_i` on body A).
    normal_impulses => pn,
    /// Total tangential impulses `p_t,i` of the last solve (N·s, along `t_i = perp(n_i)` on body A).
    tangential_impulses => pt,
    /// Compression normal impulses of the last solve (N·s).
    compression_impulses => pc,
}

impl FrictionalImpactSolver {
    /// A solver preallocated for `rows` contacts.
    pub fn with_capacity(rows: usize) -> Self {
        let mut s = Self::default();
        s.reserve(rows);
        s
    }

    /// Grows the buffers for `rows` contacts (no-op if they already hold them).
    pub fn reserve(&mut self, rows: usize) {
        if rows <= self.cap {
            return;
        }
        self.jn.resize(rows, [0.0; 6]);
        self.jt.resize(rows, [0.0; 6]);
        for v in [
            &mut self.dnn,
            &mut self.dtt,
            &mut self.pn,
            &mut self.pt,
            &mut self.qn,
            &mut self.qt,
            &mut self.pc,
            &mut self.target,
        ] {
            v.resize(rows, 0.0);
        }
        let k = 2 * rows.min(MLCP_ENUMERATION_MAX);
        self.a.resize(k * k, 0.0);
        self.b.resize(k, 0.0);
        self.mlcp.reserve(rows);
        let bodies = 2 * rows;
        if self.touched.capacity() < bodies {
            self.touched.reserve(bodies - self.touched.len());
        }
        self.u0.resize(bodies, [0.0; 3]);
        self.uc.resize(bodies, [0.0; 3]);
        self.cap = rows;
    }

    /// Energy fallbacks so far: `(restitution scaled, whole jump scaled)`.
    pub fn fallbacks(&self) -> (u64, u64) {
        (self.restitution_fallbacks, self.jump_fallbacks)
    }

    /// Resolves the impact set `rows` with friction coefficient `mu` (≥ 0) and plastic-correction
    /// threshold `eps_v` (m/s), applying the velocity jumps to `bodies`.
    ///
    /// # Panics
    /// If a row's body index is not an index into `bodies` (a bug in the caller).
    pub fn solve(
        &mut self,
        rows: &[ImpactRow],
        mu: f64,
        eps_v: f64,
        bodies: &mut [Body],
    ) -> FrictionalOutcome {
        let n = rows.len();
        self.reserve(n);
        self.n = n;
        if self.mark.len() < bodies.len() {
            self.mark.resize(bodies.len(), false);
        }
        // Jacobians: normal (n, r×n) and tangent (t, r×t) blocks, t = perp(n); zero for fixed bodies.
        self.touched.clear();
        for (i, row) in rows.iter().enumerate() {
            let t = perp(row.n);
            let (mut jn, mut jt) = ([0.0; 6], [0.0; 6]);
            if bodies[row.body_a].is_dynamic() {
                jn[..3].copy_from_slice(&[row.n.x, row.n.y, cross(row.r_a, row.n)]);
                jt[..3].copy_from_slice(&[t.x, t.y, cross(row.r_a, t)]);
            }
            if bodies[row.body_b].is_dynamic() {
                jn[3..].copy_from_slice(&[-row.n.x, -row.n.y, -cross(row.r_b, row.n)]);
                jt[3..].copy_from_slice(&[-t.x, -t.y, -cross(row.r_b, t)]);
            }
            self.jn[i] = jn;
            self.jt[i] = jt;
            let (mut dn, mut dt) = (0.0, 0.0);
            for (off, bi) in [(0usize, row.body_a), (3, row.body_b)] {
                let b = &bodies[bi];
                dn += b.inv_mass * (jn[off] * jn[off] + jn[off + 1] * jn[off + 1])
                    + b.inv_inertia * jn[off + 2] * jn[off + 2];
                dt += b.inv_mass * (jt[off] * jt[off] + jt[off + 1] * jt[off + 1])
                    + b.inv_inertia * jt[off + 2] * jt[off + 2];
                if b.is_dynamic() && !self.mark[bi] {
                    self.mark[bi] = true;
                    self.touched.push(bi);
                }
            }
            self.dnn[i] = dn;
            self.dtt[i] = dt;
            self.pn[i] = 0.0;
            self.pt[i] = 0.0;
        }
        for &bi in &self.touched {
            self.mark[bi] = false;
        }
        for (k, &bi) in self.touched.iter().enumerate() {
            self.u0[k] = twist(&bodies[bi]);
        }
        let ke0 = self.touched_ke(bodies);
        let ke_tol = ke0 * KE_REL_TOL + KE_ABS_TOL;
        let mut converged = true;

        // 1. Compression.
        let (compression, ok) = self.phase(rows, mu, ImpactPhase::Compression, bodies);
        converged &= ok;
        self.pc[..n].copy_from_slice(&self.qn[..n]);
        for (k, &bi) in self.touched.iter().enumerate() {
            self.uc[k] = twist(&bodies[bi]);
        }
        let ke_c = self.touched_ke(bodies);

        // 2. Restitution with prescribed normal impulses P_i = e_i·p_n,i.
        let mut any = false;
        for (i, row) in rows.iter().enumerate() {
            self.target[i] = row.restitution * self.pc[i];
            any |= self.target[i] > 0.0;
        }
        let mut restitution = PhaseMethod::Empty;
        let mut restitution_scale = None;
        if any {
            let (m, ok) = self.phase(rows, mu, ImpactPhase::Restitution, bodies);
            restitution = m;
            converged &= ok;
            // Energy fallback 1. Along u(α) = u_c + α·Δ with Δ = u_r − u_c (the restitution jump),
            //   T(α) = T_c + α·g + ½·α²·h,  g = Σ Δᵀ M u_c,  h = Σ Δᵀ M Δ ≥ 0.
            // T(1) > T⁻ triggers it; T_c ≤ T⁻ (compression is dissipative), so the largest α ∈ [0, 1]
            // with T(α) ≤ T⁻ is the positive root of ½·h·α² + g·α − D = 0, D = T⁻ − T_c ≥ 0:
            //   α = (−g + √(g² + 2·h·D)) / h  (h > 0; T(1) > T⁻ ≥ T_c rules out h = g = 0).
            let ke_r = self.touched_ke(bodies);
            if ke_r > ke0 + ke_tol {
                let (g, h) = self.line_coefficients(bodies, true);
                let d = (ke0 - ke_c).max(0.0);
                let alpha = if h > 0.0 {
                    ((-g + (g * g + 2.0 * h * d).max(0.0).sqrt()) / h).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                self.scale_jump(bodies, alpha, true);
                for i in 0..n {
                    self.pn[i] -= (1.0 - alpha) * self.qn[i];
                    self.pt[i] -= (1.0 - alpha) * self.qt[i];
                }
                self.restitution_fallbacks += 1;
                restitution_scale = Some(alpha);
            }
        }

        // 3. Plastic correction: a compression from the current velocities (dissipative).
        let mut passes = 0;
        while passes < MAX_CORRECTION_PASSES && self.min_normal_velocity(rows, bodies) < -eps_v {
            passes += 1;
            let (_, ok) = self.phase(rows, mu, ImpactPhase::Compression, bodies);
            converged &= ok;
        }

        // 4. Last check (rounding, an unconverged iteration): scale the whole jump Δ = u − u⁻ to the
        //    kinetic-energy minimiser along it, β = −g/h with g = Σ Δᵀ M u⁻, h = Σ Δᵀ M Δ, clamped
        //    to [0, 1]: T(β) = T⁻ + β·g + ½β²·h = T⁻ − g²/(2h) ≤ T⁻. If rounding still leaves
        //    T > T⁻ + tol, the pre-impact twists are restored exactly (β = 0).
        let mut jump_scale = None;
        if self.touched_ke(bodies) > ke0 + ke_tol {
            let (g, h) = self.line_coefficients(bodies, false);
            let mut beta = if h > 0.0 {
                (-g / h).clamp(0.0, 1.0)
            } else {
                0.0
            };
            self.scale_jump(bodies, beta, false);
            if self.touched_ke(bodies) > ke0 + ke_tol {
                beta = 0.0;
                self.scale_jump(bodies, 0.0, false);
            }
            for i in 0..n {
                self.pn[i] *= beta;
                self.pt[i] *= beta;
            }
            self.jump_fallbacks += 1;
            jump_scale = Some(beta);
        }

        FrictionalOutcome {
            rows: n,
            kinetic_energy_before: ke0,
            kinetic_energy_after: self.touched_ke(bodies),
            compression,
            restitution,
            converged,
            correction_passes: passes,
            restitution_scale,
            jump_scale,
        }
    }

    /// Kinetic energy of the touched bodies (J), in their fixed order.
    fn touched_ke(&self, bodies: &[Body]) -> f64 {
        self.touched
            .iter()
            .map(|&bi| bodies[bi].kinetic_energy())
            .sum()
    }

    /// `(g, h)` of the line `u(s) = base + s·Δ`, `Δ = u − base`: `g = Σ Δᵀ M base`, `h = Σ Δᵀ M Δ`.
    /// `base` is the post-compression twist (`from_compression`) or the pre-impact one.
    fn line_coefficients(&self, bodies: &[Body], from_compression: bool) -> (f64, f64) {
        let (mut g, mut h) = (0.0, 0.0);
        for (k, &bi) in self.touched.iter().enumerate() {
            let b = &bodies[bi];
            let base = if from_compression {
                self.uc[k]
            } else {
                self.u0[k]
            };
            let d = [b.vel.x - base[0], b.vel.y - base[1], b.omega - base[2]];
            g += b.mass * (d[0] * base[0] + d[1] * base[1]) + b.inertia * d[2] * base[2];
            h += b.mass * (d[0] * d[0] + d[1] * d[1]) + b.inertia * d[2] * d[2];
        }
        (g, h)
    }

    /// Sets every touched body to `base + s·(u − base)`.
    fn scale_jump(&self, bodies: &mut [Body], s: f64, from_compression: bool) {
        for (k, &bi) in self.touched.iter().enumerate() {
            let b = &mut bodies[bi];
            let base = if from_compression {
                self.uc[k]
            } else {
                self.u0[k]
            };
            if s == 0.0 {
                b.vel.x = base[0];
                b.vel.y = base[1];
                b.omega = base[2];
            } else {
                b.vel.x = base[0] + s * (b.vel.x - base[0]);
                b.vel.y = base[1] + s * (b.vel.y - base[1]);
                b.omega = base[2] + s * (b.omega - base[2]);
            }
        }
    }

    /// Smallest normal velocity `G_n,i·u` (m/s) over the set; `+∞` when empty.
    fn min_normal_velocity(&self, rows: &[ImpactRow], bodies: &[Body]) -> f64 {
        let mut m = f64::INFINITY;
        for (i, row) in rows.iter().enumerate() {
            if self.dnn[i] > 0.0 {
                m = m.min(row_velocity(&self.jn[i], row, bodies));
            }
        }
        m
    }

    /// Applies `Δu = M⁻¹(G_n,iᵀ·dn + G_t,iᵀ·dt)` for contact `i`.
    fn apply(&self, i: usize, row: &ImpactRow, bodies: &mut [Body], dn: f64, dt: f64) {
        let (jn, jt) = (&self.jn[i], &self.jt[i]);
        for (off, bi) in [(0usize, row.body_a), (3, row.body_b)] {
            let b = &mut bodies[bi];
            if b.is_dynamic() {
                b.vel.x += b.inv_mass * (jn[off] * dn + jt[off] * dt);
                b.vel.y += b.inv_mass * (jn[off + 1] * dn + jt[off + 1] * dt);
                b.omega += b.inv_inertia * (jn[off + 2] * dn + jt[off + 2] * dt);
            }
        }
    }

    /// One phase: impulses into `qn`, `qt` (and added to the totals), velocity jumps applied.
    /// Returns the method and false if an iteration did not converge.
    fn phase(
        &mut self,
        rows: &[ImpactRow],
        mu: f64,
        phase: ImpactPhase,
        bodies: &mut [Body],
    ) -> (PhaseMethod, bool) {
        let n = rows.len();
        self.qn[..n].fill(0.0);
        self.qt[..n].fill(0.0);
        let result = if n == 1 {
            self.routh(&rows[0], mu, phase, bodies)
        } else if n <= MLCP_ENUMERATION_MAX && self.enumerate(rows, mu, phase, bodies) {
            (PhaseMethod::Enumeration, true)
        } else {
            (PhaseMethod::Pgs, self.pgs(rows, mu, phase, bodies))
        };
        for i in 0..n {
            self.pn[i] += self.qn[i];
            self.pt[i] += self.qt[i];
        }
        result
    }

    /// Single contact, exact (Routh). In impulse space the contact velocity moves along
    /// `d(w_n, w_t) = (a_nn·dp_n + a_nt·dp_t, a_nt·dp_n + a_tt·dp_t)`. With the normal impulse as the
    /// parameter, friction fixes `k = dp_t/dp_n`:
    /// - sliding (`w_t ≠ 0`, `s = sign w_t`): `k = −s·μ`;
    /// - at `w_t = 0`, sticking if it holds (`|a_nt| ≤ μ·a_tt`): `k = −a_nt/a_tt`, so `dw_t = 0`;
    /// - otherwise slip starts (reversal) in the direction `s = sign(a_nt)` it is driven to, `k = −s·μ`
    ///   (then `dw_t/dp_n = a_nt − s·μ·a_tt` has sign `s`: consistent, and it never returns to 0).
    ///
    /// The piece ends where slip stops (`w_t = 0`) or the phase ends: compression at `w_n = 0`,
    /// restitution when the phase's normal impulse reaches `P`. With `A` positive definite
    /// `dw_n/dp_n > 0` when slip cannot stop, so every phase ends after at most three pieces.
    fn routh(
        &mut self,
        row: &ImpactRow,
        mu: f64,
        phase: ImpactPhase,
        bodies: &mut [Body],
    ) -> (PhaseMethod, bool) {
        let (jn, jt) = (self.jn[0], self.jt[0]);
        let mut vn = row_velocity(&jn, row, bodies);
        let mut vt = row_velocity(&jt, row, bodies);
        let (a_nn, a_tt) = (self.dnn[0], self.dtt[0]);
        let mut a_nt = 0.0;
        for (off, bi) in [(0usize, row.body_a), (3, row.body_b)] {
            let b = &bodies[bi];
            a_nt += b.inv_mass * (jn[off] * jt[off] + jn[off + 1] * jt[off + 1])
                + b.inv_inertia * jn[off + 2] * jt[off + 2];
        }
        let target = match phase {
            ImpactPhase::Compression if vn >= 0.0 || a_nn <= 0.0 => {
                return (PhaseMethod::Empty, true)
            }
            ImpactPhase::Compression => f64::INFINITY,
            ImpactPhase::Restitution => self.target[0],
        };
        let (mut p_n, mut p_t) = (0.0, 0.0);
        for _ in 0..4 {
            let (k, sliding) = if vt.abs() > VT_ZERO {
                (-vt.signum() * mu, true)
            } else if a_nt.abs() <= mu * a_tt && a_tt > 0.0 {
                (-a_nt / a_tt, false)
            } else {
                vt = 0.0;
                (-a_nt.signum() * mu, false)
            };
            let r_n = a_nn + a_nt * k;
            let r_t = a_nt + a_tt * k;
            let d_end = match phase {
                ImpactPhase::Compression if r_n > 0.0 => -vn / r_n,
                ImpactPhase::Compression => f64::INFINITY,
                ImpactPhase::Restitution => target - p_n,
            };
            let d_slip = if sliding && r_t * vt < 0.0 {
                -vt / r_t
            } else {
                f64::INFINITY
            };
            let d = d_end.min(d_slip).max(0.0);
            if !d.is_finite() {
                break;
            }
            p_n += d;
            p_t += k * d;
            vn += r_n * d;
            if d_slip < d_end {
                vt = 0.0;
            } else {
                break;
            }
        }
        self.qn[0] = p_n;
        self.qt[0] = p_t;
        self.apply(0, row, bodies, p_n, p_t);
        (PhaseMethod::Routh, true)
    }

    /// Exact enumeration of the phase's mixed LCP; false if no mode vector is feasible.
    fn enumerate(
        &mut self,
        rows: &[ImpactRow],
        mu: f64,
        phase: ImpactPhase,
        bodies: &mut [Body],
    ) -> bool {
        let n = rows.len();
        let k = 2 * n;
        // Dense Delassus matrix over the stacked rows (n_0, t_0, n_1, t_1, …) and start velocities.
        for i in 0..k {
            let (ri, ji) = stacked_row(rows, &self.jn, &self.jt, i);
            self.b[i] = row_velocity(ji, ri, bodies);
            for j in 0..k {
                let (rj, jj) = stacked_row(rows, &self.jn, &self.jt, j);
                let mut s = 0.0;
                for (pi, bi) in [(0usize, ri.body_a), (3, ri.body_b)] {
                    let body = &bodies[bi];
                    if !body.is_dynamic() {
                        continue;
                    }
                    for (pj, bj) in [(0usize, rj.body_a), (3, rj.body_b)] {
                        if bi == bj {
                            s += body.inv_mass * (ji[pi] * jj[pj] + ji[pi + 1] * jj[pj + 1])
                                + body.inv_inertia * ji[pi + 2] * jj[pj + 2];
                        }
                    }
                }
                self.a[i * k + j] = s;
            }
        }
        if self
            .mlcp
            .solve(&self.a[..k * k], &self.b[..k], mu, phase, &self.target[..n])
            .is_none()
        {
            return false;
        }
        for (i, row) in rows.iter().enumerate() {
            let x = self.mlcp.solution(n);
            let (dn, dt) = (x[2 * i], x[2 * i + 1]);
            self.qn[i] = dn;
            self.qt[i] = dt;
            self.apply(i, row, bodies, dn, dt);
        }
        true
    }

    /// Projected Gauss–Seidel on the body twists ("sequential impulses"): per contact,
    /// `p_n ← max(0, p_n − w_n/A_nn)` (compression only), then
    /// `p_t ← clamp(p_t − w_t/A_tt, −μ·p_n, μ·p_n)`, each increment applied to the bodies at once, so
    /// `w = G·u` is always current and a row costs O(1). In restitution `p_n = P_i` is applied first
    /// and kept. Convergence test: a sweep whose largest `|Δp|` is below [`PGS_TOL`]; at a fixed
    /// point every projection is idle, which is exactly the phase's complementarity conditions.
    fn pgs(
        &mut self,
        rows: &[ImpactRow],
        mu: f64,
        phase: ImpactPhase,
        bodies: &mut [Body],
    ) -> bool {
        if phase == ImpactPhase::Restitution {
            for (i, row) in rows.iter().enumerate() {
                let p = self.target[i];
                self.qn[i] = p;
                self.apply(i, row, bodies, p, 0.0);
            }
        }
        for _ in 0..PGS_MAX_SWEEPS {
            let mut max_delta = 0.0f64;
            for (i, row) in rows.iter().enumerate() {
                if phase == ImpactPhase::Compression && self.dnn[i] > 0.0 {
                    let w = row_velocity(&self.jn[i], row, bodies);
                    let new = (self.qn[i] - w / self.dnn[i]).max(0.0);
                    let d = new - self.qn[i];
                    if d != 0.0 {
                        self.qn[i] = new;
                        self.apply(i, row, bodies, d, 0.0);
                        max_delta = max_delta.max(d.abs());
                    }
                }
                if self.dtt[i] > 0.0 {
                    let w = row_velocity(&self.jt[i], row, bodies);
                    let bound = mu * self.qn[i];
                    let new = (self.qt[i] - w / self.dtt[i]).clamp(-bound, bound);
                    let d = new - self.qt[i];
                    if d != 0.0 {
                        self.qt[i] = new;
                        self.apply(i, row, bodies, 0.0, d);
                        max_delta = max_delta.max(d.abs());
                    }
                }
            }
            if max_delta < PGS_TOL {
                return true;
            }
        }
        false
    }
}

/// `(v_x, v_y, ω)` of a body.
fn twist(b: &Body) -> [f64; 3] {
    [b.vel.x, b.vel.y, b.omega]
}

/// Row `i` of the stacked frictional set (`n_0, t_0, n_1, t_1, …`): its impact row and its normal
/// (even `i`) or tangential (odd `i`) Jacobian `[ax, ay, aω, bx, by, bω]`.
#[inline(always)]
fn stacked_row<'a>(
    rows: &'a [ImpactRow],
    jn: &'a [[f64; 6]],
    jt: &'a [[f64; 6]],
    i: usize,
) -> (&'a ImpactRow, &'a [f64; 6]) {
    let j = if i.is_multiple_of(2) {
        &jn[i / 2]
    } else {
        &jt[i / 2]
    };
    (&rows[i / 2], j)
}

/// `J·u` for one 6-entry Jacobian row of `row`'s two bodies (m/s).
fn row_velocity(j: &[f64; 6], row: &ImpactRow, bodies: &[Body]) -> f64 {
    let (a, b) = (&bodies[row.body_a], &bodies[row.body_b]);
    j[0] * a.vel.x
        + j[1] * a.vel.y
        + j[2] * a.omega
        + j[3] * b.vel.x
        + j[4] * b.vel.y
        + j[5] * b.omega
}
