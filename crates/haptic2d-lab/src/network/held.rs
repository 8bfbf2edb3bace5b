//! The energy a force held over a period really gives a body (issue 41: where the split loop's
//! ~7 mJ at a 200 ms round trip come from, docs/TELEOP.md).
//!
//! A sampled port applies a force `F` that is *held* over the period `T` (zero-order hold) while
//! the body accelerates under it. On a free body of mass `m` moving at `v` at the start of the
//! period the force's work is
//!
//! ```text
//! W = F·Δx = F·(v·T + F·T²/(2m)) = F·v·T + F²·T²/(2m)
//! ```
//!
//! The second term is the force's work on the motion it causes itself: never negative, so booking
//! only `F·v·T` (as `TdpaPort::book` does) under-counts the energy out. It matters where the
//! passivity controller's damping is large: at its explicit-damping cap `α = 2m/T` the damping
//! force `−α·v` reverses the velocity in one period and does no work at all (`W = 0`) while the
//! books count `α·v²·T` dissipated. The formula holds for a *free* body: a handle held by a hand,
//! or a body resting on a wall, is accelerated by the other forces too (in a held contact not at
//! all), so `F²·T²/(2m)` is an upper bound of the self-term, not the plant's work (a controller
//! booked on it was tried and not adopted, docs/TELEOP.md). Pure, no allocation.

/// The work (J) of a force `f` (N, or N·m) held for `dt` (s) on a free body of mass `m` (kg, or
/// kg·m²) moving at `v` (m/s, or rad/s) at the start: `f·v·dt + f²·dt²/(2m)`. A mass ≤ 0 or a
/// non-finite one books `f·v·dt` alone.
pub fn held_work(f: f64, v: f64, m: f64, dt: f64) -> f64 {
    let own = if m.is_finite() && m > 0.0 {
        f * f * dt * dt / (2.0 * m)
    } else {
        0.0
    };
    f * v * dt + own
}

/// The velocity (m/s) to book a held force with, `v + f·dt/(2m)`, so that `f·v_booked·dt` is
/// [`held_work`].
pub fn booked_velocity(f: f64, v: f64, m: f64, dt: f64) -> f64 {
    if m.is_finite() && m > 0.0 {
        v + f * dt / (2.0 * m)
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The work on a free point mass under a held force by the energy theorem: the change of its
    /// kinetic energy, its velocity stepped in 10 000 sub-steps.
    fn exact_work(f: f64, v: f64, m: f64, dt: f64) -> f64 {
        let n = 10_000;
        let mut u = v;
        for _ in 0..n {
            u += f / m * dt / n as f64;
        }
        0.5 * m * (u * u - v * v)
    }

    #[test]
    fn the_held_work_is_the_work_on_a_free_mass_over_the_period() {
        for (f, v) in [(2.0, 0.01), (-3.0, 0.02), (1.0, -0.05), (0.5, 0.0)] {
            let (m, dt) = (0.2, 1e-3);
            assert!((held_work(f, v, m, dt) - exact_work(f, v, m, dt)).abs() < 1e-15);
            assert!(
                (f * booked_velocity(f, v, m, dt) * dt - exact_work(f, v, m, dt)).abs() < 1e-15
            );
        }
    }

    #[test]
    fn a_damping_at_the_explicit_cap_does_no_work_though_f_v_t_books_it_as_dissipated() {
        // α = 2m/T: the velocity reverses in one period (v → −v): no work, kinetic energy kept.
        let (m, dt, v) = (0.2, 1e-3, 0.03);
        let f = -(2.0 * m / dt) * v;
        assert!(exact_work(f, v, m, dt).abs() < 1e-12);
        assert!(held_work(f, v, m, dt).abs() < 1e-15);
        // …while F·v·T books 0.36 mJ dissipated in that one period.
        assert!(f * v * dt < -3e-4);
    }
}
