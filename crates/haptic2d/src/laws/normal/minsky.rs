//! Minsky et al. (1990): stabilise the wall by adding damping (§5.3, [REC] form).

use super::spring_wall::{spring_wall, SpringWall};
use super::NormalInput;

crate::declare_law! {
    /// `F_w,k = max(0, K·δ_k + B_M·v_in,k)` while `δ_k > 0`, else 0.
    ///
    /// Rule of thumb: `B_M ≥ 2·(K·T/2)`.
    pub struct MinskyLaw as "minsky" {
        /// Wall stiffness `K` (N/m).
        k: f64 [] "N/m" NonNegative "wall stiffness",
        /// Wall damping `B_M` (N·s/m).
        b_m: f64 ["b"] "N·s/m" NonNegative "wall damping",
    }
    state {
        /// Stored energy `½K·δ²` after the last sample (J).
        stored: f64 = 0.0,
    }
    /// A wall of stiffness `k` (N/m) and damping `b_m` (N·s/m).
    pub fn new;
}

impl MinskyLaw {
    /// 1-D defaults: `K = 2000 N/m`, `B_M = 10 N·s/m`.
    pub fn one_d() -> Self {
        Self::new(2000.0, 10.0)
    }
    /// Per-contact defaults for a face on two contacts: `K = 1000 N/m`, `B_M = 5 N·s/m`.
    pub fn per_contact() -> Self {
        Self::new(1000.0, 5.0)
    }
}

spring_wall!(MinskyLaw, k);

impl SpringWall for MinskyLaw {
    #[inline(always)]
    fn wall_force(&mut self, delta: f64, input: &NormalInput) -> f64 {
        let v_in = -input.c0;
        (self.k * delta + self.b_m * v_in).max(0.0)
    }
}
