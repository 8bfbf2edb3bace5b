//! Impedance (virtual-coupling) controller, the baseline of §11.2 (Colgate et al. 1995; Adams &
//! Hannaford 1999): a spring–damper between device and virtual object with equal and opposite forces,
//!
//! ```text
//! f_cm = K_vc·(x_s − x_m) + B_vc·(v_s − v_m);    f_cs = −f_cm
//! ```
//!
//! (four-channel equivalent `C1 = C_s`, `C4 = −C_m`, `C2 = C3 = 0`). θ errors are wrapped.

use serde::{Deserialize, Serialize};

use super::four_channel::{check_min_mass, pose_error, TeleopSignals};
use crate::device::linalg::V3;

/// Virtual-coupling gains per DOF (x, y, θ).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CouplingGains {
    /// Coupling stiffness `K_vc` (N/m, N/m, N·m/rad). Default (500, 500, 1.0); the θ value is not in
    /// the spec and follows `K_m`.
    pub k: V3,
    /// Coupling damping `B_vc` (N·s/m, N·s/m, N·m·s/rad). Default (5, 5, 0.01); θ follows `B_m`.
    pub b: V3,
}

impl Default for CouplingGains {
    fn default() -> Self {
        Self {
            k: [500.0, 500.0, 1.0],
            b: [5.0, 5.0, 0.01],
        }
    }
}

/// The virtual-coupling controller (stateless apart from its gains).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VirtualCoupling {
    /// Gains.
    pub gains: CouplingGains,
}

impl VirtualCoupling {
    /// A coupling with `gains`; every gain must be finite and ≥ 0 (the error names the field).
    pub fn new(gains: CouplingGains) -> Result<Self, String> {
        for (name, v) in [("k", &gains.k), ("b", &gains.b)] {
            for (i, x) in v.iter().enumerate() {
                if !(x.is_finite() && *x >= 0.0) {
                    return Err(format!(
                        "coupling.{name}[{i}] must be a finite number >= 0 (got {x})"
                    ));
                }
            }
        }
        Ok(Self { gains })
    }

    /// §6.4 check of the coupling on a slave of generalized mass `mass` (kg, kg, kg·m²) at period `dt`.
    pub fn check_slave_mass(&self, mass: &V3, dt: f64) -> Result<(), String> {
        check_min_mass("coupling k/b", &self.gains.k, &self.gains.b, mass, dt)
    }

    /// One sample: returns `(f_cm, f_cs)` (N, N, N·m). Only poses and twists are used; the force
    /// channels `f_h`, `f_e` are ignored (`C2 = C3 = 0`).
    pub fn step(&mut self, s: &TeleopSignals) -> (V3, V3) {
        let e = pose_error(&s.x_s, &s.x_m);
        let f_cm: V3 = std::array::from_fn(|i| {
            self.gains.k[i] * e[i] + self.gains.b[i] * (s.v_s[i] - s.v_m[i])
        });
        (f_cm, f_cm.map(|v| -v))
    }
}
