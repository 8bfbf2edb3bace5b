//! The stiffest spring and damper a law puts on a body, for the minimum-mass rule (§6.4).

use super::friction::{FrictionModel, LoadScaling};
use super::normal::NormalModel;

impl NormalModel {
    /// Per-contact stiffness `K` (N/m) and damping `B` (N·s/m) the law presents while loading.
    pub fn stiffness_damping(&self) -> (f64, f64) {
        match self {
            NormalModel::Paper(l) => (l.kc, l.bc),
            NormalModel::Zoh(l) => (l.k, 0.0),
            NormalModel::Minsky(l) => (l.k, l.b_m),
            NormalModel::Colgate(l) => (l.k, l.b.abs()),
            NormalModel::Seh(l) => (l.k, 0.0),
            NormalModel::MassiePi(l) => (l.k, 0.0),
            NormalModel::BrakingPulse(l) => (l.k, 0.0),
            NormalModel::Hysteretic(l) => (l.k0 + l.elements.iter().map(|e| e.k).sum::<f64>(), 0.0),
        }
    }
}

impl FrictionModel {
    /// Per-contact stick stiffness (N/m) and damping (N·s/m) of the model (0 where it has none, or where
    /// it depends on the normal load).
    pub fn stiffness_damping(&self) -> (f64, f64) {
        match self {
            FrictionModel::None | FrictionModel::Karnopp(_) => (0.0, 0.0),
            FrictionModel::ResetIntegrator(m) => match m.scaling {
                LoadScaling::Limit => ((1.0 + m.a()) * m.kr, m.beta),
                LoadScaling::Stiffness => (0.0, m.beta),
            },
            FrictionModel::HaywardArmstrong(m) => (m.k, m.sigma1 + m.sigma2),
            FrictionModel::FingerPad(m) => (m.k_p0, m.b_pad),
            FrictionModel::SalcudeanVlaar(m) => (m.k_p, m.k_d + m.b_v),
        }
    }
}
