//! Classical velocity-threshold Coulomb friction (Karnopp 1985), per VE contact (§4.1).
//!
//! Inside the band `|S0| ≤ v_th` the contact is declared stuck and the friction force cancels this
//! contact's share of the other tangential forces, up to `μs·F_n`; outside it, kinetic Coulomb friction
//! `μk·F_n` opposes the slip velocity. The velocity is not reset on sticking, so a residual
//! `|S0| < v_th` persists below stiction: the creep that this model is shown to have (Fig. 7).

use super::shell::{friction_law, LoadedFriction};
use super::{FrictionInput, FrictionMode};

crate::declare_law! {
    /// Karnopp's classical stick/slip model (§4.1). Stateless apart from the logged mode.
    ///
    /// Needs [`FrictionInput::f_ext_t`]: this contact's share `(t·F_A^nonfric)/n_t` of the non-friction
    /// force on A along `+t` (N); in 1-D, `F_applied/n_contacts`.
    pub struct Karnopp as "friction model 'classical'" {
        /// Stick velocity band `v_th` (m/s).
        v_th: f64 [] "m/s" Positive "stick velocity band",
        /// Static friction coefficient `μs` (dimensionless).
        mu_s: f64 [] "" Positive "static friction coefficient (≥ mu_k)",
        /// Kinetic friction coefficient `μk` (dimensionless).
        mu_k: f64 [] "" Positive "kinetic friction coefficient",
    }
    state {
        /// Stick or slip at the last update.
        mode: FrictionMode = FrictionMode::Stick,
    }
    /// A model with band `v_th` (m/s), `μs` and `μk`.
    pub fn new;
}

impl Karnopp {
    /// Defaults (§4.1): `v_th = 0.01 m/s`, `μs = 0.5`, `μk = 0.45` (the same in 1-D and per 2-D contact).
    pub fn one_d() -> Self {
        Self::new(0.01, 0.5, 0.45)
    }
    /// Per-contact defaults of the 2-D peg: identical to [`Karnopp::one_d`] (the model has no spring or
    /// damper to split between contacts).
    pub fn per_contact() -> Self {
        Self::one_d()
    }
}

friction_law!(Karnopp);

impl LoadedFriction for Karnopp {
    #[inline(always)]
    fn loaded(&mut self, i: &FrictionInput) -> f64 {
        if i.s0.abs() > self.v_th {
            // slip: kinetic Coulomb friction against the slip velocity
            self.mode = FrictionMode::Slip;
            -self.mu_k * i.fn_ * i.s0.signum()
        } else {
            // stick: cancel this contact's share of the other tangential forces, up to μs·F_n
            self.mode = FrictionMode::Stick;
            let lim = self.mu_s * i.fn_;
            -i.f_ext_t.clamp(-lim, lim)
        }
    }

    /// No spring: 0 J.
    fn spring_energy(&self) -> f64 {
        0.0
    }

    /// No anchor: the god-object tracks the projection (§8.3, frictionless tracking).
    fn stick_point(&self, _s: f64) -> Option<f64> {
        None
    }
}
