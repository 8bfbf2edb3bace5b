//! Normal contact laws ("virtual walls", §5). All laws clamp `F_n ≥ 0`: walls push, never pull.
//!
//! In 2-D a law runs per VE contact with `δ = −d` and `v_in = −C0`; in the 1-D harness the wall surface is
//! at `x = 0`, `d = x` and `C0 = v`.

mod paper;

pub use paper::PaperLaw;

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
}

impl NormalModel {
    /// The name used in scene files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            NormalModel::Paper(_) => "paper",
        }
    }
}

impl Default for NormalModel {
    fn default() -> Self {
        NormalModel::Paper(PaperLaw::per_contact())
    }
}

impl NormalLaw for NormalModel {
    fn reset(&mut self) {
        match self {
            NormalModel::Paper(l) => l.reset(),
        }
    }
    fn force(&mut self, input: &NormalInput) -> f64 {
        match self {
            NormalModel::Paper(l) => l.force(input),
        }
    }
    fn stored_energy(&self) -> f64 {
        match self {
            NormalModel::Paper(l) => l.stored_energy(),
        }
    }
}
