//! A world port that paces its body's approach (issue 41, docs/TELEOP.md "Pacing the world's
//! body: `control::paced`, tried"): a TDPA port whose body may carry as kinetic energy only a share of the room it has, or
//! move as fast as the master does.
//!
//! # Why
//!
//! At a 200 ms round trip the honest ports of [`super::held_work`] keep the network passive but
//! lose the contact: the master's port receives ~0.5 mJ from the hand before the world's force
//! returns, and the world's port ([`super::held_work::HeldWorkControl`], damping first) spends
//! it at once. The coupling spring, stretched 12 mm while the body waited for room, throws the
//! body at the wall with the whole room as kinetic energy (42 mm/s, 0.45 of 0.46 mJ in the run of
//! the docs), the impact and the contact's damping destroy it, and ~0.04 mJ remain to compress the
//! wall: 0.5 N instead of 3 N. Pressing a wall of stiffness `k` with the force `F` stores only
//! `F²/(2k)` (0.45 mJ at 3 N on 10 000 N/m), so the room was not too small: it went to the approach.
//!
//! # The controller
//!
//! Per axis, before the TDPA scale, the requested force is clamped so that the body's velocity
//! after the period (one semi-implicit Euler step, `v' = v + (F + W)·T/m`, `W` the other forces on
//! it, e.g. the wall's) stays within
//!
//! ```text
//! |v'| ≤ v_cap = max(|v_m|, sqrt(2·γ·room/m), |v|)
//! ```
//!
//! `v_m` is the master's velocity as received (the body may follow the handle at its own speed,
//! so a short delay, where the room is ample, is unchanged), `room = E_in(there) − E_out(here)`,
//! `γ` the share of the room the body may hold as kinetic energy, and `|v|` so that the clamp never
//! forces a brake: it only refuses to speed the body up. The excess the clamp removes is the
//! spring's stretch built up during the delay, energy the network never received. A resting
//! contact (`F + W = 0`, `v = 0`) is not touched: its `v'` is zero. Then the force is scaled, as in
//! [`super::held_work`], until its predicted work over the step fits the room, and the port books
//! the body's true displacement ([`PacedPort::book_measured`]) with the predicted work the clamp
//! and the scale removed as dissipated. Diagonal mass only (a world's body: mass, mass, inertia).
//! Pure arithmetic, no allocation, fixed order.
//!
//! Measured in the split loop (docs/TELEOP.md), with the held-work controller on the device side:
//! at γ = 0.1 and `v_m` passed as zero the plants received at most +0.5 mJ at 0–200 ms and the
//! 200 ms contact was kept (2.7–2.9 N), but the 50 ms contact stiffened (3.8 N against 2.8 N
//! shipped); with `v_m` 50 ms kept (3.3 N) and 200 ms was lost (1.7 N). So the split loop does
//! not use this controller.

use super::held_work::largest_scale;
use super::tdpa::PlanarTdpa;
use crate::device::linalg::V3;

/// What the world side knows of one period, per axis (x, y, θ), for [`PacedPort::control`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PacedInput {
    /// The coupling's force on the body (N, N, N·m).
    pub force: V3,
    /// The body's velocity at the start of the period (m/s, m/s, rad/s).
    pub v: V3,
    /// The other forces on the body over the period, e.g. the wall's last contact wrench (N, N, N·m).
    pub other: V3,
    /// The body's mass and inertia (kg, kg, kg·m²).
    pub m: V3,
    /// The energy the far (master's) port has put into the network, as last received (J).
    pub far_e_in: V3,
    /// The master's velocity as received (m/s, m/s, rad/s); zero for the room's cap alone.
    pub v_master: V3,
}

/// The pacing controller of a world side's three ports (x, y, θ), with a [`PlanarTdpa`] that keeps
/// the books: [`Self::control`], then [`Self::book_measured`] in the same period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PacedPort {
    /// The share of the room the body may hold as kinetic energy (dimensionless, ≥ 0).
    gamma: f64,
    /// The predicted work the clamp and the scale removed per axis this period (J).
    cut: V3,
    /// The period of the last control (s); 0 before one or after a refused input.
    dt: f64,
}

impl PacedPort {
    /// A controller whose body may hold `gamma` (≥ 0) of the room as kinetic energy.
    pub fn new(gamma: f64) -> Self {
        Self {
            gamma: gamma.max(0.0),
            cut: [0.0; 3],
            dt: 0.0,
        }
    }

    /// The force to apply (N, N, N·m) over a period `dt` (s) for the period's [`PacedInput`]:
    /// the coupling's force clamped to the speed cap and scaled to fit `far_e_in − E_out` of
    /// `ports` (J). A non-finite input, a non-positive mass or `dt` returns no force.
    pub fn control(&mut self, ports: &PlanarTdpa, input: &PacedInput, dt: f64) -> V3 {
        let PacedInput {
            force,
            v,
            other,
            m,
            far_e_in,
            v_master,
        } = input;
        let finite = |x: &V3| x.iter().all(|c| c.is_finite());
        self.cut = [0.0; 3];
        let ok = [force, v, other, far_e_in, v_master]
            .iter()
            .all(|x| finite(x));
        if !(ok && m.iter().all(|&mi| mi > 0.0 && mi.is_finite()) && dt > 0.0) {
            self.dt = 0.0;
            return [0.0; 3];
        }
        self.dt = dt;
        std::array::from_fn(|i| {
            let room = far_e_in[i].max(0.0) - ports.axes[i].energy_out();
            let cap = speed_cap(v_master[i], room, m[i], v[i], self.gamma);
            let g = clamp_to_cap(force[i], v[i], other[i], m[i], cap, dt);
            // The work of a force f over the step: f·s + f²·k (semi-implicit Euler).
            let (s, k) = (v[i] * dt + other[i] / m[i] * dt * dt, dt * dt / m[i]);
            let b = largest_scale(g * g * k, g * s, room);
            let f = force[i];
            let (w_asked, w_out) = (f * s + f * f * k, b * g * s + b * g * b * g * k);
            self.cut[i] = (w_asked - w_out).max(0.0);
            b * g
        })
    }

    /// Books into `ports` the period in which `applied` (N, N, N·m) was applied and the body moved
    /// at the mean velocity `moved` (its displacement over the period / `dt`; m/s, m/s, rad/s):
    /// the work `applied·moved·dt`, and the predicted work the controller removed as dissipated.
    /// Books nothing without a valid [`Self::control`] in the period.
    pub fn book_measured(&self, ports: &mut PlanarTdpa, applied: &V3, moved: &V3) {
        if self.dt <= 0.0 {
            return;
        }
        for (i, port) in ports.axes.iter_mut().enumerate() {
            port.book_work(applied[i] * moved[i] * self.dt, self.cut[i]);
        }
    }
}

/// The speed cap of one axis (m/s or rad/s): the master's speed `|v_m|`, the speed at which the
/// body (mass `m`) holds the share `gamma` of the room `room` (J) as kinetic energy, or the body's
/// own speed `|v|`, whichever is largest.
pub fn speed_cap(v_m: f64, room: f64, m: f64, v: f64, gamma: f64) -> f64 {
    let by_room = (2.0 * gamma * room.max(0.0) / m).sqrt();
    v_m.abs().max(by_room).max(v.abs())
}

/// The force `f` (N) clamped so that one semi-implicit Euler step of a body of mass `m` (kg) at
/// velocity `v` (m/s) with the other force `w` (N) on it ends with `|v'| ≤ cap` (m/s, ≥ |v|):
/// `f ∈ [m·(−cap − v)/T − w, m·(cap − v)/T − w]`.
pub fn clamp_to_cap(f: f64, v: f64, w: f64, m: f64, cap: f64, dt: f64) -> f64 {
    let lo = m * (-cap - v) / dt - w;
    let hi = m * (cap - v) / dt - w;
    f.clamp(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: f64 = 1e-3;
    const M: f64 = 0.5;
    const MASS: V3 = [M, M, 1e-4];

    /// One period on x: the coupling's force `f`, the body's velocity `v`, the wall's force `w`,
    /// the far side's energy in `e_in` (J) and the master's velocity `v_m`.
    fn on_x(f: f64, v: f64, w: f64, e_in: f64, v_m: f64) -> PacedInput {
        PacedInput {
            force: [f, 0.0, 0.0],
            v: [v, 0.0, 0.0],
            other: [w, 0.0, 0.0],
            m: MASS,
            far_e_in: [e_in, 0.0, 0.0],
            v_master: [v_m, 0.0, 0.0],
        }
    }

    /// The force on x of one period without the master's motion.
    fn room_of(c: &mut PacedPort, ports: &PlanarTdpa, f: f64, v: f64, w: f64, e_in: f64) -> f64 {
        c.control(ports, &on_x(f, v, w, e_in, 0.0), T)[0]
    }

    #[test]
    fn a_free_body_pulled_hard_cruises_at_the_speed_holding_gamma_of_the_room() {
        // 5 N on a 0.5 kg body, 0.5 mJ of room, γ = 0.1: the cap is sqrt(2·0.1·0.5 mJ / 0.5 kg)
        // = 14.1 mm/s at first, and falls as the room is spent; the kinetic energy never exceeds
        // γ of the room left (+ one step's rounding).
        let (mut c, mut ports) = (PacedPort::new(0.1), PlanarTdpa::default());
        let (mut x, mut v) = (0.0, 0.0);
        for _ in 0..200 {
            let f = room_of(&mut c, &ports, -5.0, v, 0.0, 5e-4);
            let v1 = v + f * T / M;
            let moved = v1;
            c.book_measured(&mut ports, &[f, 0.0, 0.0], &[moved, 0.0, 0.0]);
            (x, v) = (x + v1 * T, v1);
            let room = 5e-4 - ports.axes[0].energy_out();
            assert!(
                0.5 * M * v * v <= 0.1 * (room + 0.5 * M * v * v) + 1e-12,
                "{v} {room}"
            );
        }
        let first_cap = (2.0 * 0.1 * 5e-4 / M).sqrt();
        assert!(v.abs() <= first_cap + 1e-12 && v < -0.005, "{v}");
        assert!(x < -0.001, "the body moved: {x}");
        // The work out never exceeded the room.
        assert!(ports.axes[0].energy_out() <= 5e-4 + 1e-12);
    }

    #[test]
    fn a_resting_contact_without_room_is_not_cut() {
        // The body rests on a wall pushing back 3 N against the 3 N coupling force, no room.
        let (mut c, ports) = (PacedPort::new(0.1), PlanarTdpa::default());
        assert_eq!(room_of(&mut c, &ports, -3.0, 0.0, 3.0, 0.0), -3.0);
    }

    #[test]
    fn the_body_follows_the_master_at_the_masters_speed_whatever_the_room() {
        // No room is needed for the cap when the master moves at 50 mm/s: one step of 5 N from
        // rest reaches 10 mm/s, under the cap, so the clamp leaves it (the scale then fits the
        // room, here ample).
        let (mut c, ports) = (PacedPort::new(0.1), PlanarTdpa::default());
        let out = c.control(&ports, &on_x(-5.0, 0.0, 0.0, 1.0, -0.05), T);
        assert_eq!(out[0], -5.0);
        // Without the master's motion and with little room (1 µJ, cap 0.63 mm/s) the same force
        // is clamped to the step that reaches the cap: m·cap/T.
        let f = room_of(&mut c, &ports, -5.0, 0.0, 0.0, 1e-6);
        let cap = (2.0 * 0.1 * 1e-6 / M).sqrt();
        assert!((f + M * cap / T).abs() < 1e-12, "{f}");
    }

    #[test]
    fn the_clamp_never_forces_a_brake_on_a_body_already_past_the_cap() {
        // A body at 20 mm/s, no room, no master motion: a force that does not speed it up passes
        // the clamp (a zero force keeps 20 mm/s); one that would is cut back to keep |v'| = |v|.
        assert_eq!(
            clamp_to_cap(0.0, 0.02, 0.0, M, speed_cap(0.0, 0.0, M, 0.02, 0.1), T),
            0.0
        );
        assert_eq!(
            clamp_to_cap(-1.0, 0.02, 0.0, M, speed_cap(0.0, 0.0, M, 0.02, 0.1), T),
            -1.0
        );
        assert_eq!(
            clamp_to_cap(1.0, 0.02, 0.0, M, speed_cap(0.0, 0.0, M, 0.02, 0.1), T),
            0.0
        );
    }

    /// A 0.5 kg body `gap` m from a wall of stiffness `k` (N/m) and damping `b` (N·s/m, acting
    /// while it presses) whose impact returns `e` of an arrival speed above 20 mm/s (the scene's
    /// restitution and collision velocity threshold `v_c`; slower, the body enters the spring),
    /// pulled into it by a constant coupling force of 5 N, with `room` (J) granted at once;
    /// `gamma` None: the plain scale (no pacing). Returns the wall force (N) after 2 s and the
    /// work out (J).
    fn press_the_wall(gamma: Option<f64>, k: f64, b: f64, e: f64, room: f64) -> (f64, f64) {
        let gap = 0.003;
        let mut c = PacedPort::new(gamma.unwrap_or(1e12));
        let mut ports = PlanarTdpa::default();
        let (mut x, mut v, mut wall) = (0.0_f64, 0.0_f64, 0.0_f64);
        for _ in 0..2000 {
            let f = room_of(&mut c, &ports, -5.0, v, wall, room);
            let mut v1 = v + (f + wall) * T / M;
            let mut x1 = x + v1 * T;
            if x1 < -gap && x >= -gap && v1 < -0.02 {
                // The impact: the body stops at the wall and leaves it at e of its speed.
                (x1, v1) = (-gap, -e * v1);
            }
            c.book_measured(&mut ports, &[f, 0.0, 0.0], &[(x1 - x) / T, 0.0, 0.0]);
            (x, v) = (x1, v1);
            let depth = -gap - x;
            wall = if depth > 0.0 {
                (k * depth - b * v).max(0.0)
            } else {
                0.0
            };
        }
        (wall, ports.axes[0].energy_out())
    }

    #[test]
    fn paced_the_room_presses_the_wall_where_the_plain_scale_spends_it_on_the_approach() {
        // 3 mm to a wall of 10 000 N/m (10 N·s/m, restitution 0.5 above 20 mm/s: the acceptance
        // scene's), 0.5 mJ
        // of room. Pressing with F stores F²/(2k), so the room allows at most sqrt(2·k·room) =
        // 3.16 N. In free flight all the work out is kinetic energy: the plain scale brings the
        // body to the wall with the whole room as kinetic energy, the impact keeps e² = ¼ of it,
        // so at most sqrt(2·k·room/4) = 1.58 N remain. Paced at γ = 0.1 the body arrives with at
        // most a tenth of the room, so the impact takes at most 7.5 % of it (the wall's damping takes
        // a little more while it is compressed).
        let (k, room, e): (f64, f64, f64) = (1e4, 5e-4, 0.5);
        let bound = (2.0 * k * room).sqrt();
        let (plain, out_plain) = press_the_wall(None, k, 10.0, e, room);
        let (paced, out_paced) = press_the_wall(Some(0.1), k, 10.0, e, room);
        assert!(
            out_plain <= room + 1e-9 && out_paced <= room + 1e-9,
            "{out_plain} {out_paced}"
        );
        assert!(plain <= (2.0 * k * room * e * e).sqrt(), "plain {plain} N");
        assert!(paced <= bound, "paced {paced} N");
        assert!(paced > 0.8 * bound, "paced {paced} N of {bound} N");
    }

    #[test]
    fn non_finite_inputs_apply_no_force_and_book_nothing() {
        let (mut c, mut ports) = (PacedPort::new(0.1), PlanarTdpa::default());
        assert_eq!(room_of(&mut c, &ports, f64::NAN, 0.0, 0.0, 1.0), 0.0);
        c.book_measured(&mut ports, &[1.0, 0.0, 0.0], &[1.0, 0.0, 0.0]);
        assert_eq!(ports.totals(), (0.0, 0.0, 0.0));
    }
}
