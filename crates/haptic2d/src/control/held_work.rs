//! A TDPA port controller that predicts the work of a force held over the period (issue 41,
//! docs/TELEOP.md "Where the ~7 mJ at 200 ms come from").
//!
//! # Why
//!
//! A sampled port applies a force `F` that is *held* over the period `T` (zero-order hold) while
//! the body moves. [`super::tdpa::TdpaPort`] books `F·v·T`, the work at the velocity of the start
//! of the period; the force's real work is `F·Δx`. At a long round trip the master port's damping
//! runs at its explicit-damping cap `α = 2m/T`, which reverses the handle in one period and does no
//! work at all while `F·v·T` books `α·v²·T` dissipated: the plants receive energy the books do not
//! show (+5.5 mJ on the handle over the acceptance run at 200 ms).
//!
//! # The prediction
//!
//! Over one period the body (mass matrix `M`, kg, kg·m, kg·m²) starts at velocity `v` and is pushed
//! by the port's force `F` and by everything else on it, `W` (for a device handle: the hand's
//! wrench as the device's observer estimates it, `DeviceEstimate::hand_wrench`). With both held,
//! `M·ẍ = F + W` is constant, so
//!
//! ```text
//! Δx = v·T + a·T²/2,   a = M⁻¹·(F + W),   and the port's work per axis  W_i = F_i·Δx_i.
//! ```
//!
//! (Summed over the axes and both forces this is the kinetic-energy change,
//! `(F + W)·Δx = ½(v + aT)ᵀM(v + aT) − ½vᵀMv`.) On a free body (`W = 0`) the self-term is
//! `F·M⁻¹F·T²/2 ≥ 0`; in a static contact (`F + W = 0`, `v = 0`) the predicted work is zero, so a
//! steady contact force is not cut — the free-mass prediction (`network::held::held_work` in the
//! lab) cut it.
//!
//! # The controller
//!
//! Per axis the force keeps its direction and is scaled by the largest `β ∈ [0, 1]` whose
//! predicted work fits the room the far side's energy leaves, `E_in(there) − E_out(here)`:
//!
//! ```text
//! W_i(β) = β²·F_i²·(M⁻¹)_ii·T²/2 + β·F_i·(v_i·T + c_i·T²/2) ≤ room_i,
//! c_i = Σ_{j≠i} (M⁻¹)_ij·F_j + (M⁻¹·W)_i        (the other axes at their requested forces)
//! ```
//!
//! and the port books the predicted work of the force *really applied* (after the caller's
//! ramp, saturation and gate) with the full `M⁻¹`, so the books are the plant's ledger up to the
//! estimate of `W` and of `v`. Scaling by `β` is a damping `α = (1 − β)·F/v` where the port
//! outputs, never past the point where the force would reverse: it cannot push the body back, so
//! it needs no explicit-damping cap. What it does not model: the joint friction (outside the
//! observer's `W`), the change of the hand's force within the period (its damping, `B·T/m ≈ 2.5 %`
//! of the self-term here), and the observer's lag (`1/K_O`, 17 ms with the default gain).
//!
//! The velocity at the start of the period matters as much as the self-term: the device's 50 Hz
//! velocity filter lags 3.2 ms, which left +1.1–1.7 mJ on the handle at a 200 ms round trip;
//! [`ForcedVelocity`] carries the velocity with the known acceleration instead. For a world's body
//! stepped by semi-implicit Euler ([`HeldWorkControl::semi_implicit`]) a damping alone does its
//! least work at `α = m/(2T)` and positive work at the usual cap `2m/T`, so there the controller
//! damps first, up to the damping of least work ([`HeldWorkControl::damping`]).
//!
//! Measured in the split loop (docs/TELEOP.md, "The held-work controller with the hand's wrench,
//! tried"): on both ports the plants at a 200 ms round trip received +0.5 mJ instead of +7 mJ, but
//! the honest ports are stricter — the contact softened at 50 ms and collapsed at 200 ms — so the
//! split loop does not use this controller. Pure arithmetic, no allocation, fixed order.

use super::tdpa::PlanarTdpa;
use crate::device::linalg::{inv3, m3_mul_v, M3, V3};

/// The work (J, or N·m·rad) per axis of the forces `f` (N, N, N·m) held for `dt` (s) on a body of
/// inverse mass matrix `m_inv` moving at `v` (m/s, m/s, rad/s) at the start, with the other forces
/// `other` (N, N, N·m) held on it too: `f_i·(v_i·dt + c·(m_inv·(f + other))_i·dt²)`, with `c = ½`
/// for a body in continuous time and `c = 1` for one semi-implicit Euler step (`v' = v + a·T`,
/// `x' = x + v'·T`).
pub fn held_work(f: &V3, v: &V3, other: &V3, m_inv: &M3, dt: f64, c: f64) -> V3 {
    let total: V3 = std::array::from_fn(|i| f[i] + other[i]);
    let a = m3_mul_v(m_inv, &total);
    std::array::from_fn(|i| f[i] * (v[i] * dt + a[i] * c * dt * dt))
}

/// The least damping `α ≥ 0` (N·s/m, N·m·s/rad) with `(f − α·v)·s + (f − α·v)²·k ≤ room` (J),
/// the work of the damped force `f − α·v` over the period (`s` m, `k` m/N: see
/// [`HeldWorkControl::control`]), up to the `α` of least work; 0 where damping cannot lower the
/// work (`v = 0`, or the least work is at `α ≤ 0`).
pub fn least_damping(f: f64, v: f64, s: f64, k: f64, room: f64) -> f64 {
    let (q, l, w0) = (v * v * k, -v * (s + 2.0 * f * k), f * s + f * f * k);
    if w0 <= room || q <= 0.0 || l >= 0.0 {
        return 0.0;
    }
    let vertex = -l / (2.0 * q);
    let disc = l * l - 4.0 * q * (w0 - room);
    if disc < 0.0 {
        return vertex;
    }
    // The smaller root, in the form without cancellation (both roots are positive here).
    (2.0 * (w0 - room) / (-l + disc.sqrt())).min(vertex)
}

/// The body's velocity at the start of the period from its sampled poses and the acceleration the
/// forces of the last period gave it: the model carries the velocity over the period
/// (`v_k = v_{k−1} + a_{k−1}·T`) and the measured mean velocity `(x_k − x_{k−1})/T` corrects it
/// through a first-order gain `g = 1 − exp(−2π·f_c·T)` against the model's own mean velocity
/// `v_{k−1} + a_{k−1}·T/2`. A body whose acceleration is known is estimated without lag; the
/// encoders' quantization is filtered as by the device's velocity filter of the same cut-off
/// (whose lag, `T·(1 − g)/g + T/2` = 3.2 ms at 50 Hz and 1 kHz, misread the period's work).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForcedVelocity {
    /// The correction gain `g` (dimensionless).
    gain: f64,
    /// The pose of the last sample, once there is one (m, m, rad).
    x_prev: Option<V3>,
    /// The velocity estimate at the last sample (m/s, m/s, rad/s).
    v: V3,
    /// The acceleration over the last period (m/s², m/s², rad/s²).
    a: V3,
}

impl ForcedVelocity {
    /// An estimator with cut-off `cutoff_hz` (Hz) at sample period `dt` (s), starting at rest.
    pub fn new(cutoff_hz: f64, dt: f64) -> Self {
        Self {
            gain: 1.0 - (-std::f64::consts::TAU * cutoff_hz * dt).exp(),
            x_prev: None,
            v: [0.0; 3],
            a: [0.0; 3],
        }
    }

    /// Feeds the pose `x` (m, m, rad) sampled `dt` (s) after the last one; returns the velocity at
    /// this sample (m/s, m/s, rad/s). The first sample reads zero (the body starts at rest).
    pub fn update(&mut self, x: &V3, dt: f64) -> V3 {
        if let Some(p) = self.x_prev {
            for i in 0..3 {
                let mean = (x[i] - p[i]) / dt;
                let model_mean = self.v[i] + self.a[i] * dt / 2.0;
                self.v[i] += self.a[i] * dt + self.gain * (mean - model_mean);
            }
        }
        self.x_prev = Some(*x);
        self.v
    }

    /// Sets the acceleration (m/s², m/s², rad/s²) the body has over the period now starting.
    pub fn set_acceleration(&mut self, a: &V3) {
        self.a = *a;
    }
}

/// The largest `β ∈ [0, 1]` with `q·β² + l·β ≤ room` (J; `q ≥ 0`, J; `l`, J): the scale of a
/// force whose predicted work is that quadratic. Where no `β` in `[0, 1]` fits (a debt), the `β`
/// of least work in `[0, 1]`.
pub fn largest_scale(q: f64, l: f64, room: f64) -> f64 {
    if q + l <= room {
        return 1.0;
    }
    if q <= 0.0 {
        // Linear, and l > room: a positive slope fits up to room/l; a negative one (room < l ≤ 0)
        // fits nowhere and works least at β = 1.
        return if l > 0.0 {
            (room / l).clamp(0.0, 1.0)
        } else {
            1.0
        };
    }
    let disc = l * l + 4.0 * q * room;
    if disc < 0.0 {
        return (-l / (2.0 * q)).clamp(0.0, 1.0);
    }
    let s = disc.sqrt();
    // The upper root, in the form without cancellation.
    let upper = if l > 0.0 {
        2.0 * room / (l + s)
    } else {
        (-l + s) / (2.0 * q)
    };
    // upper ≥ 1 with W(1) > room means both roots lie past 1: the least work is at β = 1.
    if upper >= 1.0 {
        1.0
    } else {
        upper.max(0.0)
    }
}

/// The predictive passivity controller of one side's three ports (x, y, θ), used with a
/// [`PlanarTdpa`] that keeps the books: [`Self::control`] then, with the force really applied,
/// [`Self::book`] in the same period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeldWorkControl {
    /// The body's velocity from its poses and the forces on it.
    vel: ForcedVelocity,
    /// The inverse mass matrix of the period (0 where `M` is singular: the books fall back to `F·v·T`).
    m_inv: M3,
    /// The other forces on the body over the period (N, N, N·m).
    other: V3,
    /// The body's velocity at the start of the period (m/s, m/s, rad/s).
    v: V3,
    /// The period (s).
    dt: f64,
    /// The predicted work the scaling removed per axis (J), booked as dissipated.
    cut: V3,
    /// The scale of the last period per axis.
    beta: V3,
    /// The displacement's acceleration factor: `Δx = v·T + c·a·T²` (½ for a body in continuous
    /// time, 1 for a world's semi-implicit Euler step).
    c: f64,
    /// Damp first (`F − α·v`, `α` up to the damping of least work), then scale.
    damp: bool,
}

impl HeldWorkControl {
    /// A controller at sample period `dt` (s) whose velocity estimate ([`ForcedVelocity`]) has
    /// the cut-off `cutoff_hz` (Hz).
    pub fn new(cutoff_hz: f64, dt: f64) -> Self {
        Self {
            vel: ForcedVelocity::new(cutoff_hz, dt),
            m_inv: [[0.0; 3]; 3],
            other: [0.0; 3],
            v: [0.0; 3],
            dt: 0.0,
            cut: [0.0; 3],
            beta: [0.0; 3],
            c: 0.5,
            damp: false,
        }
    }

    /// The same controller for a body stepped by semi-implicit Euler (`v' = v + a·T`,
    /// `x' = x + v'·T`, so `Δx = v·T + a·T²`): a world's body.
    pub fn semi_implicit(self) -> Self {
        Self { c: 1.0, ..self }
    }

    /// The same controller damping before it scales: per axis the least damping `α ≥ 0` (the
    /// force `F − α·v`) whose predicted work fits the room, up to the `α` of least work (for a
    /// lone body stepped by semi-implicit Euler `m/(2T)`: beyond it the damping does less, and at
    /// `2m/T` it reverses the body and does positive work); then the scale, if the room is still
    /// short. Damping takes the motion's share and leaves a steady force alone.
    pub fn damping(self) -> Self {
        Self { damp: true, ..self }
    }

    /// The scale `β` per axis of the last [`Self::control`] (1: the force as requested).
    pub fn beta(&self) -> V3 {
        self.beta
    }

    /// The body's velocity at the start of the period (m/s, m/s, rad/s) from its pose `pose` (m,
    /// m, rad) sampled `dt` (s) after the last and the acceleration booked by the last
    /// [`Self::book`] ([`ForcedVelocity`]): the `v` to give [`Self::control`]. Call once a period.
    pub fn velocity_at(&mut self, pose: &V3, dt: f64) -> V3 {
        self.vel.update(pose, dt)
    }

    /// The force to apply (N, N, N·m) in a period of `dt` (s): `force` as the far side asks,
    /// each axis scaled so that its predicted work fits `far_e_in − E_out` of `ports` (J), for a
    /// body of mass matrix `m` at velocity `v` with the other forces `other` on it (see the module
    /// docs). A non-finite input, or a non-positive `dt`, returns no force.
    #[allow(clippy::too_many_arguments)]
    pub fn control(
        &mut self,
        ports: &PlanarTdpa,
        force: &V3,
        v: &V3,
        other: &V3,
        m: &M3,
        far_e_in: &V3,
        dt: f64,
    ) -> V3 {
        let finite = |x: &V3| x.iter().all(|c| c.is_finite());
        let m_ok = m.iter().all(finite);
        self.cut = [0.0; 3];
        self.beta = [0.0; 3];
        if !(finite(force) && finite(v) && finite(other) && finite(far_e_in) && m_ok && dt > 0.0) {
            self.dt = 0.0;
            return [0.0; 3];
        }
        self.m_inv = inv3(m).unwrap_or([[0.0; 3]; 3]);
        (self.other, self.v, self.dt) = (*other, *v, dt);
        let ext = m3_mul_v(&self.m_inv, other);
        let h = self.c * dt * dt;
        std::array::from_fn(|i| {
            let cross: f64 = (0..3)
                .filter(|&j| j != i)
                .map(|j| self.m_inv[i][j] * force[j])
                .sum();
            // The work of a force g on this axis: g·s + g²·k.
            let (s, k) = (v[i] * dt + (cross + ext[i]) * h, self.m_inv[i][i] * h);
            let room = far_e_in[i].max(0.0) - ports.axes[i].energy_out();
            let f = force[i];
            let g = if self.damp {
                f - least_damping(f, v[i], s, k, room) * v[i]
            } else {
                f
            };
            let b = largest_scale(g * g * k, g * s, room);
            self.beta[i] = b;
            let (w_asked, w_out) = (f * s + f * f * k, b * g * s + b * g * b * g * k);
            self.cut[i] = (w_asked - w_out).max(0.0);
            b * g
        })
    }

    /// Books into `ports` the period in which `applied` (N, N, N·m) was really applied: its
    /// predicted work with the mass, velocity and other forces of the last [`Self::control`], and
    /// the work the scaling removed as dissipated. Books nothing without a valid control call or
    /// with a non-finite force.
    pub fn book(&mut self, ports: &mut PlanarTdpa, applied: &V3) {
        if !(self.dt > 0.0 && applied.iter().all(|f| f.is_finite())) {
            return;
        }
        let w = held_work(applied, &self.v, &self.other, &self.m_inv, self.dt, self.c);
        for ((port, w), cut) in ports.axes.iter_mut().zip(w).zip(self.cut) {
            port.book_work(w, cut);
        }
        let total: V3 = std::array::from_fn(|i| applied[i] + self.other[i]);
        self.vel.set_acceleration(&m3_mul_v(&self.m_inv, &total));
    }

    /// Books into `ports` the period in which `applied` (N, N, N·m) was applied and the body
    /// really moved at the mean velocity `moved` (its displacement over the period / `dt`; m/s,
    /// m/s, rad/s): the work `applied·moved·dt` (a world side knows its body's displacement at
    /// once), and the predicted work the controller removed as dissipated.
    pub fn book_measured(&self, ports: &mut PlanarTdpa, applied: &V3, moved: &V3) {
        if self.dt <= 0.0 {
            return;
        }
        for (i, port) in ports.axes.iter_mut().enumerate() {
            port.book_work(applied[i] * moved[i] * self.dt, self.cut[i]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::filter::VelocityFilter;
    use crate::device::linalg::dot3;

    /// A mass matrix with off-diagonal terms (kg, kg·m, kg·m²), symmetric positive definite.
    const M: M3 = [
        [0.21, 0.03, 0.004],
        [0.03, 0.18, -0.002],
        [0.004, -0.002, 0.0009],
    ];
    const T: f64 = 1e-3;
    /// A free body of 0.2 kg on x and y and 0.001 kg·m² on θ, without coupling.
    const FREE: M3 = [[0.2, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.001]];

    /// The controller's force on x for the free body [`FREE`] at `v` m/s on x, asked `f` N on x,
    /// with `far` J come in at the far side on x and no other force.
    fn on_x(c: &mut HeldWorkControl, ports: &PlanarTdpa, f: f64, v: f64, far: f64) -> f64 {
        let (f, v, far) = ([f, 0.0, 0.0], [v, 0.0, 0.0], [far, 0.0, 0.0]);
        c.control(ports, &f, &v, &[0.0; 3], &FREE, &far, T)[0]
    }

    /// The kinetic-energy change (J) of a body of mass matrix `m` from velocity `v` under the
    /// constant total force `total`, its velocity stepped in 10 000 sub-steps of `M·dv = total·dt`.
    fn kinetic_change(m: &M3, v: &V3, total: &V3, dt: f64) -> f64 {
        let dv = inv3(m).map(|mi| m3_mul_v(&mi, total)).unwrap();
        let n = 10_000;
        let mut u = *v;
        for _ in 0..n {
            for i in 0..3 {
                u[i] += dv[i] * dt / n as f64;
            }
        }
        0.5 * (dot3(&u, &m3_mul_v(m, &u)) - dot3(v, &m3_mul_v(m, v)))
    }

    #[test]
    fn the_held_work_on_a_free_body_is_its_kinetic_energy_change() {
        let mi = inv3(&M).unwrap();
        for (f, v) in [
            ([2.0, -1.0, 0.01], [0.01, 0.02, -0.3]),
            ([-3.0, 0.5, 0.0], [-0.05, 0.0, 0.1]),
        ] {
            let w = held_work(&f, &v, &[0.0; 3], &mi, T, 0.5);
            let exact = kinetic_change(&M, &v, &f, T);
            assert!(
                (w.iter().sum::<f64>() - exact).abs() < 1e-12,
                "{w:?} {exact}"
            );
        }
    }

    #[test]
    fn with_another_force_on_the_body_the_two_works_make_the_kinetic_energy_change() {
        // The hand's wrench `h` and the port's force `f` held together: each force's work over the
        // same displacement; their sum is the body's kinetic-energy change.
        let mi = inv3(&M).unwrap();
        let (f, h, v) = ([1.5, -0.4, 0.02], [-0.7, 0.9, -0.01], [0.03, -0.01, 0.2]);
        let wf: f64 = held_work(&f, &v, &h, &mi, T, 0.5).iter().sum();
        let wh: f64 = held_work(&h, &v, &f, &mi, T, 0.5).iter().sum();
        let total = [f[0] + h[0], f[1] + h[1], f[2] + h[2]];
        assert!((wf + wh - kinetic_change(&M, &v, &total, T)).abs() < 1e-12);
    }

    #[test]
    fn a_static_contact_is_not_cut_even_without_room() {
        // The hand pushes 2.3 N into a contact the port's force balances; the handle is at rest.
        let mut c = HeldWorkControl::new(50.0, T);
        let mut ports = PlanarTdpa::default();
        let f = [2.3, -0.4, 0.0];
        let hand = [-2.3, 0.4, 0.0];
        let out = c.control(&ports, &f, &[0.0; 3], &hand, &M, &[0.0; 3], T);
        // (Up to rounding: M⁻¹·(F + W) is zero only to ~1e-16 with the off-diagonal terms.)
        for i in 0..3 {
            assert!((out[i] - f[i]).abs() < 1e-12, "{out:?}");
        }
        c.book(&mut ports, &out);
        let (i, o, d) = ports.totals();
        assert!(i < 1e-18 && o < 1e-18 && d < 1e-18, "{:?}", ports.totals());
    }

    #[test]
    fn a_free_handle_force_is_scaled_until_its_work_fits_the_room_exactly() {
        // One axis: a 0.2 kg free body at 0.05 m/s, 3 N along the motion would do
        // 3·0.05·1e-3 + 9·1e-6/0.4 = 172.5 µJ; only 100 µJ came in at the far side.
        let mut c = HeldWorkControl::new(50.0, T);
        let mut ports = PlanarTdpa::default();
        let out = [on_x(&mut c, &ports, 3.0, 0.05, 1e-4), 0.0, 0.0];
        assert!(out[0] > 0.0 && out[0] < 3.0, "{out:?}");
        // The scaled force's work on the free body, by its kinetic-energy change, is the room.
        let exact = kinetic_change(&FREE, &[0.05, 0.0, 0.0], &out, T);
        assert!((exact - 1e-4).abs() < 1e-12, "{exact}");
        c.book(&mut ports, &out);
        assert!((ports.energy_out()[0] - 1e-4).abs() < 1e-15);
        // What was cut is booked as dissipated: 172.5 − 100 µJ.
        assert!(
            (ports.totals().2 - 72.5e-6).abs() < 1e-15,
            "{:?}",
            ports.totals()
        );
    }

    #[test]
    fn a_damping_force_at_the_explicit_cap_books_no_dissipation() {
        // α = 2m/T reverses a free body's velocity in one period: no work (F·v·T would book
        // α·v²·T dissipated).
        let v = [0.03, 0.0, 0.0];
        let f = [-(2.0 * 0.2 / T) * v[0], 0.0, 0.0];
        let w = held_work(&f, &v, &[0.0; 3], &inv3(&FREE).unwrap(), T, 0.5);
        assert!(w[0].abs() < 1e-15, "{w:?}");
    }

    #[test]
    fn the_force_keeps_its_direction_and_a_debt_cuts_an_output_to_zero() {
        let mut c = HeldWorkControl::new(50.0, T);
        let mut ports = PlanarTdpa::default();
        ports.axes[0].book_work(1e-4, 0.0); // 0.1 mJ out, nothing came in: a debt
        assert_eq!(on_x(&mut c, &ports, 1.0, 0.1, 0.0), 0.0);
        // An input (the force against the motion) is not cut by the debt.
        assert_eq!(on_x(&mut c, &ports, -1.0, 0.1, 0.0), -1.0);
    }

    /// The work (J) of the force `f` over one semi-implicit Euler step of a lone body (mass `m`) at
    /// velocity `v` with the other force `w` on it: `v' = v + (f + w)·T/m`, `x' = x + v'·T`.
    fn euler_work(f: f64, w: f64, v: f64, m: f64) -> f64 {
        let v1 = v + (f + w) * T / m;
        f * v1 * T
    }

    #[test]
    fn the_held_work_of_a_semi_implicit_euler_step_is_the_force_times_the_steps_displacement() {
        let mi = inv3(&FREE).unwrap();
        let (f, w, v) = ([1.2, -0.3, 0.0], [-0.5, 0.1, 0.0], [0.04, 0.01, 0.0]);
        let held = held_work(&f, &v, &w, &mi, T, 1.0);
        for i in 0..2 {
            assert!(
                (held[i] - euler_work(f[i], w[i], v[i], 0.2)).abs() < 1e-18,
                "{held:?}"
            );
        }
    }

    /// A world's body of 0.5 kg (x, y) stepped by semi-implicit Euler, its controller damping first.
    fn world_body() -> (HeldWorkControl, M3) {
        let m = [[0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 1e-4]];
        (HeldWorkControl::new(50.0, T).semi_implicit().damping(), m)
    }

    #[test]
    fn a_damping_controller_damps_a_moving_body_to_the_room_and_keeps_the_force_direction() {
        // 2 N along a body moving at 0.05 m/s, no room: the least damping whose work over the
        // Euler step is zero, the force reversed by the damping as in TDPA.
        let (mut c, m) = world_body();
        let ports = PlanarTdpa::default();
        let (f, v) = ([2.0, 0.0, 0.0], [0.05, 0.0, 0.0]);
        let out = c.control(&ports, &f, &v, &[0.0; 3], &m, &[0.0; 3], T);
        assert!(out[0] < 2.0, "{out:?}");
        assert!(euler_work(out[0], 0.0, 0.05, 0.5).abs() < 1e-15, "{out:?}");
        // The damping leaves the scale alone where it suffices.
        assert_eq!(c.beta()[0], 1.0);
    }

    #[test]
    fn the_damping_stops_at_the_least_work_m_over_2t_never_at_the_reversing_cap() {
        // A debt nothing pays in one step: the damping of least work, α = m/(2T) for a lone body,
        // whose work is −m·v²/4 (at the TDPA cap 2m/T the same damping would give +α·v²·T).
        assert!(
            (least_damping(0.0, 0.05, 0.05 * T, T * T / 0.5, -1.0) - 0.5 / (2.0 * T)).abs() < 1e-9
        );
        let f = -(0.5 / (2.0 * T)) * 0.05;
        assert!((euler_work(f, 0.0, 0.05, 0.5) + 0.5 * 0.05 * 0.05 / 4.0).abs() < 1e-15);
        let cap = -(2.0 * 0.5 / T) * 0.05;
        assert!(
            (euler_work(cap, 0.0, 0.05, 0.5) - (2.0 * 0.5 / T) * 0.05 * 0.05 * T).abs() < 1e-15
        );
    }

    #[test]
    fn a_damping_controller_leaves_a_resting_contact_alone() {
        // The body rests on a wall that pushes back 3 N against the 3 N coupling force.
        let (mut c, m) = world_body();
        let ports = PlanarTdpa::default();
        let out = c.control(
            &ports,
            &[-3.0, 0.0, 0.0],
            &[0.0; 3],
            &[3.0, 0.0, 0.0],
            &m,
            &[0.0; 3],
            T,
        );
        assert_eq!(out, [-3.0, 0.0, 0.0]);
    }

    #[test]
    fn the_largest_scale_solves_the_quadratic_and_falls_back_to_least_work() {
        // 2β² + 1β ≤ 1 → β = 0.5.
        assert!((largest_scale(2.0, 1.0, 1.0) - 0.5).abs() < 1e-15);
        // Linear: 4β ≤ 1 → 0.25.
        assert!((largest_scale(0.0, 4.0, 1.0) - 0.25).abs() < 1e-15);
        // Fits: 1.
        assert_eq!(largest_scale(1.0, -3.0, 0.0), 1.0);
        // A debt nothing in [0, 1] pays: β² − β ≥ −0.25 > −1; least work at β = 0.5.
        assert!((largest_scale(1.0, -1.0, -1.0) - 0.5).abs() < 1e-15);
        // A debt and an output: β = 0.
        assert_eq!(largest_scale(1.0, 1.0, -1.0), 0.0);
    }

    #[test]
    fn the_forced_velocity_follows_a_known_acceleration_without_the_filters_lag() {
        // x = ½·a·t² with a = 2 m/s² on x, −1 on y; the estimate is told the acceleration.
        let a = [2.0, -1.0, 0.0];
        let mut fv = ForcedVelocity::new(50.0, T);
        let mut filt = VelocityFilter::new(50.0, T);
        let (mut v_fv, mut v_f) = ([0.0; 3], [0.0; 3]);
        for k in 0..200 {
            let t = k as f64 * T;
            let x = [0.5 * a[0] * t * t, 0.5 * a[1] * t * t, 0.0];
            v_fv = fv.update(&x, T);
            fv.set_acceleration(&a);
            v_f = filt.update(&x);
        }
        let t = 199.0 * T;
        assert!((v_fv[0] - a[0] * t).abs() < 1e-9, "{v_fv:?}");
        assert!((v_fv[1] - a[1] * t).abs() < 1e-9, "{v_fv:?}");
        // The device's filter lags by a·T·((1 − g)/g + ½), g = 1 − exp(−2π·50·T).
        let g = 1.0 - (-std::f64::consts::TAU * 50.0 * T).exp();
        let lag = a[0] * T * ((1.0 - g) / g + 0.5);
        assert!((a[0] * t - v_f[0] - lag).abs() < 1e-6, "{v_f:?} {lag}");
    }
}
