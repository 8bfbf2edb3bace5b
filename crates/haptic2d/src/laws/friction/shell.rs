//! The shell shared by the friction models: no force and a forgotten state while the contact
//! carries no load, stick after a reset, the reported mode; written once.

use super::{FrictionInput, FrictionMode};

/// A friction model with a `mode` field (stick or slip after the last update) whose force is 0,
/// and whose state is forgotten, while `F_n ≤ 0`. [`friction_law!`] implements
/// [`FrictionLaw`](super::FrictionLaw) from it: `reset` sets the mode to stick and calls
/// [`forget`](Self::forget); `update` resets and returns 0 while unloaded, else returns
/// [`loaded`](Self::loaded); `begin`, `stored_energy` and `anchor` are [`start`](Self::start),
/// [`spring_energy`](Self::spring_energy) and [`stick_point`](Self::stick_point).
pub(crate) trait LoadedFriction {
    /// Forgets the model's state besides its mode. Default: the model has none.
    fn forget(&mut self) {}
    /// Starts a new contact whose god-object entry point is at edge coordinate `s_entry` (m), after
    /// the reset. Default: nothing more.
    fn start(&mut self, s_entry: f64) {
        let _ = s_entry;
    }
    /// The friction force `F_t` (N) on A along `+t` at a sample with `F_n > 0`.
    fn loaded(&mut self, input: &FrictionInput) -> f64;
    /// Energy stored in the model's springs after the last update (J).
    fn spring_energy(&self) -> f64;
    /// The stick anchor edge coordinate (m) given the current `s`, if the model has one (§8.3).
    fn stick_point(&self, s: f64) -> Option<f64>;
}

/// Sets a stick anchor (the pad's or the stick spring's) at edge coordinate `s` (m), in stick,
/// unless it is `engaged` already: at a contact's entry point, or where the vertex is when the
/// contact is loaded again after a release.
#[inline(always)]
pub(crate) fn engage(s_a: &mut f64, engaged: &mut bool, mode: &mut FrictionMode, s: f64) {
    if !*engaged {
        *s_a = s;
        *engaged = true;
        *mode = FrictionMode::Stick;
    }
}

/// Implements [`FrictionLaw`](super::FrictionLaw) for a [`LoadedFriction`] `$ty` with a field
/// `mode: FrictionMode`. A sample with `F_n ≤ 0` or a NaN `F_n` is unloaded.
macro_rules! friction_law {
    ($ty:ident) => {
        impl $crate::laws::friction::FrictionLaw for $ty {
            fn reset(&mut self) {
                self.mode = $crate::laws::friction::FrictionMode::Stick;
                $crate::laws::friction::shell::LoadedFriction::forget(self);
            }
            fn begin(&mut self, s_entry: f64) {
                self.reset();
                $crate::laws::friction::shell::LoadedFriction::start(self, s_entry);
            }
            #[inline(always)]
            fn update(&mut self, input: &$crate::laws::friction::FrictionInput) -> f64 {
                // Loaded only when `F_n > 0`: a NaN load (a world about to be stopped as
                // diverged) is no load, rather than a panic in the models' clamps.
                if input.fn_ > 0.0 {
                    return $crate::laws::friction::shell::LoadedFriction::loaded(self, input);
                }
                self.reset();
                0.0
            }
            fn stored_energy(&self) -> f64 {
                $crate::laws::friction::shell::LoadedFriction::spring_energy(self)
            }
            fn anchor(&self, s: f64) -> Option<f64> {
                $crate::laws::friction::shell::LoadedFriction::stick_point(self, s)
            }
            fn mode(&self) -> $crate::laws::friction::FrictionMode {
                self.mode
            }
        }
    };
}
pub(crate) use friction_law;

#[cfg(test)]
mod tests {
    use crate::laws::friction::{FrictionInput, FrictionLaw, FrictionModel};

    fn input(fn_: f64) -> FrictionInput {
        FrictionInput {
            ds: 1e-4,
            s: 0.01,
            s0: 0.1,
            fn_,
            dt: 1e-3,
            f_ext_t: 0.5,
        }
    }

    #[test]
    fn a_nan_normal_force_unloads_every_friction_model_instead_of_panicking() {
        for name in FrictionModel::NAMES {
            for per_contact in [false, true] {
                let mut m = FrictionModel::from_name(name, per_contact).unwrap();
                m.begin(0.0);
                let loaded = m.update(&input(2.0));
                assert!(loaded.is_finite(), "{name}: {loaded}");
                assert_eq!(m.update(&input(f64::NAN)), 0.0, "{name}");
                assert_eq!(m.stored_energy(), 0.0, "{name}: the state is forgotten");
            }
        }
    }
}
