//! Applied loads: constant forces and torques, the unidirectional sinusoid of §13.2, and body forces.

use crate::body::Body;
use crate::geom::Vec2;

/// The time profile of a load.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Profile {
    /// Constant, from `t = 0`.
    Constant,
    /// The unidirectional sinusoid `(1 − cos 2πft)/2` (§13.2), frequency `f` in Hz: it rises from 0 to 1
    /// and back every period, never changing sign.
    UnidirectionalSine {
        /// Frequency (Hz).
        frequency: f64,
    },
}

impl Profile {
    /// The profile's factor at time `t` (s).
    #[inline]
    pub fn factor(&self, t: f64) -> f64 {
        match *self {
            Profile::Constant => 1.0,
            Profile::UnidirectionalSine { frequency } => {
                0.5 * (1.0 - (std::f64::consts::TAU * frequency * t).cos())
            }
        }
    }
}

/// An external load on one body, applied at its centre of mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Load {
    /// Index of the loaded body.
    pub body: usize,
    /// Peak force (N) in world coordinates.
    pub force: Vec2,
    /// Peak torque (N·m).
    pub torque: f64,
    /// Force per unit mass (m/s², e.g. gravity), multiplied by the body's mass.
    pub per_mass: bool,
    /// Time profile.
    pub profile: Profile,
}

impl Load {
    /// The force (N) and torque (N·m) of this load on `body` at time `t` (s).
    #[inline]
    pub fn wrench(&self, body: &Body, t: f64) -> (Vec2, f64) {
        let k = self.profile.factor(t);
        let f = if self.per_mass {
            self.force * body.mass
        } else {
            self.force
        };
        (f * k, self.torque * k)
    }
}
