//! Friction models per VE contact (§1–§4). Each returns `F_t`, the tangential force on the vertex body A
//! along `+t`; friction opposes the motion of A relative to B.

mod reset_integrator;

pub use reset_integrator::{LoadScaling, ResetIntegrator};

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

/// The selectable friction models. Each variant carries its parameters and per-contact state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum FrictionModel {
    /// No friction.
    #[default]
    None,
    /// Haessig–Friedland reset integrator (§1), the paper's choice.
    ResetIntegrator(ResetIntegrator),
}

impl FrictionModel {
    /// The name used in scene files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            FrictionModel::None => "none",
            FrictionModel::ResetIntegrator(_) => "reset-integrator",
        }
    }
}

impl FrictionLaw for FrictionModel {
    fn reset(&mut self) {
        match self {
            FrictionModel::None => {}
            FrictionModel::ResetIntegrator(m) => m.reset(),
        }
    }
    fn begin(&mut self, s_entry: f64) {
        match self {
            FrictionModel::None => {}
            FrictionModel::ResetIntegrator(m) => m.begin(s_entry),
        }
    }
    fn update(&mut self, input: &FrictionInput) -> f64 {
        match self {
            FrictionModel::None => 0.0,
            FrictionModel::ResetIntegrator(m) => m.update(input),
        }
    }
    fn stored_energy(&self) -> f64 {
        match self {
            FrictionModel::None => 0.0,
            FrictionModel::ResetIntegrator(m) => m.stored_energy(),
        }
    }
    fn anchor(&self, s: f64) -> Option<f64> {
        match self {
            FrictionModel::None => None,
            FrictionModel::ResetIntegrator(m) => m.anchor(s),
        }
    }
    fn mode(&self) -> FrictionMode {
        match self {
            FrictionModel::None => FrictionMode::Slip,
            FrictionModel::ResetIntegrator(m) => m.mode(),
        }
    }
}
