//! One integration step of a rigid body under forces held over the sample (§6.2, §5.1).

use crate::body::Body;

/// How a world advances its bodies between samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IntegrationMode {
    /// Semi-implicit (symplectic) Euler on every DOF: `v⁺ = v + T·F/m`, `x⁺ = x + T·v⁺`.
    /// Passive: it dissipates `T²F²/(2m)` per step (§6.2). The normative choice ("VE mode").
    #[default]
    SemiImplicit,
    /// Exact integration of the body under the held force (and plant damping) over the sample: a
    /// lossless mass, used by the wall-comparison harnesses (§5.1, "exact-ZOH mode").
    ExactZoh,
    /// Explicit Euler: `x⁺ = x + T·v`, `v⁺ = v + T·F/m`. Active; kept for comparisons (W9) only.
    ExplicitEuler,
}

/// The minimum simulated mass (kg) for which a semi-implicit mass on a spring `k` (N/m) and damper `b`
/// (N·s/m), sampled at `dt` (s), is stable: `m > k·T²/4 + b·T/2` (§6.4).
///
/// Derivation: the closed loop has the characteristic polynomial `λ² − (2 − a − b')λ + (1 − b')` with
/// `a = kT²/m`, `b' = bT/m`; Jury's conditions give `0 < b' < 2` and `a + 2b' < 4`.
pub fn min_mass(k: f64, b: f64, dt: f64) -> f64 {
    k * dt * dt / 4.0 + b * dt / 2.0
}

/// Advances one DOF of mass `m` under force `f` and plant damping `b` over `dt` exactly (§5.1).
/// Returns `(Δx, v⁺)`.
#[inline]
fn exact_zoh_dof(v: f64, f: f64, m: f64, b: f64, dt: f64) -> (f64, f64) {
    if b > 0.0 {
        let v_inf = f / b;
        let lam = (-b * dt / m).exp();
        let dx = v_inf * dt + (v - v_inf) * (m / b) * (1.0 - lam);
        (dx, v_inf + (v - v_inf) * lam)
    } else {
        (dt * v + 0.5 * dt * dt * f / m, v + dt * f / m)
    }
}

/// Advances a dynamic body by one sample under its accumulated `force`/`torque` (held over the sample)
/// and its plant `damping`. Fixed bodies are left alone. The angle stays unwrapped.
pub fn integrate_body(body: &mut Body, dt: f64, mode: IntegrationMode) {
    if !body.is_dynamic() {
        return;
    }
    match mode {
        IntegrationMode::SemiImplicit => {
            let f = body.force - body.vel * body.damping;
            body.vel += f * (dt * body.inv_mass);
            body.omega += body.torque * dt * body.inv_inertia;
            body.pose.pos += body.vel * dt;
            body.pose.angle += body.omega * dt;
        }
        IntegrationMode::ExplicitEuler => {
            let f = body.force - body.vel * body.damping;
            body.pose.pos += body.vel * dt;
            body.pose.angle += body.omega * dt;
            body.vel += f * (dt * body.inv_mass);
            body.omega += body.torque * dt * body.inv_inertia;
        }
        IntegrationMode::ExactZoh => {
            let (dx, vx) = exact_zoh_dof(body.vel.x, body.force.x, body.mass, body.damping, dt);
            let (dy, vy) = exact_zoh_dof(body.vel.y, body.force.y, body.mass, body.damping, dt);
            let (dth, w) = exact_zoh_dof(body.omega, body.torque, body.inertia, 0.0, dt);
            body.pose.pos.x += dx;
            body.pose.pos.y += dy;
            body.pose.angle += dth;
            body.vel.x = vx;
            body.vel.y = vy;
            body.omega = w;
        }
    }
}
