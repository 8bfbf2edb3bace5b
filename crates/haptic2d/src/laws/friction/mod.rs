//! Friction models per VE contact (§1–§4). Each returns `F_t`, the tangential force on the vertex body A
//! along `+t`; friction opposes the motion of A relative to B.

mod finger_pad;
mod hayward_armstrong;
mod karnopp;
mod reset_integrator;
mod salcudean_vlaar;
mod shell;

use crate::laws::params::{ParamSpec, Params, TableRow};
pub use finger_pad::FingerPad;
pub use hayward_armstrong::{AdhesionMap, HaywardArmstrong};
pub use karnopp::Karnopp;
pub use reset_integrator::{LoadScaling, ResetIntegrator};
pub use salcudean_vlaar::SalcudeanVlaar;

/// What a friction model sees at one sample (after the normal force of the same sample is known).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrictionInput {
    /// Tangential displacement increment `Δs_k = s^B_k − s^B_{k−1}` (m), measured in the edge body's frame.
    pub ds: f64,
    /// Edge coordinate `s^B_k` of the vertex, in the edge body's frame (m).
    pub s: f64,
    /// Tangential slip velocity `S0 = t·v_rel` (m/s).
    pub s0: f64,
    /// Normal force `F_n,k` of this contact at this sample (N).
    pub fn_: f64,
    /// Sample period `T` (s).
    pub dt: f64,
    /// Share of the non-friction force on A along `+t` (N); used by the classical model (§4.1).
    pub f_ext_t: f64,
}

/// Stick or slip, as reported by a model (for logging and display).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FrictionMode {
    /// The contact sticks (or presliding).
    #[default]
    Stick,
    /// The contact slides.
    Slip,
}

/// A friction model with per-contact state.
pub trait FrictionLaw {
    /// Forgets all state (contact released or created).
    fn reset(&mut self);
    /// Starts a new contact whose god-object entry point is at edge coordinate `s_entry` (m).
    fn begin(&mut self, s_entry: f64) {
        let _ = s_entry;
        self.reset();
    }
    /// The friction force `F_t` (N) on A along `+t` for this sample.
    fn update(&mut self, input: &FrictionInput) -> f64;
    /// Energy stored in the model's springs after the last update (J).
    fn stored_energy(&self) -> f64;
    /// The stick anchor (god-object) edge coordinate (m) given the current `s`, if the model has one (§8.3).
    fn anchor(&self, s: f64) -> Option<f64>;
    /// Stick or slip after the last update.
    fn mode(&self) -> FrictionMode;
}

/// The selectable friction models. Each variant carries its parameters and per-contact state, so a
/// contact gets its own copy of the scene's prototype (no allocation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum FrictionModel {
    /// No friction.
    #[default]
    None,
    /// Haessig–Friedland reset integrator (§1), the paper's choice.
    ResetIntegrator(ResetIntegrator),
    /// Hayward–Armstrong driftless model (§2), or Dahl's model when its map is [`AdhesionMap::Dahl`].
    HaywardArmstrong(HaywardArmstrong),
    /// Nahvi et al. finger-pad model (§3).
    FingerPad(FingerPad),
    /// Classical velocity-threshold Coulomb model of Karnopp (§4.1).
    Karnopp(Karnopp),
    /// Salcudean–Vlaar modified Karnopp model (§4.2).
    SalcudeanVlaar(SalcudeanVlaar),
}

/// `$e` on the model of whichever variant `$self` holds, bound as `$m`; `$n` for no friction.
macro_rules! dispatch {
    ($self:ident, $m:ident => $e:expr, none => $n:expr) => {
        match $self {
            FrictionModel::None => $n,
            FrictionModel::ResetIntegrator($m) => $e,
            FrictionModel::HaywardArmstrong($m) => $e,
            FrictionModel::FingerPad($m) => $e,
            FrictionModel::Karnopp($m) => $e,
            FrictionModel::SalcudeanVlaar($m) => $e,
        }
    };
}

impl FrictionModel {
    /// All names accepted by [`FrictionModel::from_name`], in spec order.
    pub const NAMES: &'static [&'static str] = &[
        "none",
        "reset-integrator",
        "hayward-armstrong",
        "dahl",
        "nahvi",
        "classical",
        "salcudean-vlaar",
    ];

    /// The name used in scene files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            FrictionModel::None => "none",
            FrictionModel::ResetIntegrator(_) => "reset-integrator",
            FrictionModel::HaywardArmstrong(m) if m.is_dahl() => "dahl",
            FrictionModel::HaywardArmstrong(_) => "hayward-armstrong",
            FrictionModel::FingerPad(_) => "nahvi",
            FrictionModel::Karnopp(_) => "classical",
            FrictionModel::SalcudeanVlaar(_) => "salcudean-vlaar",
        }
    }

    /// The model called `name` (see [`FrictionModel::NAMES`]) with its default parameters: the 2-D
    /// per-contact values of the spec tables when `per_contact` is true (the 4-contact peg), the 1-D
    /// values otherwise. The error lists the valid names.
    pub fn from_name(name: &str, per_contact: bool) -> Result<Self, String> {
        fn pick<T>(per_contact: bool, one_d: T, per: T) -> T {
            if per_contact {
                per
            } else {
                one_d
            }
        }
        Ok(match name {
            "none" => FrictionModel::None,
            "reset-integrator" => FrictionModel::ResetIntegrator(pick(
                per_contact,
                ResetIntegrator::one_d(),
                ResetIntegrator::per_contact(),
            )),
            "hayward-armstrong" => FrictionModel::HaywardArmstrong(pick(
                per_contact,
                HaywardArmstrong::one_d(),
                HaywardArmstrong::per_contact(),
            )),
            "dahl" => FrictionModel::HaywardArmstrong(
                pick(
                    per_contact,
                    HaywardArmstrong::one_d(),
                    HaywardArmstrong::per_contact(),
                )
                .dahl(),
            ),
            "nahvi" => FrictionModel::FingerPad(pick(
                per_contact,
                FingerPad::one_d(),
                FingerPad::per_contact(),
            )),
            "classical" => {
                FrictionModel::Karnopp(pick(per_contact, Karnopp::one_d(), Karnopp::per_contact()))
            }
            "salcudean-vlaar" => FrictionModel::SalcudeanVlaar(pick(
                per_contact,
                SalcudeanVlaar::one_d(),
                SalcudeanVlaar::per_contact(),
            )),
            _ => {
                return Err(format!(
                    "unknown friction model '{name}'; valid: {}",
                    Self::NAMES.join(", ")
                ))
            }
        })
    }

    /// The model behind this variant as its parameter declarations, to set a value (`None` for
    /// the frictionless model, which has none).
    fn params_mut(&mut self) -> Option<&mut dyn Params> {
        dispatch!(self, m => Some(m), none => None)
    }

    /// The model behind this variant as its parameter declarations: [`Params::get`] reads a value.
    pub fn params(&self) -> &dyn Params {
        dispatch!(self, m => m, none => &Frictionless)
    }

    /// This model's parameters, declared once ([`crate::laws::params`]).
    pub fn specs(&self) -> &'static [ParamSpec] {
        self.params().specs()
    }

    /// Sets one parameter by its scene-file key ([`Self::specs`]; docs/MODELS.md Part I lists them
    /// per model). The error names the model and lists its valid keys; a non-finite value is
    /// refused. Ranges are checked by [`FrictionModel::validate`].
    pub fn set_param(&mut self, key: &str, value: f64) -> Result<(), String> {
        if !value.is_finite() {
            return Err(format!(
                "parameter '{key}' of friction model '{}' must be a finite number, got {value}",
                self.name()
            ));
        }
        if let FrictionModel::ResetIntegrator(m) = self {
            // Its set_param also moves the stiffness in use with `kr`.
            return m.set_param(key, value);
        }
        match self.params_mut() {
            Some(p) => crate::laws::params::set(p, key, value),
            None => Err(format!(
                "friction model 'none' has no parameters (got '{key}')"
            )),
        }
    }

    /// Sets the reset integrator's load scaling (§1); an error for every other model.
    pub fn set_load_scaling(&mut self, scaling: LoadScaling) -> Result<(), String> {
        match self {
            FrictionModel::ResetIntegrator(m) => {
                m.scaling = scaling;
                Ok(())
            }
            _ => Err(format!(
                "load_scaling applies only to friction model 'reset-integrator', not '{}'",
                self.name()
            )),
        }
    }

    /// Checks the parameters; the error names the model and the offending parameter.
    pub fn validate(&self) -> Result<(), String> {
        let p = self.params();
        crate::laws::params::validate(p)?;
        if p.specs().iter().any(|s| s.key == "mu_s") {
            let (mu_s, mu_k) = (p.get("mu_s"), p.get("mu_k"));
            if mu_s < mu_k {
                return Err(format!(
                    "{}: mu_s must be at least mu_k (static ≥ kinetic), got mu_s = {mu_s} < mu_k = {mu_k}",
                    p.law_name()
                ));
            }
        }
        Ok(())
    }

    /// Whether the model reads [`FrictionInput::f_ext_t`] (only the classical model, §4.1); the world
    /// may skip computing it otherwise.
    pub fn uses_external_force(&self) -> bool {
        matches!(self, FrictionModel::Karnopp(_))
    }
}

// Every law's `update`, and its dispatch here, are `#[inline(always)]`. The contact set's force
// pass builds the `FrictionInput` on the stack; a `update` compiled apart reads it back with loads that
// straddle the caller's stores, a store-forwarding stall (~2 % of a pile step). Inlined, the input stays
// in registers. A plain `#[inline]` hint was not always followed. Behaviour is unchanged.
impl FrictionLaw for FrictionModel {
    fn reset(&mut self) {
        dispatch!(self, m => m.reset(), none => ())
    }
    fn begin(&mut self, s_entry: f64) {
        dispatch!(self, m => m.begin(s_entry), none => ())
    }
    #[inline(always)]
    fn update(&mut self, input: &FrictionInput) -> f64 {
        dispatch!(self, m => m.update(input), none => 0.0)
    }
    #[inline]
    fn stored_energy(&self) -> f64 {
        dispatch!(self, m => m.stored_energy(), none => 0.0)
    }
    #[inline]
    fn anchor(&self, s: f64) -> Option<f64> {
        dispatch!(self, m => m.anchor(s), none => None)
    }
    fn mode(&self) -> FrictionMode {
        dispatch!(self, m => m.mode(), none => FrictionMode::Slip)
    }
}

/// A stand-in for the frictionless row of the MODELS table: no parameters.
struct Frictionless;

impl Params for Frictionless {
    fn law_name(&self) -> &'static str {
        "friction model 'none'"
    }
    fn specs(&self) -> &'static [ParamSpec] {
        &[]
    }
    fn get(&self, _key: &str) -> f64 {
        f64::NAN
    }
    fn put(&mut self, _key: &str, _value: f64) {}
}

/// The rows of the friction-model table of docs/MODELS.md Part I, with their per-contact defaults.
pub(crate) fn table_rows() -> Vec<TableRow> {
    let row = |names, summary, law: Box<dyn Params>, extra_keys| TableRow {
        names,
        summary,
        law,
        extra_keys,
    };
    vec![
        row(&["none"], "frictionless", Box::new(Frictionless), ""),
        row(
            &["reset-integrator"],
            "Haessig–Friedland reset integrator (the paper's choice), §1",
            Box::new(ResetIntegrator::per_contact()),
            "`load_scaling` (`\"limit\"`, default, or `\"stiffness\"`: then `p0` is used)",
        ),
        row(
            &["hayward-armstrong"],
            "driftless Dahl (elasto-plastic), §2",
            Box::new(HaywardArmstrong::per_contact()),
            "",
        ),
        row(
            &["dahl"],
            "plain Dahl (α ≡ 1) for comparison, §2",
            Box::new(HaywardArmstrong::per_contact().dahl()),
            "",
        ),
        row(
            &["nahvi"],
            "finger-pad model, §3",
            Box::new(FingerPad::per_contact()),
            "",
        ),
        row(
            &["classical"],
            "Karnopp velocity threshold, §4.1",
            Box::new(Karnopp::per_contact()),
            "",
        ),
        row(
            &["salcudean-vlaar"],
            "modified Karnopp with PD stick, §4.2",
            Box::new(SalcudeanVlaar::per_contact()),
            "",
        ),
    ]
}
