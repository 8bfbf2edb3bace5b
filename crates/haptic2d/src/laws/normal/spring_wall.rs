//! The shell shared by the spring walls (every normal law but the paper's and the hysteretic):
//! the energy ledger's `½K·δ²` and the zero force outside the wall, written once.

use super::NormalInput;

/// A wall whose stored energy is its spring's `½K·δ_k²` and whose force is 0 while `δ_k = 0`.
/// [`spring_wall!`] implements [`NormalLaw`](super::NormalLaw) from it: every sample records the
/// energy; outside it calls [`outside`](Self::outside) and returns 0, inside it returns
/// [`wall_force`](Self::wall_force); `reset` calls [`forget`](Self::forget) and zeroes the energy.
pub(crate) trait SpringWall {
    /// Forgets the law's own state (contact released). Default: the law has none.
    fn forget(&mut self) {}
    /// What the law forgets at a sample outside the wall. Default: [`forget`](Self::forget).
    fn outside(&mut self) {
        self.forget();
    }
    /// The force `F_n,k ≥ 0` (N) at penetration `delta = δ_k > 0` (m).
    fn wall_force(&mut self, delta: f64, input: &NormalInput) -> f64;
}

/// Implements [`NormalLaw`](super::NormalLaw) for a [`SpringWall`] `$ty` whose stiffness `K`
/// (N/m) is the field `$k` and whose stored energy (J) is the field `stored`.
macro_rules! spring_wall {
    ($ty:ident, $k:ident) => {
        impl $crate::laws::normal::NormalLaw for $ty {
            fn reset(&mut self) {
                $crate::laws::normal::spring_wall::SpringWall::forget(self);
                self.stored = 0.0;
            }
            #[inline(always)]
            fn force(&mut self, input: &$crate::laws::normal::NormalInput) -> f64 {
                use $crate::laws::normal::spring_wall::SpringWall as _;
                let delta = input.depth();
                self.stored = 0.5 * self.$k * delta * delta;
                if delta <= 0.0 {
                    self.outside();
                    return 0.0;
                }
                self.wall_force(delta, input)
            }
            fn stored_energy(&self) -> f64 {
                self.stored
            }
        }
    };
}
pub(crate) use spring_wall;
