//! The optional passivity guard (§6.5): per body, if the mechanical energy exceeds the initial energy plus
//! the work put in, scale the twist back and count the event.

use crate::body::Body;

/// Per-body energy-bounding guard. Off by default; with the semi-implicit integrator it can only trigger
/// through a bug or round-off, because §6.2 guarantees `E_{k+1} ≤ E_0 + W_in,k`.
#[derive(Clone, Debug, Default)]
pub struct PassivityGuard {
    /// Tolerance `ε_E` (J).
    pub epsilon: f64,
    /// Per body: `E_0 + W_in` so far (J).
    budget: Vec<f64>,
    /// Number of samples at which the guard scaled a twist.
    pub triggers: u64,
}

impl PassivityGuard {
    /// A guard with tolerance `epsilon` (J) for `bodies`.
    pub fn new(epsilon: f64, bodies: &[Body]) -> Self {
        Self {
            epsilon,
            budget: bodies.iter().map(|b| b.kinetic_energy()).collect(),
            triggers: 0,
        }
    }
    /// Adds energy `w` (J) put into body `i` during this sample (work of every force on it, and the
    /// kinetic-energy change of any impulse).
    #[inline]
    pub fn add_input(&mut self, i: usize, w: f64) {
        self.budget[i] += w;
    }
    /// Checks body `i` after integration; scales its twist if it holds more energy than its budget.
    /// Returns true if it triggered.
    pub fn check(&mut self, i: usize, body: &mut Body) -> bool {
        let e = body.kinetic_energy();
        let budget = self.budget[i].max(0.0);
        if e > budget + self.epsilon {
            let s = (budget / e).sqrt();
            body.vel *= s;
            body.omega *= s;
            self.budget[i] = body.kinetic_energy();
            self.triggers += 1;
            true
        } else {
            false
        }
    }
}
