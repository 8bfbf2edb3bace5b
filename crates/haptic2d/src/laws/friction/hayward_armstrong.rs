//! Driftless Dahl friction of Hayward & Armstrong (2000), per VE contact (§2), and Dahl's original model
//! as the test variant with `α ≡ 1`.
//!
//! `z = x − w` is the elastic displacement between the contact point and a virtual adhesion point `w`.
//! Integrated over displacement ("over space, not time"):
//!
//! ```text
//! dz = dx − α(z, dx)·|dx|·z / z_max,        F = k·z + σ1·dz/dt + σ2·ẋ,        F_t = −F
//! ```
//!
//! The adhesion map `α` is 0 while unloading (`sgn dx ≠ sgn z`) and inside the elastic zone
//! `|z| ≤ z_stick`, rises as a half sine from 0 at `z_stick` to 1 at `z_max`, and is 1 beyond. Because the
//! adhesion point does not move in the elastic zone, oscillating loads below `k·z_stick` cause no drift.

use super::shell::{friction_law, LoadedFriction};
use super::{FrictionInput, FrictionMode};

/// Which adhesion map the model uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AdhesionMap {
    /// Hayward–Armstrong: elastic zone, smooth plastic transition, full sliding at `z_max` (default).
    #[default]
    Driftless,
    /// Dahl's model: `α ≡ 1` while loading (the unloading sign rule is kept). Drifts under small
    /// oscillating loads; kept as a test variant (H2, H3).
    Dahl,
}

crate::declare_law! {
    /// Hayward–Armstrong elasto-plastic friction (§2). Parameters are public; the state (`z`) is private.
    ///
    /// Load dependence \[REC\]: `z_max = μk·F_n/k`, `z_stick = r_stick·z_max`; the single force level is
    /// `k·z_max = μk·F_n` (no separate static peak, so `μs` is not a parameter).
    pub struct HaywardArmstrong named (|s: &HaywardArmstrong| if s.is_dahl() { "friction model 'dahl'" } else { "friction model 'hayward-armstrong'" }) {
        /// Presliding stiffness `k` per contact (N/m).
        k: f64 [] "N/m" Positive "bristle stiffness",
        /// Kinetic friction coefficient `μk` (dimensionless); sets `z_max = μk·F_n/k`.
        mu_k: f64 [] "" Positive "kinetic friction coefficient",
        /// Elastic-zone ratio `r_stick = z_stick/z_max` (dimensionless, strictly between 0 and 1).
        r_stick: f64 [] "" OpenUnit "stick fraction of the breakaway strain",
        /// Damping on the elastic rate `dz/dt`, `σ1` (N·s/m).
        sigma1: f64 [] "N·s/m" NonNegative "bristle damping",
        /// Viscous friction on the slip velocity, `σ2` (N·s/m).
        sigma2: f64 [] "N·s/m" NonNegative "viscous friction",
    }
    state {
        /// Adhesion map: Hayward–Armstrong (driftless) or Dahl (`α ≡ 1`).
        pub map: AdhesionMap = AdhesionMap::Driftless,
        /// Elastic displacement `z` (m) after the last update.
        z: f64 = 0.0,
        /// Whether the adhesion point moved at the last update (`α·|Δs| > 0`), reported as `Slip`.
        mode: FrictionMode = FrictionMode::Stick,
    }
    /// A driftless model with stiffness `k` (N/m), `μk`, `r_stick`, `σ1` and `σ2` (N·s/m).
    pub fn new;
}

impl HaywardArmstrong {
    /// 1-D defaults (§2 table): `k = 5000 N/m`, `μk = 0.45`, `r_stick = 0.5`, `σ1 = 10 N·s/m`, `σ2 = 0`.
    pub fn one_d() -> Self {
        Self::new(5000.0, 0.45, 0.5, 10.0, 0.0)
    }
    /// Per-contact defaults of the 4-contact 2-D peg (§2 table): `k = 2500 N/m`, `σ1 = 5 N·s/m`.
    pub fn per_contact() -> Self {
        Self::new(2500.0, 0.45, 0.5, 5.0, 0.0)
    }
    /// The same parameters with Dahl's adhesion map (`α ≡ 1`), the drifting test variant.
    pub fn dahl(self) -> Self {
        Self {
            map: AdhesionMap::Dahl,
            ..self
        }
    }
    /// Whether this is the Dahl variant.
    #[inline]
    pub fn is_dahl(&self) -> bool {
        self.map == AdhesionMap::Dahl
    }
    /// The elastic displacement `z` (m) after the last update.
    #[inline]
    pub fn z(&self) -> f64 {
        self.z
    }
    /// The smooth part of the adhesion map, `α_m(ζ) = ½·sin(π·(ζ − (z_max + z_stick)/2)/(z_max − z_stick)) + ½`,
    /// for `z_stick < ζ < z_max` (m). Rises from 0 at `z_stick` to 1 at `z_max`.
    #[inline]
    pub fn alpha_m(zeta: f64, z_stick: f64, z_max: f64) -> f64 {
        let mid = 0.5 * (z_max + z_stick);
        0.5 * (std::f64::consts::PI * (zeta - mid) / (z_max - z_stick)).sin() + 0.5
    }
    /// The adhesion map `α(z, dx)` for elastic displacement `z` (m), motion `dx` (m or m/s; only its
    /// sign matters) and limit `z_max` (m), with `z_stick = r_stick·z_max`.
    pub fn alpha(&self, z: f64, dx: f64, z_max: f64) -> f64 {
        // Unloading (or no motion, or no strain) is purely elastic.
        if dx == 0.0 || z == 0.0 || dx.signum() != z.signum() {
            return 0.0;
        }
        let zeta = z.abs();
        match self.map {
            AdhesionMap::Dahl => 1.0,
            AdhesionMap::Driftless => {
                let z_stick = self.r_stick * z_max;
                if zeta <= z_stick {
                    0.0
                } else if zeta >= z_max {
                    1.0
                } else {
                    Self::alpha_m(zeta, z_stick, z_max)
                }
            }
        }
    }
}

friction_law!(HaywardArmstrong);

impl LoadedFriction for HaywardArmstrong {
    fn forget(&mut self) {
        self.z = 0.0;
    }

    #[inline(always)]
    fn loaded(&mut self, i: &FrictionInput) -> f64 {
        let z_max = self.mu_k * i.fn_ / self.k;
        self.z = self.z.clamp(-z_max, z_max); // reset if the load dropped
        let z_prev = self.z;
        let alpha = self.alpha(self.z, i.ds, z_max); // sign test uses sgn(Δs_k)
        self.z += i.ds - alpha * i.ds.abs() * self.z / z_max; // explicit step over displacement
        self.z = self.z.clamp(-z_max, z_max); // prevents overshoot for large |Δs|
        self.mode = if alpha * i.ds.abs() > 0.0 {
            FrictionMode::Slip
        } else {
            FrictionMode::Stick
        };
        -(self.k * self.z + self.sigma1 * (self.z - z_prev) / i.dt + self.sigma2 * i.s0)
    }

    /// `½·k·z²` (J), the U_f of §13.2 F7-5.
    fn spring_energy(&self) -> f64 {
        0.5 * self.k * self.z * self.z
    }

    /// The adhesion point `s − z` (§8.3).
    fn stick_point(&self, s: f64) -> Option<f64> {
        Some(s - self.z)
    }
}
