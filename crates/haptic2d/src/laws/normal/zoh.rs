//! ZOH pure stiffness, the "active" wall (§5.2).

use super::spring_wall::{spring_wall, SpringWall};
use super::NormalInput;

crate::law_params! { ZohLaw, "zoh";
    k (self.k) [] "N/m" NonNegative "wall stiffness",
}

/// `F_w,k = K·δ_k`, held over the sample.
///
/// Energy \[DER\]: the held force is `Kδ_k` but the spring energy changes as if the force were the
/// average `K(δ_k + δ_{k+1})/2`, so the wall returns `½K(δ_{k+1} − δ_k)²` more energy than it absorbed
/// every sample: it is active.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZohLaw {
    /// Wall stiffness `K` (N/m).
    pub k: f64,
    /// Stored energy `½K·δ²` after the last sample (J).
    stored: f64,
}

impl ZohLaw {
    /// A wall of stiffness `k` (N/m).
    pub fn new(k: f64) -> Self {
        Self { k, stored: 0.0 }
    }
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
