//! Ellis et al. (1997) sample–estimate–hold wall, with the optional predictor–corrector (§5.5).

use super::spring_wall::{spring_wall, SpringWall};
use super::NormalInput;

crate::declare_law! {
    /// SEH wall: hold `F_w,k = max(0, K·δ̃_k)` with the extrapolated penetration
    /// `δ̃_k = 2δ_k − 1.5δ_{k−1} + 0.5δ_{k−2}` over the coming interval (applied while `δ_k > 0`).
    ///
    /// The history uses the **signed** gap (`δ_j := −d_j` even outside), so at onset the previous samples
    /// are negative penetrations. With fewer than three samples of history `δ̃_k = δ_k`.
    ///
    /// Predictor–corrector option (\[REC\]): `F_w,k = max(0, K·(δ̃_k + δ̄_{k−1} − δ̃^{used}_{k−1}))`, where
    /// `δ̄_{k−1} = (δ_{k−1} + δ_k)/2` is the mean penetration actually seen over the last interval
    /// (clamped penetrations, `δ_j = max(0, −d_j)`) and `δ̃^{used}_{k−1} = F_w,k−1/K` is the estimate that was
    /// actually held at `k−1` (0 if the wall was inactive then).
    pub struct SehLaw as "seh" {
        /// Wall stiffness `K` (N/m).
        k: f64 [] "N/m" NonNegative "wall stiffness",
        /// Use the predictor–corrector term.
        corrector: bool [] "" Switch "predictor–corrector off (0) or on (1)",
    }
    state {
        /// Penetration estimate held at the previous sample, `F_w,k−1/K` (m); 0 when inactive.
        used_prev: f64 = 0.0,
        /// Stored energy `½K·δ²` after the last sample (J).
        stored: f64 = 0.0,
    }
    /// A wall of stiffness `k` (N/m), with or without the corrector.
    pub fn new;
}

impl SehLaw {
    /// 1-D default: `K = 2000 N/m`, no corrector.
    pub fn one_d() -> Self {
        Self::new(2000.0, false)
    }
    /// Per-contact default for a face on two contacts: `K = 1000 N/m`, no corrector.
    pub fn per_contact() -> Self {
        Self::new(1000.0, false)
    }
    /// The same law with the predictor–corrector switched on or off.
    pub fn with_corrector(mut self, corrector: bool) -> Self {
        self.corrector = corrector;
        self
    }
}

spring_wall!(SehLaw, k);

impl SpringWall for SehLaw {
    fn forget(&mut self) {
        self.used_prev = 0.0;
    }
    #[inline(always)]
    fn wall_force(&mut self, delta: f64, input: &NormalInput) -> f64 {
        // Predictor: extrapolated signed penetration over the coming interval.
        let mut estimate = -input.seh_distance();
        // Corrector: add the error of the previous interval's held estimate.
        if self.corrector && input.hist >= 2 {
            let delta_prev = (-input.d[1]).max(0.0);
            let mean_prev = 0.5 * (delta_prev + delta);
            estimate += mean_prev - self.used_prev;
        }
        let f = (self.k * estimate).max(0.0);
        self.used_prev = if self.k > 0.0 { f / self.k } else { 0.0 };
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::normal::NormalLaw;

    fn input(d: [f64; 3]) -> NormalInput {
        NormalInput {
            d,
            hist: 3,
            c0: 0.0,
            dt: 0.002,
            m_eff: 0.5,
        }
    }

    #[test]
    fn predictor_uses_signed_history_and_corrector_adds_last_error() {
        let mut seh = SehLaw::new(1000.0, false);
        // Onset: previous samples outside (positive gaps) enter as negative penetrations.
        // δ̃ = 2·0.001 − 1.5·(−0.001) + 0.5·(−0.003) = 0.002.
        assert!((seh.force(&input([-0.001, 0.001, 0.003])) - 2.0).abs() < 1e-12);
        let mut pc = SehLaw::new(1000.0, true);
        // First active sample: nothing used before, δ̄ = (0 + 0.001)/2 → +0.0005.
        assert!((pc.force(&input([-0.001, 0.001, 0.003])) - 2.5).abs() < 1e-12);
        // Next: δ̃ = 2·0.002 − 1.5·0.001 + 0.5·(−0.001) = 0.002; δ̄ = 0.0015; used 0.0025 → 0.001.
        assert!((pc.force(&input([-0.002, -0.001, 0.001])) - 1.0).abs() < 1e-12);
        // Outside: zero and forget.
        assert_eq!(pc.force(&input([0.001, -0.002, -0.001])), 0.0);
    }
}
