//! Finger-pad friction after Nahvi, Hollerbach, Freier & Nelson (1998), per VE contact (§3) [REC].
//!
//! A compliant pad joins the vertex (the "bone") to an anchor `s_a` on the edge (the skin–surface patch).
//! With deflection `u = s − s_a` and pad stiffness `k_pad = k_p0 + k_p1·F_n`:
//!
//! - stick: the anchor is fixed and `F_t = −(k_pad·u + b_pad·S0)`;
//! - stick → slip when `k_pad·|u| > μs·F_n`;
//! - slip: the anchor is dragged so that `|u| = μk·F_n/k_pad`, and `F_t = −k_pad·u`;
//! - slip → stick when the pad force falls below `μk·F_n` (the vertex reverses relative to the anchor).
//!
//! The static/kinetic gap is a hysteretic threshold on one spring, not a stiffness boost as in §1.

use super::shell::{engage, friction_law, LoadedFriction};
use super::{FrictionInput, FrictionMode};

crate::declare_law! {
    /// Nahvi finger-pad friction (§3). Parameters are public; the state (`s_a`, mode) is private.
    pub struct FingerPad as "friction model 'nahvi'" {
        /// Pad tangential stiffness at zero load, `k_p0` (N/m).
        k_p0: f64 [] "N/m" Positive "pad stiffness at zero load",
        /// Load stiffening `k_p1` (1/m): `k_pad = k_p0 + k_p1·F_n`.
        k_p1: f64 [] "1/m" NonNegative "load stiffening",
        /// Pad damping in stick, `b_pad` (N·s/m).
        b_pad: f64 [] "N·s/m" NonNegative "pad damping",
        /// Static friction coefficient `μs` (dimensionless).
        mu_s: f64 [] "" Positive "static friction coefficient (≥ mu_k)",
        /// Kinetic friction coefficient `μk` (dimensionless).
        mu_k: f64 [] "" Positive "kinetic friction coefficient",
    }
    state {
        /// Anchor edge coordinate `s_a` (m, in the edge body's frame).
        s_a: f64 = 0.0,
        /// Whether `s_a` holds a valid anchor; if not, the next loaded update anchors at the current `s`.
        engaged: bool = false,
        /// Stick or slip.
        mode: FrictionMode = FrictionMode::Stick,
        /// Pad stiffness used at the last update (N/m).
        k_used: f64 = k_p0,
        /// Deflection `u` after the last update (m).
        u: f64 = 0.0,
    }
    /// A model with every parameter given: `k_p0` (N/m), `k_p1` (1/m), `b_pad` (N·s/m), `μs`, `μk`.
    fn with_params;
}

impl FingerPad {
    /// A linear-pad model (`k_p1 = 0`) with stiffness `k_p0` (N/m), damping `b_pad` (N·s/m), `μs`, `μk`.
    pub fn new(k_p0: f64, b_pad: f64, mu_s: f64, mu_k: f64) -> Self {
        Self::with_params(k_p0, 0.0, b_pad, mu_s, mu_k)
    }
    /// 1-D defaults (§3 table): `k_p0 = 4000 N/m`, `k_p1 = 0`, `b_pad = 10 N·s/m`, `μs = 0.5`, `μk = 0.45`.
    pub fn one_d() -> Self {
        Self::new(4000.0, 10.0, 0.5, 0.45)
    }
    /// Per-contact defaults of the 4-contact 2-D peg (§3 table): `k_p0 = 2000 N/m`, `b_pad = 5 N·s/m`.
    pub fn per_contact() -> Self {
        Self::new(2000.0, 5.0, 0.5, 0.45)
    }
    /// The pad stiffness `k_pad = k_p0 + k_p1·F_n` (N/m) at normal force `fn_` (N).
    #[inline]
    pub fn k_pad(&self, fn_: f64) -> f64 {
        self.k_p0 + self.k_p1 * fn_
    }
    /// The deflection `u = s − s_a` (m) after the last update.
    #[inline]
    pub fn deflection(&self) -> f64 {
        self.u
    }
}

friction_law!(FingerPad);

impl LoadedFriction for FingerPad {
    fn forget(&mut self) {
        self.engaged = false;
        self.u = 0.0;
    }

    /// Anchors the pad at the god-object's entry point, so `u ≈ 0` at first contact.
    fn start(&mut self, s_entry: f64) {
        engage(&mut self.s_a, &mut self.engaged, &mut self.mode, s_entry);
    }

    #[inline(always)]
    fn loaded(&mut self, i: &FrictionInput) -> f64 {
        // Loaded again after a release (or never begun): anchor where the vertex is now.
        engage(&mut self.s_a, &mut self.engaged, &mut self.mode, i.s);
        let k = self.k_pad(i.fn_);
        self.k_used = k;
        let mut u = i.s - self.s_a;
        if self.mode == FrictionMode::Stick && k * u.abs() > self.mu_s * i.fn_ {
            self.mode = FrictionMode::Slip;
        }
        if self.mode == FrictionMode::Slip {
            if k * u.abs() >= self.mu_k * i.fn_ {
                // Drag the anchor so that the pad force is exactly the kinetic level.
                self.s_a = i.s - u.signum() * self.mu_k * i.fn_ / k;
                u = i.s - self.s_a;
                self.u = u;
                return -k * u;
            }
            self.mode = FrictionMode::Stick;
        }
        self.u = u;
        -(k * u + self.b_pad * i.s0)
    }

    /// `½·k_pad·u²` (J), the U_f of §13.2 F7-5.
    fn spring_energy(&self) -> f64 {
        0.5 * self.k_used * self.u * self.u
    }

    /// The pad anchor `s_a` (§8.3), once engaged.
    fn stick_point(&self, _s: f64) -> Option<f64> {
        self.engaged.then_some(self.s_a)
    }
}
