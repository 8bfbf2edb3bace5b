//! Second-order Butterworth low-pass (bilinear transform with pre-warping), per channel of a 3-vector.
//! Used on backward-difference accelerations (30 Hz) by the inverse-dynamics observer (§10.6) and the
//! acceleration feedforwards of the four-channel controller (§11.1).

use super::linalg::V3;

/// A biquad low-pass `y = (b0 + b1 z⁻¹ + b2 z⁻²)/(1 + a1 z⁻¹ + a2 z⁻²)·u` on three channels, unit DC
/// gain, Butterworth (`Q = 1/√2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LowPass2 {
    b: [f64; 3],
    a: [f64; 2],
    u1: V3,
    u2: V3,
    y1: V3,
    y2: V3,
}

impl LowPass2 {
    /// A filter with cut-off `cutoff_hz` (Hz) at sample period `dt` (s). The cut-off is clamped below
    /// Nyquist.
    pub fn new(cutoff_hz: f64, dt: f64) -> Self {
        let fc = cutoff_hz.min(0.45 / dt);
        let k = (std::f64::consts::PI * fc * dt).tan();
        let q = std::f64::consts::FRAC_1_SQRT_2;
        let norm = 1.0 / (1.0 + k / q + k * k);
        let b0 = k * k * norm;
        Self {
            b: [b0, 2.0 * b0, b0],
            a: [2.0 * (k * k - 1.0) * norm, (1.0 - k / q + k * k) * norm],
            u1: [0.0; 3],
            u2: [0.0; 3],
            y1: [0.0; 3],
            y2: [0.0; 3],
        }
    }

    /// Clears the state (output restarts from zero).
    pub fn reset(&mut self) {
        self.u1 = [0.0; 3];
        self.u2 = [0.0; 3];
        self.y1 = [0.0; 3];
        self.y2 = [0.0; 3];
    }

    /// Filters one sample `u` and returns the output.
    pub fn update(&mut self, u: &V3) -> V3 {
        let mut y = [0.0; 3];
        for i in 0..3 {
            y[i] = self.b[0] * u[i] + self.b[1] * self.u1[i] + self.b[2] * self.u2[i]
                - self.a[0] * self.y1[i]
                - self.a[1] * self.y2[i];
        }
        self.u2 = self.u1;
        self.u1 = *u;
        self.y2 = self.y1;
        self.y1 = y;
        y
    }
}
