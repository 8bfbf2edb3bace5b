//! Hand-wrench observers (§10.6): static, inverse dynamics (paper-faithful) and generalized momentum
//! (default). All three estimate the wrench `W_h` (N, N, N·m) that the hand applies to the handle.

use serde::{Deserialize, Serialize};

use super::dynamics::LumpedDynamics;
use super::fault::DeviceFault;
use super::linalg::{jt_mul_v, m3_mul_v, M43, V3, V4};
use super::lowpass::LowPass2;
use super::params::DeviceParams;

/// Which hand-wrench observer to run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ObserverKind {
    /// `Ŵ_h = −J_aᵀ·(τ − τ̂_f)`: valid at low acceleration.
    Static,
    /// `Ŵ_h = M_x·ẍ̂ + c − J_aᵀ·(τ − τ̂_f)`, `ẍ̂` a second backward difference of the pose through a
    /// 2nd-order 30 Hz low-pass.
    InverseDynamics,
    /// Generalized-momentum observer `ṙ = K_O·(W_h − r)` (default): no double differentiation.
    #[default]
    Momentum,
}

/// The hand-wrench observer with the state of all three variants (only the selected one is used).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HandWrenchObserver {
    /// The selected variant.
    pub kind: ObserverKind,
    model: LumpedDynamics,
    dt: f64,
    k_o: V3,
    k: u64,
    // Inverse dynamics: pose history and acceleration filter.
    x1: V3,
    x2: V3,
    accel_lp: LowPass2,
    // Momentum: p_0, the running integral, and the previous sample's drive terms.
    p0: V3,
    integral: V3,
    prev_j: M43,
    prev_qd: V4,
    prev_bias: V3,
    r: V3,
}

impl HandWrenchObserver {
    /// An observer of `kind` for the device `p` at sample period `dt` (s). Fails (naming the field) if
    /// `K_O·T ≥ 1`.
    pub fn new(p: &DeviceParams, kind: ObserverKind, dt: f64) -> Result<Self, String> {
        p.validate_for_period(dt)?;
        Ok(Self {
            kind,
            model: LumpedDynamics::new(p),
            dt,
            k_o: p.observer_gain,
            k: 0,
            x1: [0.0; 3],
            x2: [0.0; 3],
            accel_lp: LowPass2::new(p.accel_cutoff_hz, dt),
            p0: [0.0; 3],
            integral: [0.0; 3],
            prev_j: [[0.0; 3]; 4],
            prev_qd: [0.0; 4],
            prev_bias: [0.0; 3],
            r: [0.0; 3],
        })
    }

    /// Restarts the observer (the next update is sample 0).
    pub fn reset(&mut self) {
        self.k = 0;
        self.accel_lp.reset();
        self.integral = [0.0; 3];
        self.r = [0.0; 3];
    }

    /// The latest estimate `Ŵ_h,k` (N, N, N·m).
    pub fn estimate(&self) -> V3 {
        self.r
    }

    /// One sample (§0.5 step 2): pose `x_k` (θ unwrapped), filtered twist `v̂_k`, and the joint torques
    /// `τ_{k−1}` (N·m) applied during the previous interval (zeros at sample 0). Returns `Ŵ_h,k`.
    ///
    /// The friction estimate is `τ̂_f = f_c·sgn(q̇) + f_v·q̇` at `q̇ = J_a·v̂` (the model's friction).
    pub fn update(&mut self, x: &V3, v: &V3, tau_prev: &V4) -> Result<V3, DeviceFault> {
        self.update_elapsed(x, v, tau_prev, self.dt)
    }

    /// Like [`update`](Self::update) for a sample taken `elapsed` seconds after the previous one (a
    /// late tick; `elapsed == T` is exactly `update`). The momentum observer integrates the held
    /// torques over the measured interval (they were held that long); the inverse-dynamics observer
    /// cannot difference twice over unequal intervals, so it holds its estimate for that sample; the
    /// static observer needs no time.
    pub fn update_elapsed(
        &mut self,
        x: &V3,
        v: &V3,
        tau_prev: &V4,
        elapsed: f64,
    ) -> Result<V3, DeviceFault> {
        let h = if elapsed.is_finite() && elapsed > 0.0 {
            elapsed
        } else {
            self.dt
        };
        let late = h != self.dt;
        let terms = self.model.terms(x, v)?;
        let first = self.k == 0;
        let w = match self.kind {
            ObserverKind::Static => {
                let tf = self.model.joint_friction(&terms.qd);
                let net: V4 = std::array::from_fn(|i| tau_prev[i] - tf[i]);
                jt_mul_v(&terms.j, &net).map(|v| -v)
            }
            ObserverKind::InverseDynamics => {
                let tf = self.model.joint_friction(&terms.qd);
                let net: V4 = std::array::from_fn(|i| tau_prev[i] - tf[i]);
                let drive = jt_mul_v(&terms.j, &net);
                let raw: V3 = if late {
                    // Hold: restart the difference history at this sample.
                    self.x1 = *x;
                    self.x2 = *x;
                    self.prev_j = terms.j;
                    self.prev_qd = terms.qd;
                    self.prev_bias = terms.momentum_bias;
                    self.k += 1;
                    return Ok(self.r);
                } else if self.k >= 2 {
                    let t2 = self.dt * self.dt;
                    std::array::from_fn(|i| (x[i] - 2.0 * self.x1[i] + self.x2[i]) / t2)
                } else {
                    [0.0; 3]
                };
                let acc = self.accel_lp.update(&raw);
                let ma = m3_mul_v(&terms.m, &acc);
                std::array::from_fn(|i| ma[i] + terms.c[i] - drive[i])
            }
            ObserverKind::Momentum => {
                let p = m3_mul_v(&terms.m, v);
                if first {
                    self.p0 = p;
                    self.integral = [0.0; 3];
                    [0.0; 3]
                } else {
                    // Σ T·(J_aᵀ(τ_{j−1} − τ̂_f) + J̇_aᵀD_I J_a ẋ_{j−1} + m_e2 Ȧ_2ᵀA_2 ẋ_{j−1} + r_{j−1}),
                    // every term evaluated at the previous sample.
                    let tf = self.model.joint_friction(&self.prev_qd);
                    let net: V4 = std::array::from_fn(|i| tau_prev[i] - tf[i]);
                    let drive = jt_mul_v(&self.prev_j, &net);
                    let mut r = [0.0; 3];
                    for i in 0..3 {
                        self.integral[i] += h * (drive[i] + self.prev_bias[i] + self.r[i]);
                        r[i] = self.k_o[i] * (p[i] - self.p0[i] - self.integral[i]);
                    }
                    r
                }
            }
        };
        self.prev_j = terms.j;
        self.prev_qd = terms.qd;
        self.prev_bias = terms.momentum_bias;
        self.x2 = self.x1;
        self.x1 = *x;
        self.k += 1;
        self.r = w;
        Ok(w)
    }
}
