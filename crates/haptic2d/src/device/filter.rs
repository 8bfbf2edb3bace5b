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
        self.update_elapsed(x, self.dt)
    }

    /// Like [`update`](Self::update), for a sample taken `elapsed` seconds after the previous one
    /// (a late tick): the difference is divided by the measured interval and the filter coefficient
    /// is that of the interval, `α = 1 − exp(−2π·f_v·elapsed)`, so a handle moving steadily reads the
    /// same speed whether the tick came on time or late. `elapsed == T` is exactly [`update`](Self::update); a
    /// non-finite or non-positive `elapsed` is taken as `T`.
    pub fn update_elapsed(&mut self, x: &V3, elapsed: f64) -> V3 {
        if !self.initialized {
            self.initialized = true;
            self.x_prev = *x;
            self.v = [0.0; 3];
            return self.v;
        }
        let (h, alpha) = if elapsed == self.dt || !(elapsed.is_finite() && elapsed > 0.0) {
            (self.dt, self.alpha)
        } else {
            // α_v = 1 − exp(−2π f_v T) with T → elapsed: the cut-off f_v = −ln(1 − α)/(2π T).
            let f_v = -(1.0 - self.alpha).ln() / (std::f64::consts::TAU * self.dt);
            (
                elapsed,
                1.0 - (-std::f64::consts::TAU * f_v * elapsed).exp(),
            )
        };
        for ((v, xi), xp) in self.v.iter_mut().zip(x).zip(&self.x_prev) {
            let raw = (xi - xp) / h;
            *v += alpha * (raw - *v);
        }
        self.x_prev = *x;
        self.v
    }

    /// The current estimate `v̂_k`.
    pub fn velocity(&self) -> V3 {
        self.v
    }
}
