//! Implicit damping of contact chains (issue 17): the damper that lets a stack come to rest.
//!
//! **Why.** Every contact is an explicit spring–damper (`Kc`, `Bc`, §5.9), so its damping is
//! proportional to its stiffness (`Bc/Kc = 0.4 ms` in the pile). For a chain of such interfaces
//! the modal damping is `ζ_i = (Bc/Kc)·ω_i/2`: the slow collective modes of a tall stack are
//! barely damped (pile:1000, 40 rows: `ω_1 ≈ 17 rad/s`, decay rate `≈ 0.16 s⁻¹` measured, the
//! pile "breathes" for tens of seconds; docs/PERFORMANCE.md). A larger `Bc` is not available:
//! the force pass is explicit and a body with `C` contacts sees `T·Bc·C·w ≈ 0.8` already, against
//! an explicit stability bound of about 1.
//!
//! **What.** For every contact of a *chain* — a Continuous, loaded (`f_n > 0`) record of which a
//! dynamic body touches at least two other bodies — an extra normal damper
//! `B_c = m_c/τ` (`m_c = 1/w` the contact's effective normal mass,
//! `w = 1/m_A + 1/m_B + (r_A×n)²/I_A + (r_B×n)²/I_B`, `τ` = `WorldParams::chain_tau`) acts on the
//! *end-of-sample* relative normal velocity (backward Euler): `F = −B_c·v⁺_n`, solved for all
//! chain contacts together by projected Gauss–Seidel (fixed number of sweeps, in the contact
//! set's key order, from zero impulses) with the bound `F ≥ −f_n` (the damper may cancel the
//! law's push but never pulls). Implicit, it is stable for any `τ > 0` and any number of contacts
//! per body, so a contact can be damped near or above critical and the collective modes decay.
//!
//! **Passive.** With `v*` the velocities the integrator would reach without this damper, impulses
//! `λ` change the kinetic energy by `λᵀv* + ½λᵀWλ = Φ(λ) − ½λᵀK⁻¹λ`, where
//! `Φ(λ) = ½λᵀ(W + K⁻¹)λ + λᵀv*` (`K = diag(T·B_c)`) is the convex function that projected
//! Gauss–Seidel decreases monotonically from `Φ(0) = 0` inside a box that contains 0. So
//! `ΔKE ≤ −½λᵀK⁻¹λ ≤ 0` after every sweep, whatever the number of sweeps: the pass only removes
//! energy (returned by [`ChainDamping::apply`]). Positions then advance with the damped velocity
//! (semi-implicit Euler), as they do with any other held force.
//!
//! **Choice of τ and sweeps** (pile:1000 at 1 kHz, `haptic2d-bench --settle 6 --every 0.25 (or
//! 0.05) --set world.chain_tau=τ,world.chain_sweeps=S`; "at rest from" = the first check after
//! which no body moved ≥ 1 cm/s): off, 1000 bodies moving at 6 s; τ = 1 ms / 8 sweeps, 4.5 s
//! (0.0098 m/s at 5 s: no margin); 0.5 ms / 8, 3.75 s; 0.5 ms / 12 and / 16, blips of 1–2 cm/s
//! up to 3.2–5 s; 0.2 ms / 8, 2.25 s; 0.1 ms / 4, *never* (500 bodies at 0.1 m/s at 5 s);
//! **0.2 ms / 16, 2.15 s** (0.05 s checks; largest speed after 2.5 s 6.8 mm/s; the default).
//! The sweeps matter beyond the pile: with 8 sweeps at τ = 0.2 ms the 25 aligned 10-box stacks
//! of `tests/stack_corners.rs` kept rocking (2 cm/s, contacts churning after 2 s); with 16 they
//! pass (2e-3 m/s). A sweep that has not converged leaves `F ≠ −B_c·v⁺` (still passive, but the
//! impulses then shuffle energy between the stack's modes instead of removing it).
//!
//! **Scope.** Bodies that touch only one other body (a box on the floor, a probe against a wall:
//! the paper's one- and two-contact scenes) are not chains: their contacts keep the explicit law
//! alone, bit for bit. The pass runs in [`IntegrationMode::SemiImplicit`](super::IntegrationMode)
//! only, after the drive of the sample is known (`World::finish_step`); the contact wrench of a
//! body includes it after `finish_step` (before, in `begin_step`, only the explicit laws).

use crate::body::Body;
use crate::contact::{ContactState, VeContact, Wrench2};
use crate::geom::{cross, Vec2};

/// No partner yet (per-body scratch).
const NONE: u32 = u32::MAX;

/// One chain contact in the solve, with everything its update needs (no body lookups in the
/// sweeps).
#[derive(Clone, Copy, Debug)]
struct Row {
    a: usize,
    b: usize,
    n: Vec2,
    /// `r_A × n`, `r_B × n` (m).
    rna: f64,
    rnb: f64,
    /// Velocity change of A / B per unit impulse: `n/m`, and `(r × n)/I` (1/kg, 1/(kg·m)).
    ja: Vec2,
    ka: f64,
    jb: Vec2,
    kb: f64,
    /// Inverse effective normal mass `w` (1/kg).
    w: f64,
    /// `c = r/((1 + r)·w)` with `r = T/τ` (kg).
    c: f64,
    /// Lower bound `−T·f_n` of the impulse (N·s).
    lo: f64,
    /// Accumulated impulse (N·s, along `+n` on A).
    lambda: f64,
}

/// The implicit chain damper of a world (its parameters and reused buffers).
#[derive(Clone, Debug)]
pub struct ChainDamping {
    partner: Vec<u32>,
    multi: Vec<bool>,
    vel: Vec<Vec2>,
    omega: Vec<f64>,
    rows: Vec<Row>,
    /// Chain contacts damped in the last sample.
    pub last_rows: usize,
}

/// Default damping time `τ` (s) of the chain damper (`WorldParams::chain_tau`).
pub const DEFAULT_CHAIN_TAU: f64 = 2.0e-4;
/// Default number of the chain damper's Gauss–Seidel sweeps (`WorldParams::chain_sweeps`).
pub const DEFAULT_CHAIN_SWEEPS: u32 = 16;

impl Default for ChainDamping {
    fn default() -> Self {
        Self {
            partner: Vec::new(),
            multi: Vec::new(),
            vel: Vec::new(),
            omega: Vec::new(),
            rows: Vec::with_capacity(64),
            last_rows: 0,
        }
    }
}

impl ChainDamping {
    /// Adds the chain dampers' forces of this sample to `wrenches` and to the bodies' held
    /// `force`/`torque` (which must hold every other force of the sample), given the contact
    /// records `entries` of this sample and the sample period `dt` (s), with damping time `tau`
    /// (s: a chain contact's damper is `B_c = m_c/τ`, N·s/m; `None` = off) and `sweeps`
    /// Gauss–Seidel sweeps (each one passive; more damp the collective modes of tall stacks
    /// faster). Returns the kinetic energy the dampers remove over the sample (J, ≥ 0 up to
    /// rounding).
    pub fn apply(
        &mut self,
        tau: Option<f64>,
        sweeps: u32,
        dt: f64,
        entries: &[VeContact],
        bodies: &mut [Body],
        wrenches: &mut [Wrench2],
    ) -> f64 {
        self.last_rows = 0;
        let tau = match tau {
            Some(t) if t > 0.0 && t.is_finite() && dt > 0.0 => t,
            _ => return 0.0,
        };
        let n = bodies.len();
        if self.partner.len() != n {
            self.partner.resize(n, NONE);
            self.multi.resize(n, false);
            self.vel.resize(n, Vec2::ZERO);
            self.omega.resize(n, 0.0);
        }
        self.partner.fill(NONE);
        self.multi.fill(false);
        // 1. Which dynamic bodies touch two or more other bodies.
        for e in entries.iter().filter(|e| is_loaded(e)) {
            for (x, y) in [(e.body_a, e.body_b), (e.body_b, e.body_a)] {
                if !bodies[x].is_dynamic() {
                    continue;
                }
                let p = &mut self.partner[x];
                if *p == NONE {
                    *p = y as u32;
                } else if *p != y as u32 {
                    self.multi[x] = true;
                }
            }
        }
        // 2. The chain contacts.
        let r = dt / tau;
        self.rows.clear();
        for e in entries.iter().filter(|e| is_loaded(e)) {
            let (a, b) = (e.body_a, e.body_b);
            let chain = (bodies[a].is_dynamic() && self.multi[a])
                || (bodies[b].is_dynamic() && self.multi[b]);
            if !chain {
                continue;
            }
            let (ba, bb) = (&bodies[a], &bodies[b]);
            let rna = cross(e.point - ba.pose.pos, e.n);
            let rnb = cross(e.point - bb.pose.pos, e.n);
            let w =
                ba.inv_mass + bb.inv_mass + ba.inv_inertia * rna * rna + bb.inv_inertia * rnb * rnb;
            if !(w > 0.0 && w.is_finite()) {
                continue;
            }
            self.rows.push(Row {
                a,
                b,
                n: e.n,
                rna,
                rnb,
                ja: e.n * ba.inv_mass,
                ka: rna * ba.inv_inertia,
                jb: e.n * bb.inv_mass,
                kb: rnb * bb.inv_inertia,
                w,
                c: r / ((1.0 + r) * w),
                lo: -dt * e.f_n,
                lambda: 0.0,
            });
        }
        self.last_rows = self.rows.len();
        if self.rows.is_empty() {
            return 0.0;
        }
        // 3. The velocities the integrator would reach without the dampers (semi-implicit Euler).
        for (i, b) in bodies.iter().enumerate() {
            if b.is_dynamic() {
                let f = b.force - b.vel * b.damping;
                self.vel[i] = b.vel + f * (dt * b.inv_mass);
                self.omega[i] = b.omega + b.torque * dt * b.inv_inertia;
            } else {
                self.vel[i] = b.vel;
                self.omega[i] = b.omega;
            }
        }
        let ke_star = self.kinetic(bodies);
        // 4. Projected Gauss–Seidel on F = −B_c·v⁺_n, F ≥ −f_n.
        let (vel, omega) = (&mut self.vel, &mut self.omega);
        for _ in 0..sweeps {
            for row in self.rows.iter_mut() {
                let (a, b) = (row.a, row.b);
                let v_rel = (vel[a] - vel[b]).dot(row.n) + omega[a] * row.rna - omega[b] * row.rnb;
                let new = (-row.c * (v_rel - row.w * row.lambda)).max(row.lo);
                let d = new - row.lambda;
                row.lambda = new;
                vel[a] += row.ja * d;
                omega[a] += row.ka * d;
                vel[b] -= row.jb * d;
                omega[b] -= row.kb * d;
            }
        }
        let removed = ke_star - self.kinetic(bodies);
        // 5. The impulses as forces held over the sample.
        let inv_dt = 1.0 / dt;
        for row in &self.rows {
            let f = row.n * (row.lambda * inv_dt);
            let (ta, tb) = (row.rna * row.lambda * inv_dt, row.rnb * row.lambda * inv_dt);
            wrenches[row.a].force += f;
            wrenches[row.a].torque += ta;
            wrenches[row.b].force -= f;
            wrenches[row.b].torque -= tb;
            bodies[row.a].force += f;
            bodies[row.a].torque += ta;
            bodies[row.b].force -= f;
            bodies[row.b].torque -= tb;
        }
        removed
    }

    /// Kinetic energy of the working velocities (J).
    fn kinetic(&self, bodies: &[Body]) -> f64 {
        let mut ke = 0.0;
        for (i, b) in bodies.iter().enumerate() {
            if b.is_dynamic() {
                ke += 0.5
                    * (b.mass * self.vel[i].dot(self.vel[i])
                        + b.inertia * self.omega[i] * self.omega[i]);
            }
        }
        ke
    }
}

/// A Continuous record whose law pushes this sample.
#[inline]
fn is_loaded(e: &VeContact) -> bool {
    e.state == Some(ContactState::Continuous) && e.f_n > 0.0
}
