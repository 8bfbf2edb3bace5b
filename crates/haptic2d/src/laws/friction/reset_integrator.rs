//! Haessig–Friedland reset-integrator friction (§1), per VE contact: the paper's model (eq. 2).

use super::shell::{friction_law, LoadedFriction};
use super::{FrictionInput, FrictionMode};

crate::law_params! { ResetIntegrator, "friction model 'reset-integrator'";
    kr (self.kr) [] "N/m" Positive "stick stiffness Kr",
    mu_s (self.mu_s) [] "" Positive "static friction coefficient (≥ mu_k)",
    mu_k (self.mu_k) [] "" Positive "kinetic friction coefficient",
    beta (self.beta) [] "N·s/m" NonNegative "stick damping β",
    p0 (self.p0_fixed) [] "m" Positive "fixed strain limit (with load_scaling = \"stiffness\")",
}

/// How Coulomb proportionality to the normal load enters (§1, "Load dependence").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LoadScaling {
    /// Constant `Kr`, strain limit `p0 = μk·F_n/Kr` (default).
    #[default]
    Limit,
    /// Constant strain limit `p0`, stiffness `Kr = μk·F_n/p0`.
    Stiffness,
}

/// The reset integrator: a bounded strain `p` that integrates the relative tangential displacement in
/// stick and is held at `±p0` in slip.
///
/// Stick: `F_f = (1 + a)·Kr·p + β·S0`; slip: `F_f = Kr·p`; the force on A is `F_t = −F_f`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResetIntegrator {
    /// Kinetic strain stiffness `Kr` (N/m); with `LoadScaling::Stiffness` it is recomputed each sample.
    pub kr: f64,
    /// Static friction coefficient `μs`.
    pub mu_s: f64,
    /// Kinetic friction coefficient `μk`.
    pub mu_k: f64,
    /// Stick damping `β` (N·s/m).
    pub beta: f64,
    /// Load scaling option.
    pub scaling: LoadScaling,
    /// Fixed strain limit `p0` (m) used with `LoadScaling::Stiffness`.
    pub p0_fixed: f64,
    /// Strain `p` (m).
    p: f64,
    /// Stiffness used at the last sample (N/m).
    k_used: f64,
    mode: FrictionMode,
}

impl LoadScaling {
    /// The scene-file names of the options.
    pub const NAMES: &'static [&'static str] = &["limit", "stiffness"];
    /// The option's scene-file name.
    pub fn name(&self) -> &'static str {
        match self {
            LoadScaling::Limit => "limit",
            LoadScaling::Stiffness => "stiffness",
        }
    }
    /// Parses a scene-file name (`limit` or `stiffness`); the error lists the valid names.
    pub fn from_name(name: &str) -> Result<Self, String> {
        match name {
            "limit" => Ok(LoadScaling::Limit),
            "stiffness" => Ok(LoadScaling::Stiffness),
            _ => Err(format!(
                "unknown load scaling '{name}'; valid: {}",
                Self::NAMES.join(", ")
            )),
        }
    }
}

impl ResetIntegrator {
    /// A model with `Kr` (N/m), `μs`, `μk` and `β` (N·s/m), load scaling `Limit`.
    pub fn new(kr: f64, mu_s: f64, mu_k: f64, beta: f64) -> Self {
        Self {
            kr,
            mu_s,
            mu_k,
            beta,
            scaling: LoadScaling::Limit,
            p0_fixed: 1e-4,
            p: 0.0,
            k_used: kr,
            mode: FrictionMode::Stick,
        }
    }
    /// 1-D defaults: `Kr = 4000`, `μs = 0.5`, `μk = 0.45`, `β = 20`.
    pub fn one_d() -> Self {
        Self::new(4000.0, 0.5, 0.45, 20.0)
    }
    /// Per-contact defaults of the 4-contact 2-D peg: `Kr = 2000`, `β = 10`.
    pub fn per_contact() -> Self {
        Self::new(2000.0, 0.5, 0.45, 10.0)
    }
    /// The stiction boost `a = μs/μk − 1`.
    #[inline]
    pub fn a(&self) -> f64 {
        self.mu_s / self.mu_k - 1.0
    }
    /// The strain limit `p0` (m) at normal force `fn_` (N): `μk·F_n/Kr` with [`LoadScaling::Limit`],
    /// the fixed `p0` with [`LoadScaling::Stiffness`].
    #[inline]
    pub fn p0(&self, fn_: f64) -> f64 {
        match self.scaling {
            LoadScaling::Limit => self.mu_k * fn_ / self.kr,
            LoadScaling::Stiffness => self.p0_fixed,
        }
    }
    /// The current strain `p` (m).
    #[inline]
    pub fn strain(&self) -> f64 {
        self.p
    }
    /// The per-contact state: strain `p` (m), the stiffness of the last sample (N/m) and the
    /// mode (the lean law slots keep only this, `contact/lean_law.rs`).
    #[inline(always)]
    pub(crate) fn state(&self) -> (f64, f64, FrictionMode) {
        (self.p, self.k_used, self.mode)
    }
    /// These parameters with the per-contact state `(p, k_used, mode)` of [`state`](Self::state).
    #[inline(always)]
    pub(crate) fn with_state(mut self, (p, k_used, mode): (f64, f64, FrictionMode)) -> Self {
        self.p = p;
        self.k_used = k_used;
        self.mode = mode;
        self
    }
    /// True if `other` has bit for bit the same parameters (`Kr`, `μs`, `μk`, `β`, load scaling
    /// and fixed `p0`), whatever either's state.
    pub(crate) fn same_params(&self, other: &Self) -> bool {
        let bits = |m: &Self| [m.kr, m.mu_s, m.mu_k, m.beta, m.p0_fixed].map(f64::to_bits);
        bits(self) == bits(other) && self.scaling == other.scaling
    }
    /// Sets one parameter by its key ([`Self::SPECS`]); the error lists the valid keys. Ranges are
    /// checked by `validate`.
    pub fn set_param(&mut self, key: &str, value: f64) -> Result<(), String> {
        crate::laws::params::set(self, key, value)?;
        self.k_used = self.kr;
        Ok(())
    }
}

friction_law!(ResetIntegrator);

impl LoadedFriction for ResetIntegrator {
    fn forget(&mut self) {
        self.p = 0.0;
    }

    #[inline(always)]
    fn loaded(&mut self, i: &FrictionInput) -> f64 {
        // Load scaling: either the strain limit or the stiffness follows μk·F_n.
        let (kr, p0) = match self.scaling {
            LoadScaling::Limit => (self.kr, self.mu_k * i.fn_ / self.kr),
            LoadScaling::Stiffness => (self.mu_k * i.fn_ / self.p0_fixed, self.p0_fixed),
        };
        self.k_used = kr;
        let a = self.a();
        let p_star = self.p + i.ds; // candidate: integrate the relative displacement
        if i.ds > 0.0 && p_star >= p0 {
            // slip in +t: hold the integrator at the limit
            self.p = p0;
            self.mode = FrictionMode::Slip;
            -kr * self.p
        } else if i.ds < 0.0 && p_star <= -p0 {
            // slip in −t
            self.p = -p0;
            self.mode = FrictionMode::Slip;
            -kr * self.p
        } else {
            // stick; 'reset' if p0 shrank because F_n fell
            self.p = p_star.clamp(-p0, p0);
            self.mode = FrictionMode::Stick;
            -((1.0 + a) * kr * self.p + self.beta * i.s0)
        }
    }

    /// `½(1 + a)·Kr·p²` in stick, `½Kr·p²` in slip (J): the U_f of §13.2 F7-5.
    fn spring_energy(&self) -> f64 {
        let k = match self.mode {
            FrictionMode::Stick => (1.0 + self.a()) * self.k_used,
            FrictionMode::Slip => self.k_used,
        };
        0.5 * k * self.p * self.p
    }

    /// The stick point `s − p` (§8.3).
    fn stick_point(&self, s: f64) -> Option<f64> {
        Some(s - self.p)
    }
}
