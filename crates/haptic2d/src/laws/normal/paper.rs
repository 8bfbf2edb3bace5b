//! The paper's continuous-contact law (§5.9): an SEH spring plus damping.

use super::{NormalInput, NormalLaw};

crate::declare_law! {
    /// `F_n,k = max(0, −Kc·d̃_k − Bc·C0,k)` with `d̃_k = 2d_k − 1.5d_{k−1} + 0.5d_{k−2}` (paper eq. 1).
    ///
    /// The clamp keeps the damper from pulling separating bodies together. Collisions faster than `v_c`
    /// are resolved by impulses (§7) before this law applies.
    ///
    /// Outside the wall (`d_k > 0`, no contact record in 2-D) the force is 0: in the 1-D harness the law is
    /// called at every sample, and the damper must not act before contact.
    pub struct PaperLaw as "paper" {
        /// Contact stiffness `Kc` (N/m).
        kc: f64 ["k"] "N/m" NonNegative "contact stiffness Kc",
        /// Contact damping `Bc` (N·s/m).
        bc: f64 ["b"] "N·s/m" NonNegative "contact damping Bc",
    }
    state {
        /// Stored energy `½Kc·δ²` after the last sample (J).
        stored: f64 = 0.0,
    }
    /// A law with stiffness `kc` (N/m) and damping `bc` (N·s/m).
    pub fn new;
}

impl PaperLaw {
    /// 1-D defaults: `Kc = 2000 N/m`, `Bc = 10 N·s/m`.
    pub fn one_d() -> Self {
        Self::new(2000.0, 10.0)
    }
    /// Per-contact defaults for a face on two contacts: `Kc = 1000 N/m`, `Bc = 5 N·s/m`.
    pub fn per_contact() -> Self {
        Self::new(1000.0, 5.0)
    }
    /// The per-contact state: the stored energy of the last sample (J; the lean law slots keep
    /// only this, `contact/lean_law.rs`).
    #[inline(always)]
    pub(crate) fn state(&self) -> f64 {
        self.stored
    }
    /// These parameters with the per-contact state `stored` of [`state`](Self::state).
    #[inline(always)]
    pub(crate) fn with_state(mut self, stored: f64) -> Self {
        self.stored = stored;
        self
    }
    /// True if `other` has bit for bit the same `Kc` and `Bc`, whatever either's state.
    pub(crate) fn same_params(&self, other: &Self) -> bool {
        self.kc.to_bits() == other.kc.to_bits() && self.bc.to_bits() == other.bc.to_bits()
    }
}

impl NormalLaw for PaperLaw {
    fn reset(&mut self) {
        self.stored = 0.0;
    }
    #[inline(always)]
    fn force(&mut self, input: &NormalInput) -> f64 {
        let delta = input.depth();
        self.stored = 0.5 * self.kc * delta * delta;
        if input.d[0] > 0.0 {
            return 0.0;
        }
        (-self.kc * input.seh_distance() - self.bc * input.c0).max(0.0)
    }
    fn stored_energy(&self) -> f64 {
        self.stored
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uses_seh_history_and_clamps() {
        let mut l = PaperLaw::new(1000.0, 0.0);
        let inp = NormalInput {
            d: [-0.001, 0.0005, 0.002],
            hist: 3,
            c0: 0.0,
            dt: 0.002,
            m_eff: 1.0,
        };
        // d̃ = −0.002 − 0.00075 + 0.001 = −0.00175
        assert!((l.force(&inp) - 1.75).abs() < 1e-12);
        let sep = NormalInput { c0: 1.0, ..inp };
        assert_eq!(PaperLaw::new(1000.0, 10.0).force(&sep), 0.0);
    }
}
