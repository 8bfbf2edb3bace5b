//! Colgate & Schenkel (1997) wall and passivity condition (§5.4).

use super::spring_wall::{spring_wall, SpringWall};
use super::NormalInput;

/// Signed Colgate passivity margin `b − (K·T/2 + |B|)` (N·s/m): the sampled wall
/// `F = K·δ_k + B·(δ_k − δ_{k−1})/T` on a device with physical damping `b` (N·s/m) at period `t` (s)
/// is passive when the margin is positive.
///
/// `b` is the *plant* damping (device or body damping), not part of the law.
pub fn colgate_margin(b: f64, k: f64, bw: f64, t: f64) -> f64 {
    b - (k * t / 2.0 + bw.abs())
}

crate::declare_law! {
    /// `F_w,k = max(0, K·δ_k + B·(δ_k − δ_{k−1})/T)` while `δ_k > 0`, else 0.
    ///
    /// `δ_{k−1} = max(0, −d_{k−1})`; with no history the difference term is zero. The plant damping `b`
    /// that makes this wall passive ([`colgate_margin`]) belongs to the harness (1-D) or the body (2-D).
    pub struct ColgateLaw as "colgate" {
        /// Wall stiffness `K` (N/m).
        k: f64 [] "N/m" NonNegative "wall stiffness",
        /// Virtual damping `B` (N·s/m), applied to the backward-difference penetration rate.
        b: f64 [] "N·s/m" Finite "virtual damping (may be negative: the condition uses |B|)",
    }
    state {
        /// Stored energy `½K·δ²` after the last sample (J).
        stored: f64 = 0.0,
    }
    /// A wall of stiffness `k` (N/m) and virtual damping `b` (N·s/m).
    pub fn new;
}

impl ColgateLaw {
    /// 1-D (Fig. 4) defaults: `K = 2000 N/m`, `B = 0`.
    pub fn one_d() -> Self {
        Self::new(2000.0, 0.0)
    }
    /// Per-contact defaults for a face on two contacts: `K = 1000 N/m`, `B = 0`.
    pub fn per_contact() -> Self {
        Self::new(1000.0, 0.0)
    }
}

spring_wall!(ColgateLaw, k);

impl SpringWall for ColgateLaw {
    #[inline(always)]
    fn wall_force(&mut self, delta: f64, input: &NormalInput) -> f64 {
        let delta_prev = if input.hist >= 2 {
            (-input.d[1]).max(0.0)
        } else {
            delta
        };
        (self.k * delta + self.b * (delta - delta_prev) / input.dt).max(0.0)
    }
}
