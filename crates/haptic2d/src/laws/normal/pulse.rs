//! Salcudean–Vlaar braking pulse on wall entry (§5.7, [REC] sizing).

use super::spring_wall::{spring_wall, SpringWall};
use super::NormalInput;

crate::declare_law! {
    /// Spring `K·δ_k` plus, for the first `N_p` samples inside, a braking pulse
    /// `F_b = (1 + e_b)·m_eff·v_c / (N_p·T)` sized to reverse the latched entry speed `v_c` to `e_b·v_c`.
    ///
    /// On the first sample with `δ_k > 0` after being outside (in 2-D: the first call after creation or
    /// reset), the law latches `v_c = max(0, v_in,k)` and `m_eff` from [`NormalInput::m_eff`]. The counter
    /// resets when `δ = 0`.
    pub struct BrakingPulseLaw as "pulse" {
        /// Wall stiffness `K` (N/m).
        k: f64 [] "N/m" NonNegative "wall stiffness",
        /// Pulse restitution target `e_b` (dimensionless, ≥ 0).
        e_b: f64 [] "" NonNegative "pulse restitution",
        /// Pulse length `N_p` (samples, ≥ 1).
        n_p: u32 [] "samples" Count "pulse length",
    }
    state {
        /// Inside the wall at the previous call.
        inside: bool = false,
        /// Samples of the pulse already applied.
        count: u32 = 0,
        /// Latched pulse force `F_b` (N).
        pulse: f64 = 0.0,
        /// Stored energy `½K·δ²` after the last sample (J).
        stored: f64 = 0.0,
    }
    /// A wall of stiffness `k` (N/m) with pulse restitution `e_b` and length `n_p` samples.
    pub fn new;
}

impl BrakingPulseLaw {
    /// 1-D defaults: `K = 2000 N/m`, `e_b = 0.3`, `N_p = 5` (10 ms at 500 Hz).
    pub fn one_d() -> Self {
        Self::new(2000.0, 0.3, 5)
    }
    /// Per-contact defaults: `K = 1000 N/m`, `e_b = 0.3`, `N_p = 5`; the world splits `m_eff` among
    /// the contacts that start in the same sample.
    pub fn per_contact() -> Self {
        Self::new(1000.0, 0.3, 5)
    }
}

spring_wall!(BrakingPulseLaw, k);

impl SpringWall for BrakingPulseLaw {
    fn forget(&mut self) {
        self.outside();
        self.pulse = 0.0;
    }
    /// Leaving the wall re-arms the pulse (the latched `F_b` is replaced at the next entry).
    fn outside(&mut self) {
        self.inside = false;
        self.count = 0;
    }
    #[inline(always)]
    fn wall_force(&mut self, delta: f64, input: &NormalInput) -> f64 {
        if !self.inside {
            // First sample inside: latch the entry speed and size the pulse.
            self.inside = true;
            self.count = 0;
            let v_c = (-input.c0).max(0.0);
            let m_eff = input.m_eff.max(0.0);
            self.pulse = (1.0 + self.e_b) * m_eff * v_c / (self.n_p as f64 * input.dt);
        }
        let mut f = self.k * delta;
        if self.count < self.n_p {
            f += self.pulse;
            self.count += 1;
        }
        f.max(0.0)
    }
}
