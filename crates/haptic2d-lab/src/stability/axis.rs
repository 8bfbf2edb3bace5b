//! The 1-DOF linear model of one axis of the haptic loop (x, y or θ), in world units, in continuous
//! time and as the sampled-data loop the tick actually runs.
//!
//! **Plant (master).** The handle's lumped inertia `m` and physical damping `b` (joint viscous friction
//! reflected to the handle), with an optional hand modelled as a spring–damper `(K_h, B_h)` to a fixed
//! target (the simulated hands of `haptic2d::device::HandModel`; the hand is massless there):
//!
//! ```text
//! m·v̇_m = f_cm − b·v_m + f_h,        f_h = −K_h·x_m − B_h·v_m   (0 when released)
//! ```
//!
//! **Slave and environment.** The virtual body `M_s` in contact with the scene's stiffest contact,
//! linearised as a spring–damper `(K_e, B_e)` to ground: `f_e = K_e·x_s + B_e·v_s` and
//! `M_s·v̇_s = f_cs − f_e`.
//!
//! **Controller**, in the general linear form that covers both §11 architectures
//! (`e = x_s − x_m`, `ė = v_s − v̂_m`, `r` the hand-wrench estimate):
//!
//! ```text
//! f_cm =  k_m·e + b_m·ė + g_mh·r + g_me·f_e − d_m·v̂_m
//! f_cs = −k_s·e − b_s·ė + g_sh·r + g_se·f_e − d_s·v_s
//! ```
//!
//! Four-channel (§11.1): `g_mh = C6`, `g_me = −(1 + C6)`, `g_sh = 1 + C5`, `g_se = −C5`, and `d_m` the
//! master damping injection, `d_s` the slave damping injection (`C2`, `C3` overrides replace
//! `−g_me`, `g_sh`). Virtual coupling (§11.2): `k_m = k_s = K_vc`, `b_m = b_s = B_vc`, no force
//! channels.
//!
//! **Continuous time** (the ideal loop: `v̂_m = v_m`, and the momentum observer as the first-order lag
//! it is for an exact model, `ṙ = K_O·(f_h − r)`): state `(x_m, v_m, x_s, v_s, r)`. With the hand
//! released and `C6 = 0` the observer decouples (pole `−K_O`) and the rest has the characteristic
//! polynomial of §11.4 ([`AxisModel::released_polynomial`]).
//!
//! **Sampled data** ([`AxisModel::discrete`]), tick `k` exactly as `HapticSystem::tick` runs it:
//! the encoders give `x_m,k`; the velocity filter `v̂_k = v̂_{k−1} + α·((x_m,k − x_m,k−1)/T − v̂_{k−1})`;
//! the momentum observer `I_k = I_{k−1} + T·(u_{k−1} − b·v̂_{k−1} + r_{k−1})`,
//! `r_k = K_O·(m·v̂_k − I_k)` (`u_{k−1}` the wrench applied over the previous interval); the slave's
//! contact force `f_e,k` at `x_s,k`; the controller; the slave by semi-implicit Euler
//! `v_s ← v_s + T·(f_cs − f_e)/M_s`, `x_s ← x_s + T·v_s`; and the plant under the wrench held over
//! `[kT, (k+1)T)` (zero-order hold, exact: `[x; v] ← Φ·[x; v] + Γ·u` with `Φ = e^{A T}` from the
//! exponential of the augmented matrix `[[A, B], [0, 0]]·T`). `delay = 1` holds the command one more
//! sample (a device whose write lands one tick late), `delay = 0` is the simulated device of the lab.
//! The state is `(x_m, v_m, x_prev, v̂, I, r, x_s, v_s, u_prev, u_pending)`; the loop is linear, so
//! its state matrix is assembled column by column from the step map applied to unit vectors, and the
//! loop's growth rate is `ln ρ(A_d) / T` (1/s), directly comparable with the continuous poles' real
//! parts.

use super::dense::Mat;

/// The linear controller of one axis (see the module docs for the law).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisController {
    /// Master position gain `k_m` (N/m or N·m/rad).
    pub k_m: f64,
    /// Master damping on the velocity error `b_m` (N·s/m or N·m·s/rad).
    pub b_m: f64,
    /// Slave position gain `k_s`.
    pub k_s: f64,
    /// Slave damping `b_s`.
    pub b_s: f64,
    /// Hand-force estimate into the master command `g_mh` (= C6).
    pub g_mh: f64,
    /// Environment force into the master command `g_me` (= −(1 + C6)).
    pub g_me: f64,
    /// Hand-force estimate into the slave drive `g_sh` (= 1 + C5).
    pub g_sh: f64,
    /// Environment force into the slave drive `g_se` (= −C5).
    pub g_se: f64,
    /// Master damping injection `d_m` (N·s/m or N·m·s/rad): `−d_m·v̂_m` in `f_cm`.
    pub d_m: f64,
    /// Slave damping injection `d_s` (N·s/m or N·m·s/rad): `−d_s·v_s` in `f_cs`.
    pub d_s: f64,
}

/// One axis of the loop, in world units (kg or kg·m², N/m or N·m/rad, …).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisModel {
    /// Master (handle) inertia `m` in world units.
    pub m: f64,
    /// Master physical damping `b`.
    pub b: f64,
    /// Hand stiffness `K_h` (0 = released).
    pub k_h: f64,
    /// Hand damping `B_h` (0 = released).
    pub b_h: f64,
    /// Slave inertia `M_s`.
    pub m_s: f64,
    /// Environment stiffness `K_e`.
    pub k_e: f64,
    /// Environment damping `B_e`.
    pub b_e: f64,
    /// Controller.
    pub ctrl: AxisController,
    /// Momentum-observer gain `K_O` (1/s).
    pub k_o: f64,
    /// Velocity-filter cut-off (Hz).
    pub velocity_cutoff_hz: f64,
}

/// Dimension of the continuous-time state `(x_m, v_m, x_s, v_s, r)`.
pub const CONTINUOUS_DIM: usize = 5;
/// Dimension of the sampled-data state.
pub const DISCRETE_DIM: usize = 10;

impl AxisModel {
    /// This model with the hand released (`K_h = B_h = 0`).
    pub fn released(&self) -> Self {
        Self {
            k_h: 0.0,
            b_h: 0.0,
            ..*self
        }
    }

    /// The continuous-time state matrix (state `(x_m, v_m, x_s, v_s, r)`).
    pub fn continuous(&self) -> Mat {
        let c = &self.ctrl;
        Mat::from_linear_map(CONTINUOUS_DIM, |z| {
            let (x_m, v_m, x_s, v_s, r) = (z[0], z[1], z[2], z[3], z[4]);
            let f_h = -self.k_h * x_m - self.b_h * v_m;
            let f_e = self.k_e * x_s + self.b_e * v_s;
            let (e, de) = (x_s - x_m, v_s - v_m);
            let f_cm = c.k_m * e + c.b_m * de + c.g_mh * r + c.g_me * f_e - c.d_m * v_m;
            let f_cs = -c.k_s * e - c.b_s * de + c.g_sh * r + c.g_se * f_e - c.d_s * v_s;
            vec![
                v_m,
                (f_cm - self.b * v_m + f_h) / self.m,
                v_s,
                (f_cs - f_e) / self.m_s,
                self.k_o * (f_h - r),
            ]
        })
    }

    /// The §11.4 characteristic polynomial of the released loop for the four-channel law with
    /// `C5 = C6 = 0` (plus the damping injection `d_m`, which adds to `B_m` on the master side only),
    /// highest power first:
    ///
    /// ```text
    /// m·M_s·s⁴ + (m·B_s + M_s·(B_m + b + d_m))·s³ + (m·(K_s + K_e) + M_s·K_m + (b + d_m)·B_s)·s²
    ///   + (K_e·(B_m + B_s) + (b + d_m)·(K_s + K_e))·s + K_e·(K_m + K_s)
    /// ```
    ///
    /// (with `B_e = 0`). Derivation: `(m s² + (B_m + b')s + K_m)·x_m = (B_m s + K_m)·x_s − K_e·x_s` and
    /// `(M_s s² + B_s s + K_s + K_e)·x_s = (B_s s + K_s)·x_m`, `b' = b + d_m`; the determinant of the
    /// 2×2 system is the polynomial.
    pub fn released_polynomial(&self) -> [f64; 5] {
        let c = &self.ctrl;
        let (m, ms, ke) = (self.m, self.m_s, self.k_e);
        let b = self.b + c.d_m;
        [
            m * ms,
            m * c.b_s + ms * (c.b_m + b),
            m * (c.k_s + ke) + ms * c.k_m + b * c.b_s,
            ke * (c.b_m + c.b_s) + b * (c.k_s + ke),
            ke * (c.k_m + c.k_s),
        ]
    }

    /// ZOH discretisation of the plant `m·v̇ = u − (b + B_h)·v − K_h·x` over `dt`: `(Φ, Γ)` with
    /// `[x; v]⁺ = Φ·[x; v] + Γ·u`.
    fn plant_zoh(&self, dt: f64) -> ([[f64; 2]; 2], [f64; 2]) {
        // Augmented matrix [[A, B], [0, 0]]·T; its exponential is [[Φ, Γ], [0, 1]].
        let mut a = Mat::zeros(3);
        a.set(0, 1, dt);
        a.set(1, 0, -self.k_h / self.m * dt);
        a.set(1, 1, -(self.b + self.b_h) / self.m * dt);
        a.set(1, 2, dt / self.m);
        let e = a.expm();
        (
            [[e.get(0, 0), e.get(0, 1)], [e.get(1, 0), e.get(1, 1)]],
            [e.get(0, 2), e.get(1, 2)],
        )
    }

    /// The sampled-data state matrix of the loop at period `dt` (s), with `delay` extra samples (0 or
    /// 1) between the controller's output and the amplifiers.
    pub fn discrete(&self, dt: f64, delay: usize) -> Mat {
        let (phi, gam) = self.plant_zoh(dt);
        let alpha = 1.0 - (-std::f64::consts::TAU * self.velocity_cutoff_hz * dt).exp();
        let c = self.ctrl;
        let s = *self;
        Mat::from_linear_map(DISCRETE_DIM, move |z| {
            let (x_m, v_m, x_prev, v_hat, integ, r_prev) = (z[0], z[1], z[2], z[3], z[4], z[5]);
            let (x_s, v_s, u_prev, u_pend) = (z[6], z[7], z[8], z[9]);
            // Steps 1–2: velocity filter and momentum observer.
            let v_k = v_hat + alpha * ((x_m - x_prev) / dt - v_hat);
            let i_k = integ + dt * (u_prev - s.b * v_hat + r_prev);
            let r_k = s.k_o * (s.m * v_k - i_k);
            // Steps 3–7: contact force at x_s,k, then the controller.
            let f_e = s.k_e * x_s + s.b_e * v_s;
            let (e, de) = (x_s - x_m, v_s - v_k);
            let f_cm = c.k_m * e + c.b_m * de + c.g_mh * r_k + c.g_me * f_e - c.d_m * v_k;
            let f_cs = -c.k_s * e - c.b_s * de + c.g_sh * r_k + c.g_se * f_e - c.d_s * v_s;
            // Step 9: the wrench applied over [kT, (k+1)T).
            let (u, pend) = if delay == 0 {
                (f_cm, 0.0)
            } else {
                (u_pend, f_cm)
            };
            // Step 10: slave (semi-implicit Euler) and plant (exact ZOH).
            let v_s1 = v_s + dt * (f_cs - f_e) / s.m_s;
            let x_s1 = x_s + dt * v_s1;
            let x_m1 = phi[0][0] * x_m + phi[0][1] * v_m + gam[0] * u;
            let v_m1 = phi[1][0] * x_m + phi[1][1] * v_m + gam[1] * u;
            vec![x_m1, v_m1, x_m, v_k, i_k, r_k, x_s1, v_s1, u, pend]
        })
    }
}
