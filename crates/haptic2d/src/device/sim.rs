//! A simulated twin-pantograph plant: integrates the lumped dynamics (§10.6) with RK4 sub-steps under
//! held motor torques, joint friction and a hand model, and reports quantised encoder angles.

use super::dynamics::LumpedDynamics;
use super::encoder::Encoder;
use super::fault::DeviceFault;
use super::hand::HandModel;
use super::linalg::{dot3, jt_mul_v, m3_mul_v, solve3, V3, V4};
use super::params::DeviceParams;

/// Simulated device state and settings. State is kept in handle coordinates `(x, ẋ)`; joint angles
/// follow by inverse kinematics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimDevice {
    /// The plant model (joint friction `f_c`, `f_v` included; set them to zero for a frictionless plant).
    pub model: LumpedDynamics,
    /// The encoders used to quantise the reported joint angles.
    pub encoder: Encoder,
    /// Whether [`SimDevice::encoders`] quantises (default true).
    pub quantize: bool,
    /// RK4 sub-steps per tick (default 10).
    pub substeps: u32,
    x: V3,
    xd: V3,
    t: f64,
}

impl SimDevice {
    /// A plant for device `p` at rest at pose `x0` (m, m, rad). Validates `p` and the pose.
    pub fn new(p: &DeviceParams, x0: V3) -> Result<Self, String> {
        p.validate()?;
        let model = LumpedDynamics::new(p);
        model
            .kin
            .configuration(&x0)
            .map_err(|e| format!("simulated device initial pose {x0:?}: {e}"))?;
        Ok(Self {
            model,
            encoder: Encoder::new(p.encoder_counts, p.n_g),
            quantize: true,
            substeps: 10,
            x: x0,
            xd: [0.0; 3],
            t: 0.0,
        })
    }

    /// Sets pose (m, m, rad) and twist (m/s, m/s, rad/s).
    pub fn set_state(&mut self, x: V3, xd: V3) {
        self.x = x;
        self.xd = xd;
    }

    /// True handle pose (m, m, rad, θ unwrapped).
    pub fn pose(&self) -> V3 {
        self.x
    }

    /// True handle twist (m/s, m/s, rad/s).
    pub fn velocity(&self) -> V3 {
        self.xd
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Kinetic energy `½ẋᵀM_xẋ` (J).
    pub fn kinetic_energy(&self) -> Result<f64, DeviceFault> {
        self.model.kinetic_energy(&self.x, &self.xd)
    }

    /// The encoder reading (rad), quantised when [`SimDevice::quantize`] is set.
    pub fn encoders(&self) -> Result<V4, DeviceFault> {
        let q = self.model.kin.ik(&self.x)?;
        Ok(if self.quantize {
            q.map(|v| self.encoder.quantize(v))
        } else {
            q
        })
    }

    /// Handle acceleration `ẍ = M_x⁻¹·(J_aᵀ(τ − τ_f) + W_h − c)` at state `(x, xd)` and time `t`.
    fn accel(
        &self,
        x: &V3,
        xd: &V3,
        t: f64,
        tau: &V4,
        hand: &HandModel,
    ) -> Result<V3, DeviceFault> {
        let terms = self.model.terms(x, xd)?;
        let tf = self.model.joint_friction(&terms.qd);
        let net: V4 = std::array::from_fn(|i| tau[i] - tf[i]);
        let drive = jt_mul_v(&terms.j, &net);
        let wh = hand.wrench(x, xd, t);
        let rhs: V3 = std::array::from_fn(|i| drive[i] + wh[i] - terms.c[i]);
        solve3(&terms.m, &rhs).ok_or(DeviceFault::Singular)
    }

    /// Advances one tick of `dt` (s) with motor torques `tau` (N·m) held, joint friction and the hand
    /// wrench of `hand` (re-evaluated at every RK4 stage), then returns the encoder reading (rad).
    pub fn step(&mut self, tau: &V4, hand: &HandModel, dt: f64) -> Result<V4, DeviceFault> {
        if !tau.iter().all(|v| v.is_finite()) {
            return Err(DeviceFault::NonFinite);
        }
        let n = self.substeps.max(1);
        let h = dt / n as f64;
        let add = |a: &V3, b: &V3, s: f64| -> V3 { std::array::from_fn(|i| a[i] + s * b[i]) };
        for _ in 0..n {
            let (x, v, t) = (self.x, self.xd, self.t);
            let k1x = v;
            let k1v = self.accel(&x, &v, t, tau, hand)?;
            let x2 = add(&x, &k1x, 0.5 * h);
            let v2 = add(&v, &k1v, 0.5 * h);
            let k2v = self.accel(&x2, &v2, t + 0.5 * h, tau, hand)?;
            let x3 = add(&x, &v2, 0.5 * h);
            let v3 = add(&v, &k2v, 0.5 * h);
            let k3v = self.accel(&x3, &v3, t + 0.5 * h, tau, hand)?;
            let x4 = add(&x, &v3, h);
            let v4 = add(&v, &k3v, h);
            let k4v = self.accel(&x4, &v4, t + h, tau, hand)?;
            self.x = std::array::from_fn(|i| {
                x[i] + h / 6.0 * (k1x[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i])
            });
            self.xd = std::array::from_fn(|i| {
                v[i] + h / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i])
            });
            self.t += h;
        }
        self.encoders()
    }

    /// Power `ẋ·W` (W) that `wrench` would deliver at the current twist (for energy checks).
    pub fn power(&self, wrench: &V3) -> f64 {
        dot3(&self.xd, wrench)
    }

    /// Generalized momentum `M_x·ẋ` (kg·m/s, kg·m/s, kg·m²/s) at the current state.
    pub fn momentum(&self) -> Result<V3, DeviceFault> {
        let terms = self.model.terms(&self.x, &self.xd)?;
        Ok(m3_mul_v(&terms.m, &self.xd))
    }
}
