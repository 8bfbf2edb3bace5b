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

impl NormalModel {
    /// The depth (m) at which the law holds a constant force `f` (N) on one contact at rest:
    /// `f/K` for a spring; for the hysteretic law the depth where the parallel spring and the
    /// elements (each saturating at its block friction) together carry `f`, `k0·δ + Σ min(k_i·δ,
    /// f_i) = f`; infinite where the law cannot hold it.
    pub fn static_depth(&self, f: f64) -> f64 {
        match self {
            NormalModel::Hysteretic(l) => {
                let g =
                    |d: f64| l.k0 * d + l.elements.iter().map(|e| (e.k * d).min(e.f)).sum::<f64>();
                let mut hi = 1e-6;
                while g(hi) < f {
                    hi *= 2.0;
                    if hi > 1e6 {
                        return f64::INFINITY;
                    }
                }
                let mut lo = 0.0;
                for _ in 0..100 {
                    let m = 0.5 * (lo + hi);
                    if g(m) < f {
                        lo = m
                    } else {
                        hi = m
                    }
                }
                hi
            }
            _ => {
                let k = self.stiffness_damping().0;
                if k > 0.0 {
                    f / k
                } else {
                    f64::INFINITY
                }
            }
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
