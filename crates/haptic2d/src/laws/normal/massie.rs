//! Massie PI wall (PHANToM rendering, §5.6, [REC] form).

use super::spring_wall::{spring_wall, SpringWall};
use super::NormalInput;

crate::declare_law! {
    /// While `δ_k > 0`: `I_k = I_{k−1} + T·δ_k`, `F_w,k = max(0, K·δ_k + K_I·I_k)`; at `δ_k = 0` the
    /// integral resets. Optional anti-windup clamps `0 ≤ I_k ≤ I_max`.
    ///
    /// The integral removes the steady-state penetration under a constant push, but its phase lag makes
    /// the wall strongly active.
    pub struct MassiePiLaw as "pi" {
        /// Proportional stiffness `K` (N/m).
        k: f64 [] "N/m" NonNegative "proportional stiffness",
        /// Integral gain `K_I` (N/(m·s)).
        k_i: f64 [] "N/(m·s)" NonNegative "integral gain",
        /// Anti-windup bound `I_max` (m·s); `f64::INFINITY` disables it.
        i_max: f64 [] "m·s" NonNegativeOrInfinite "anti-windup bound",
    }
    state {
        /// Integral of penetration `I_k` (m·s).
        integral: f64 = 0.0,
        /// Stored energy `½K·δ²` after the last sample (J).
        stored: f64 = 0.0,
    }
    /// A PI wall with gains `k` (N/m), `k_i` (N/(m·s)) and anti-windup bound `i_max` (m·s).
    pub fn new;
}

impl MassiePiLaw {
    /// 1-D defaults: `K = 2000 N/m`, `K_I = 2×10⁴ N/(m·s)`, `I_max = ∞`.
    pub fn one_d() -> Self {
        Self::new(2000.0, 2.0e4, f64::INFINITY)
    }
    /// Per-contact defaults for a face on two contacts: `K = 1000 N/m`, `K_I = 10⁴ N/(m·s)`, `I_max = ∞`.
    pub fn per_contact() -> Self {
        Self::new(1000.0, 1.0e4, f64::INFINITY)
    }
    /// The current integral state `I_k` (m·s).
    pub fn integral(&self) -> f64 {
        self.integral
    }
}

spring_wall!(MassiePiLaw, k);

impl SpringWall for MassiePiLaw {
    fn forget(&mut self) {
        self.integral = 0.0;
    }
    #[inline(always)]
    fn wall_force(&mut self, delta: f64, input: &NormalInput) -> f64 {
        self.integral = (self.integral + input.dt * delta).clamp(0.0, self.i_max);
        (self.k * delta + self.k_i * self.integral).max(0.0)
    }
}
