//! The simulated linkages an emulated board moves: one 2DIY five-bar ([`Plant2`]) or the twin
//! pantograph (the core's [`SimDevice`], MODELS §10.6), pushed by a simulated [`HandModel`].
//!
//! [`Plant2`] is a lumped 2-DOF model: joint inertia `I_j` on each motor, an end-point mass `m_e`,
//! viscous joint friction `b`. With `E = FK(q)`, `Ė = J·q̇`, the kinetic energy is
//! `T = ½·I_j·|q̇|² + ½·m_e·|J·q̇|²`, and Lagrange's equations give
//!
//! ```text
//! (I_j·1 + m_e·JᵀJ)·q̈ = τ + Jᵀ·f_h − b·q̇ − m_e·Jᵀ·(J̇·q̇)
//! ```
//!
//! (`m_e·Jᵀ·Ë` with `Ë = J·q̈ + J̇·q̇` is the end mass's share). `J̇·q̇` is taken by a forward
//! difference of `J` along `q̇` over one sub-step. Integrated by semi-implicit Euler, ≤ 100 µs steps.

use haptic2d::device::linalg::V4;
use haptic2d::device::pantograph2::{j_mul, jt_mul, Pantograph2};
use haptic2d::device::{DeviceParams, HandModel, SimDevice};
use haptic2d::geom::Vec2;

/// A 2DIY linkage with lumped inertia.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plant2 {
    /// Geometry (m).
    pub linkage: Pantograph2,
    /// Joint inertia per motor, rotor + proximal link (kg·m²). Default 2e-5.
    pub i_j: f64,
    /// End-point mass: handle + distal links (kg). Default 0.03.
    pub m_e: f64,
    /// Viscous joint friction (N·m·s/rad). Default 2e-4.
    pub b: f64,
    q: [f64; 2],
    qd: [f64; 2],
    t: f64,
}

impl Plant2 {
    /// A linkage at rest with its end point at `e` (m, board frame).
    pub fn new(linkage: Pantograph2, e: Vec2) -> Result<Self, String> {
        let q = linkage
            .ik(e)
            .map_err(|err| format!("emulator start point ({:.4} m, {:.4} m): {err}", e.x, e.y))?;
        Ok(Self {
            linkage,
            i_j: 2e-5,
            m_e: 0.03,
            b: 2e-4,
            q,
            qd: [0.0; 2],
            t: 0.0,
        })
    }

    /// Motor angles (rad).
    pub fn q(&self) -> [f64; 2] {
        self.q
    }

    /// End point (m, board frame), if the linkage assembles.
    pub fn end_point(&self) -> Option<Vec2> {
        self.linkage.fk(self.q).ok()
    }

    /// Advances `dt` (s) under joint torques `tau` (N·m) and the hand. Errors (the state is kept)
    /// when the linkage reaches a singular pose.
    pub fn step(&mut self, tau: [f64; 2], hand: &HandModel, dt: f64) -> Result<(), String> {
        self.step_damped(tau, hand, 0.0, dt)
    }

    /// [`step`](Self::step) with an extra hand damping `b_h` (N·s/m) on the end point.
    pub fn step_damped(
        &mut self,
        tau: [f64; 2],
        hand: &HandModel,
        b_h: f64,
        dt: f64,
    ) -> Result<(), String> {
        let n = (dt / 1e-4).ceil().max(1.0) as usize;
        let h = dt / n as f64;
        for _ in 0..n {
            let s = self.linkage.state(self.q).map_err(|e| e.to_string())?;
            let ed = j_mul(&s.j, self.qd);
            let w = hand.wrench(&[s.e.x, s.e.y, 0.0], &[ed[0], ed[1], 0.0], self.t);
            let qn = [self.q[0] + h * self.qd[0], self.q[1] + h * self.qd[1]];
            let jdqd = match self.linkage.state(qn) {
                Ok(s2) => {
                    let a = j_mul(&s2.j, self.qd);
                    [(a[0] - ed[0]) / h, (a[1] - ed[1]) / h]
                }
                Err(_) => [0.0; 2],
            };
            let fh = jt_mul(&s.j, [w[0] - b_h * ed[0], w[1] - b_h * ed[1]]);
            let cor = jt_mul(&s.j, jdqd);
            let rhs: [f64; 2] =
                std::array::from_fn(|i| tau[i] + fh[i] - self.b * self.qd[i] - self.m_e * cor[i]);
            // M = I_j·1 + m_e·JᵀJ (symmetric positive definite).
            let j = &s.j;
            let jtj = [
                [
                    j[0][0] * j[0][0] + j[1][0] * j[1][0],
                    j[0][0] * j[0][1] + j[1][0] * j[1][1],
                ],
                [0.0, j[0][1] * j[0][1] + j[1][1] * j[1][1]],
            ];
            let (m00, m01, m11) = (
                self.i_j + self.m_e * jtj[0][0],
                self.m_e * jtj[0][1],
                self.i_j + self.m_e * jtj[1][1],
            );
            let det = m00 * m11 - m01 * m01;
            let qdd = [
                (m11 * rhs[0] - m01 * rhs[1]) / det,
                (m00 * rhs[1] - m01 * rhs[0]) / det,
            ];
            for ((q, qd), a) in self.q.iter_mut().zip(self.qd.iter_mut()).zip(qdd) {
                *qd += h * a;
                *q += h * *qd;
            }
            self.t += h;
        }
        Ok(())
    }
}

/// The linkage behind an emulated board.
#[derive(Clone, Debug)]
pub enum Plant {
    /// One 2DIY five-bar; joints `(q1, q2)`.
    TwoDiy(Plant2),
    /// The twin pantograph; joints `(q11, q12, q21, q22)`.
    Twin(Box<SimDevice>),
}

impl Plant {
    /// A twin-pantograph plant for `params` at rest at handle pose `x0` (m, m, rad). A hand damping
    /// `b_h` (N·s/m) at the handle is approximated by joint viscous friction `b_h·l1²/2` per joint
    /// (four joints share it), added to `f_v`.
    pub fn twin(params: &DeviceParams, x0: [f64; 3], b_h: f64) -> Result<Self, String> {
        let mut p = *params;
        p.f_v += 0.5 * b_h * p.l1 * p.l1;
        let mut sim = SimDevice::new(&p, x0)?;
        sim.quantize = false; // the emulated board's encoders quantise
        sim.substeps = 4;
        Ok(Plant::Twin(Box::new(sim)))
    }

    /// Joint angles (rad); a 2DIY fills the first two.
    pub fn joint_angles(&self) -> V4 {
        match self {
            Plant::TwoDiy(p) => [p.q[0], p.q[1], 0.0, 0.0],
            Plant::Twin(s) => s.encoders().unwrap_or([f64::NAN; 4]),
        }
    }

    /// Advances `dt` (s) under joint torques `tau` (N·m) and `hand`, plus the hand's own damping
    /// `b_h` (N·s/m at the end point; for the twin it was folded into the joint friction at
    /// construction, see [`Plant::twin`]).
    pub fn step(&mut self, tau: &V4, hand: &HandModel, b_h: f64, dt: f64) -> Result<(), String> {
        match self {
            Plant::TwoDiy(p) => p.step_damped([tau[0], tau[1]], hand, b_h, dt),
            Plant::Twin(s) => {
                // SimDevice steps at most 10 ms at a time (long gaps are split).
                let n = (dt / 0.002).ceil().max(1.0) as usize;
                for _ in 0..n {
                    s.step(tau, hand, dt / n as f64)
                        .map_err(|e| e.to_string())?;
                }
                Ok(())
            }
        }
    }
}
