//! Normal contact laws ("virtual walls", §5). All laws clamp `F_n ≥ 0`: walls push, never pull.
//!
//! In 2-D a law runs per VE contact with `δ = −d` and `v_in = −C0`; in the 1-D harness the wall surface is
//! at `x = 0`, `d = x` and `C0 = v`.
//!
//! Calling convention. In 2-D the world calls [`NormalLaw::force`] only while a contact record exists
//! (`d ≤ 0`) and gives each contact a fresh copy of the scene's prototype, so "the first sample after
//! being outside" is the first call after creation or [`NormalLaw::reset`]. In the 1-D harness the law is
//! called at every sample; every law returns 0 while `δ_k = 0` and resets its own entry state there
//! (PI integral, pulse counter, hysteretic blocks).
//!
//! Per-contact halving (§5, §13.1): when a flat face rests on the wall through two vertex contacts, each
//! contact uses half the 1-D stiffness, damping, integral gain and friction levels (`per_contact()`),
//! which reproduces the 1-D numbers (`one_d()`).

mod colgate;
mod hysteretic;
mod impact_offset;
mod massie;
mod minsky;
mod paper;
mod pulse;
mod seh;
mod spring_wall;
mod zoh;

use crate::laws::params::{ParamSpec, Params, TableRow};
pub use colgate::{colgate_margin, ColgateLaw};
pub use hysteretic::{HystereticLaw, SlideElement, BLOCK_STICK_SPEED, MAX_ELEMENTS};
pub use impact_offset::ContactNormal;
pub use massie::MassiePiLaw;
pub use minsky::MinskyLaw;
pub use paper::PaperLaw;
pub use pulse::BrakingPulseLaw;
pub use seh::SehLaw;
pub use zoh::ZohLaw;

/// What a normal law sees at one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NormalInput {
    /// Signed distance history (m): `d[0] = d_k`, `d[1] = d_{k−1}`, `d[2] = d_{k−2}`; negative = penetration.
    pub d: [f64; 3],
    /// How many entries of `d` are valid (1..=3). Laws that need more history fall back as their section says.
    pub hist: u8,
    /// Normal relative velocity `C0` (m/s), positive when separating.
    pub c0: f64,
    /// Sample period `T` (s).
    pub dt: f64,
    /// Effective mass behind the contact (kg), used by the braking pulse (§5.7).
    pub m_eff: f64,
}

impl NormalInput {
    /// Penetration depth `δ_k = max(0, −d_k)` (m).
    #[inline]
    pub fn depth(&self) -> f64 {
        (-self.d[0]).max(0.0)
    }
    /// The SEH estimate `d̃_k = 2d_k − 1.5d_{k−1} + 0.5d_{k−2}` of the signed distance (m), or `d_k`
    /// when fewer than three samples of history exist (§5.5).
    #[inline]
    pub fn seh_distance(&self) -> f64 {
        if self.hist >= 3 {
            2.0 * self.d[0] - 1.5 * self.d[1] + 0.5 * self.d[2]
        } else {
            self.d[0]
        }
    }
}

/// A normal contact law with per-contact state.
pub trait NormalLaw {
    /// Forgets all state (contact released).
    fn reset(&mut self);
    /// The normal force `F_n,k ≥ 0` (N) for this sample; it is held over `[kT, (k+1)T)`.
    fn force(&mut self, input: &NormalInput) -> f64;
    /// Energy stored in the law's springs after the last `force` call (J), for the energy ledger.
    fn stored_energy(&self) -> f64;
}

/// The selectable normal laws. Every variant carries its parameters and its per-contact state, so a
/// contact gets its own copy of the scene's prototype (no allocation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NormalModel {
    /// The paper's law, §5.9: `F_n = max(0, −Kc·d̃ − Bc·C0)` with the SEH estimate `d̃`.
    Paper(PaperLaw),
    /// ZOH pure stiffness, §5.2 (active).
    Zoh(ZohLaw),
    /// Minsky et al. stiffness plus damping, §5.3.
    Minsky(MinskyLaw),
    /// Colgate–Schenkel wall `K·δ + B·Δδ/T`, §5.4 (passive with enough plant damping).
    Colgate(ColgateLaw),
    /// Ellis et al. sample–estimate–hold, §5.5, optionally with the predictor–corrector.
    Seh(SehLaw),
    /// Massie PI wall, §5.6.
    MassiePi(MassiePiLaw),
    /// Salcudean–Vlaar braking pulse, §5.7.
    BrakingPulse(BrakingPulseLaw),
    /// Goldfarb–Wang hysteretic wall, §5.8.
    Hysteretic(HystereticLaw),
}

/// Every name accepted by [`NormalModel::from_name`].
pub const NORMAL_MODEL_NAMES: [&str; 9] = [
    "paper",
    "zoh",
    "minsky",
    "colgate",
    "seh",
    "seh-pc",
    "pi",
    "pulse",
    "hysteretic",
];

/// `$e` with `$l` bound to the law of whichever variant of [`NormalModel`] `$m` holds (the
/// variants listed once).
macro_rules! each_law {
    ($m:expr, $l:ident => $e:expr) => {
        each_law!(@ $m, $l => $e; Paper Zoh Minsky Colgate Seh MassiePi BrakingPulse Hysteretic)
    };
    (@ $m:expr, $l:ident => $e:expr; $($v:ident)+) => {
        match $m {
            $(NormalModel::$v($l) => $e,)+
        }
    };
}

impl NormalModel {
    /// The name used in scene files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            NormalModel::Paper(_) => "paper",
            NormalModel::Zoh(_) => "zoh",
            NormalModel::Minsky(_) => "minsky",
            NormalModel::Colgate(_) => "colgate",
            NormalModel::Seh(l) if l.corrector => "seh-pc",
            NormalModel::Seh(_) => "seh",
            NormalModel::MassiePi(_) => "pi",
            NormalModel::BrakingPulse(_) => "pulse",
            NormalModel::Hysteretic(_) => "hysteretic",
        }
    }

    /// The model called `name` with its spec defaults: the halved per-contact values when
    /// `per_contact` is true (a face on two contacts in 2-D), the 1-D values otherwise.
    pub fn from_name(name: &str, per_contact: bool) -> Result<Self, String> {
        // Law `$l` with its per-contact or its 1-D defaults.
        macro_rules! pick {
            ($l:ident) => {
                if per_contact {
                    $l::per_contact()
                } else {
                    $l::one_d()
                }
            };
        }
        Ok(match name {
            "paper" => NormalModel::Paper(pick!(PaperLaw)),
            "zoh" => NormalModel::Zoh(pick!(ZohLaw)),
            "minsky" => NormalModel::Minsky(pick!(MinskyLaw)),
            "colgate" => NormalModel::Colgate(pick!(ColgateLaw)),
            "seh" | "seh-pc" => NormalModel::Seh(pick!(SehLaw).with_corrector(name == "seh-pc")),
            "pi" => NormalModel::MassiePi(pick!(MassiePiLaw)),
            "pulse" => NormalModel::BrakingPulse(pick!(BrakingPulseLaw)),
            "hysteretic" => NormalModel::Hysteretic(pick!(HystereticLaw)),
            _ => {
                return Err(format!(
                    "unknown normal law `{name}`; valid names: {}",
                    NORMAL_MODEL_NAMES.join(", ")
                ))
            }
        })
    }

    /// Checks every parameter against its declared rule; the error names the law, the parameter,
    /// the rule and the unit.
    pub fn validate(&self) -> Result<(), String> {
        crate::laws::params::validate(self.params())
    }

    /// Sets one parameter by its key or an alias ([`Self::specs`]); the error lists the valid keys.
    /// Call [`NormalModel::validate`] after setting all of them.
    pub fn set_param(&mut self, key: &str, value: f64) -> Result<(), String> {
        crate::laws::params::set(self.params_mut(), key, value)
    }

    /// The law behind this model as its parameter declarations, to set a value.
    fn params_mut(&mut self) -> &mut dyn Params {
        each_law!(self, l => l)
    }

    /// The law behind this model as its parameter declarations: [`Params::get`] reads a value.
    pub fn params(&self) -> &dyn Params {
        each_law!(self, l => l)
    }

    /// This model's parameters, declared once ([`crate::laws::params`]).
    pub fn specs(&self) -> &'static [ParamSpec] {
        self.params().specs()
    }
}

/// The rows of the normal-law table of docs/MODELS.md Part I, with their per-contact defaults.
pub(crate) fn table_rows() -> Vec<TableRow> {
    let row = |names, summary, law: Box<dyn Params>| TableRow {
        names,
        summary,
        law,
        extra_keys: "",
    };
    vec![
        row(&["paper"], "the paper's law, §5.9: `F_n = max(0, −Kc·d̃ − Bc·C0)`, `d̃` the SEH estimate", Box::new(PaperLaw::per_contact())),
        row(&["zoh"], "pure stiffness, zero-order hold (active), §5.2", Box::new(ZohLaw::per_contact())),
        row(&["minsky"], "stiffness + damping, §5.3", Box::new(MinskyLaw::per_contact())),
        row(&["colgate"], "`K·δ + B·Δδ/T`, §5.4 (passive with plant damping `b > KT/2 + \\|B\\|`; that `b` is the body's `damping`)", Box::new(ColgateLaw::per_contact())),
        row(&["seh", "seh-pc"], "Ellis sample–estimate–hold, optionally with the predictor–corrector (`seh-pc` sets `corrector = 1`), §5.5", Box::new(SehLaw::per_contact())),
        row(&["pi"], "Massie PI wall, §5.6", Box::new(MassiePiLaw::per_contact())),
        row(&["pulse"], "Salcudean–Vlaar braking pulse, §5.7", Box::new(BrakingPulseLaw::per_contact())),
        row(&["hysteretic"], "Goldfarb–Wang elasto-slide wall, §5.8", Box::new(HystereticLaw::per_contact())),
    ]
}

impl Default for NormalModel {
    fn default() -> Self {
        NormalModel::Paper(PaperLaw::per_contact())
    }
}

// Every law's `force`, and its dispatch here, are `#[inline(always)]`. The contact set's force
// pass builds the `NormalInput` on the stack; a `force` compiled apart reads it back with loads that
// straddle the caller's stores, a store-forwarding stall (~15 % of a pile step). Inlined, the input stays
// in registers. A plain `#[inline]` hint was not always followed. Behaviour is unchanged.
/// Implements [`NormalLaw`] for an enum whose every variant wraps one law, by forwarding each
/// method to the variant's law (used for [`NormalModel`] and for the contact set's compact slots,
/// `contact/compact_law.rs`, which are the same laws without the hysteretic wall).
macro_rules! normal_law_dispatch {
    ($ty:ident { $($variant:ident),+ $(,)? }) => {
        impl $crate::laws::normal::NormalLaw for $ty {
            fn reset(&mut self) {
                match self {
                    $($ty::$variant(l) => l.reset(),)+
                }
            }
            #[inline(always)]
            fn force(&mut self, input: &$crate::laws::normal::NormalInput) -> f64 {
                match self {
                    $($ty::$variant(l) => l.force(input),)+
                }
            }
            fn stored_energy(&self) -> f64 {
                match self {
                    $($ty::$variant(l) => l.stored_energy(),)+
                }
            }
        }
    };
}
pub(crate) use normal_law_dispatch;

normal_law_dispatch!(NormalModel {
    Paper,
    Zoh,
    Minsky,
    Colgate,
    Seh,
    MassiePi,
    BrakingPulse,
    Hysteretic,
});

#[cfg(test)]
mod tests {
    use super::*;

    fn inside(d: f64, c0: f64) -> NormalInput {
        NormalInput {
            d: [d, d, d],
            hist: 3,
            c0,
            dt: 0.002,
            m_eff: 0.5,
        }
    }

    #[test]
    fn names_round_trip_and_unknown_lists_valid() {
        for name in NORMAL_MODEL_NAMES {
            for per in [false, true] {
                let m = NormalModel::from_name(name, per).expect("known name");
                assert_eq!(m.name(), name);
                assert!(m.validate().is_ok(), "{name} defaults must validate");
            }
        }
        let e = NormalModel::from_name("spring", false).unwrap_err();
        assert!(e.contains("hysteretic") && e.contains("seh-pc"), "{e}");
    }

    #[test]
    fn set_param_and_validate_name_the_parameter() {
        let mut m = NormalModel::from_name("minsky", false).expect("known");
        m.set_param("k", -1.0).expect("known key");
        assert!(m.validate().unwrap_err().contains("`k`"));
        let e = m.set_param("stiffness", 1.0).unwrap_err();
        assert!(e.contains("b_m"), "{e}");
        let mut h = NormalModel::from_name("hysteretic", true).expect("known");
        h.set_param("f2", 0.7).expect("element key");
        h.set_param("m1", -0.1).expect("element key");
        assert!(h.validate().unwrap_err().contains("`m1`"));
        assert!(h.set_param("k9", 1.0).is_err());
        let mut p = NormalModel::from_name("pulse", false).expect("known");
        assert!(p.set_param("n_p", 2.5).is_err());
        p.set_param("n_p", 3.0).expect("integer");
    }

    #[test]
    fn per_contact_halves_one_d() {
        for name in NORMAL_MODEL_NAMES {
            let mut one = NormalModel::from_name(name, false).expect("known");
            let mut per = NormalModel::from_name(name, true).expect("known");
            // Two contacts at the same depth and rate give the 1-D force (no pulse: c0 = 0).
            let f1 = one.force(&inside(-0.001, 0.0));
            let f2 = per.force(&inside(-0.001, 0.0));
            assert!((f1 - 2.0 * f2).abs() < 1e-12, "{name}: {f1} vs 2×{f2}");
        }
    }

    #[test]
    fn every_law_is_zero_outside_and_nonnegative() {
        for name in NORMAL_MODEL_NAMES {
            let mut m = NormalModel::from_name(name, false).expect("known");
            assert_eq!(m.force(&inside(0.001, -0.5)), 0.0, "{name} outside");
            assert!(m.force(&inside(-0.0001, 5.0)) >= 0.0, "{name} clamps");
        }
    }

    #[test]
    fn hysteretic_massless_loading_and_unloading() {
        let mut h = HystereticLaw::one_d();
        let at = |d: f64| inside(-d, 0.0);
        // Elastic below the smallest slip deflection f1/k1 = 1 mm.
        assert!((h.force(&at(0.0005)) - 1.0).abs() < 1e-12);
        // Loading to 4 mm: both blocks slip; F = 1000·0.004 + 0.5 + 1.0.
        assert!((h.force(&at(0.004)) - 5.5).abs() < 1e-12);
        // Unloading to 3 mm: elements relax elastically by 1 mm each: F = 3 + 0 + 0.5.
        assert!((h.force(&at(0.003)) - 3.5).abs() < 1e-12);
        assert!(h.stored_energy() > 0.0);
        h.force(&at(0.0));
        assert_eq!(h.block_positions(), [0.0; MAX_ELEMENTS]);
    }

    #[test]
    fn pulse_latches_entry_speed_once() {
        let mut p = BrakingPulseLaw::one_d();
        let mut inp = inside(-0.0001, -0.4);
        let fb = 1.3 * 0.5 * 0.4 / (5.0 * 0.002);
        for _ in 0..5 {
            assert!((p.force(&inp) - (0.2 + fb)).abs() < 1e-9);
        }
        assert!((p.force(&inp) - 0.2).abs() < 1e-9);
        inp.d[0] = 0.0001;
        assert_eq!(p.force(&inp), 0.0);
        inp.d[0] = -0.0001;
        assert!(p.force(&inp) > 1.0, "pulse re-arms after leaving");
    }

    #[test]
    fn colgate_margin_signs() {
        assert!(colgate_margin(2.4, 2000.0, 0.0, 0.002) > 0.0);
        assert!(colgate_margin(1.0, 2000.0, 0.0, 0.002) < 0.0);
        assert!((colgate_margin(3.0, 2000.0, -0.5, 0.002) - 0.5).abs() < 1e-12);
    }
}
