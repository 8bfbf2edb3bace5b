//! ZOH pure stiffness, the "active" wall (§5.2).

use super::spring_wall::{spring_wall, SpringWall};
use super::NormalInput;

crate::declare_law! {
    /// `F_w,k = K·δ_k`, held over the sample.
    ///
    /// Energy \[DER\]: the held force is `Kδ_k` but the spring energy changes as if the force were the
    /// average `K(δ_k + δ_{k+1})/2`, so the wall returns `½K(δ_{k+1} − δ_k)²` more energy than it absorbed
    /// every sample: it is active.
    pub struct ZohLaw as "zoh" {
        /// Wall stiffness `K` (N/m).
        k: f64 [] "N/m" NonNegative "wall stiffness",
    }
    state {
        /// Stored energy `½K·δ²` after the last sample (J).
        stored: f64 = 0.0,
    }
    /// A wall of stiffness `k` (N/m).
    pub fn new;
}

impl ZohLaw {
    /// 1-D default: `K = 2000 N/m`.
    pub fn one_d() -> Self {
        Self::new(2000.0)
    }
    /// Per-contact default for a face on two contacts: `K = 1000 N/m`.
    pub fn per_contact() -> Self {
        Self::new(1000.0)
    }
}

spring_wall!(ZohLaw, k);

impl SpringWall for ZohLaw {
    #[inline(always)]
    fn wall_force(&mut self, delta: f64, _input: &NormalInput) -> f64 {
        (self.k * delta).max(0.0)
    }
}
