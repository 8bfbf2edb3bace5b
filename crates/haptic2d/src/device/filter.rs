//! Handle velocity estimation (§10.7): backward difference followed by a first-order low-pass,
//! `v̂_k = v̂_{k−1} + α_v·((x_k − x_{k−1})/T − v̂_{k−1})`, `α_v = 1 − exp(−2π·f_v·T)`, applied to
//! `(x, y)` and to the unwrapped `θ`.

use super::linalg::V3;

/// The velocity filter state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VelocityFilter {
    /// Filter coefficient `α_v` (dimensionless), 0.466 for 50 Hz at 500 Hz.
    pub alpha: f64,
    /// Sample period `T` (s).
    pub dt: f64,
    x_prev: V3,
    v: V3,
    initialized: bool,
}

impl VelocityFilter {
    /// A filter with cut-off `cutoff_hz` (Hz) at sample period `dt` (s).
    pub fn new(cutoff_hz: f64, dt: f64) -> Self {
        Self {
            alpha: 1.0 - (-std::f64::consts::TAU * cutoff_hz * dt).exp(),
            dt,
            x_prev: [0.0; 3],
            v: [0.0; 3],
            initialized: false,
        }
    }

    /// Forgets the history; the next sample re-initialises with zero velocity.
    pub fn reset(&mut self) {
        self.initialized = false;
        self.v = [0.0; 3];
    }

    /// Feeds pose `x_k` (m, m, rad with θ unwrapped) and returns `v̂_k` (m/s, m/s, rad/s). The first
    /// sample after construction or [`reset`](Self::reset) returns zero.
    pub fn update(&mut self, x: &V3) -> V3 {
        if !self.initialized {
            self.initialized = true;
            self.x_prev = *x;
            self.v = [0.0; 3];
            return self.v;
        }
        for ((v, xi), xp) in self.v.iter_mut().zip(x).zip(&self.x_prev) {
            let raw = (xi - xp) / self.dt;
            *v += self.alpha * (raw - *v);
        }
        self.x_prev = *x;
        self.v
    }

    /// The current estimate `v̂_k`.
    pub fn velocity(&self) -> V3 {
        self.v
    }
}
