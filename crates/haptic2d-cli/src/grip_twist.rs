//! The twist target from a sensed handle orientation (an Inverse3's VerseGrip): the slave's angle at
//! the first reading plus the handle's turn since then, so nothing jumps at the start whatever the
//! grip's yaw is when the loop begins.
//!
//! ```text
//! θ_t,k = θ_s,0 + Σ_{j ≤ k} wrap(a_j − a_{j−1}),   wrap(x) ∈ (−π, π]
//! ```
//!
//! with `a_j` the reported angle (rad, in (−π, π]) and `θ_s,0` the slave's angle at the first
//! reading. Summing the wrapped steps unwraps the reported angle, so turning the grip past ±π keeps
//! turning the slave the same way (the body's angle is unwrapped too).

use std::f64::consts::{PI, TAU};

/// The running state: `None` until the first reading.
#[derive(Debug, Clone, Copy, Default)]
pub struct GripTwist {
    /// (last reported angle, current target) (rad).
    state: Option<(f64, f64)>,
}

impl GripTwist {
    /// The twist target (rad) for the reported angle `a` (rad), with `slave_angle` (rad) the slave's
    /// angle, used only at the first reading. A non-finite `a` keeps the previous target.
    pub fn target(&mut self, a: f64, slave_angle: f64) -> Option<f64> {
        if !a.is_finite() {
            return self.state.map(|(_, t)| t);
        }
        let t = match self.state {
            None => slave_angle,
            Some((last, t)) => t + wrap(a - last),
        };
        self.state = Some((a, t));
        Some(t)
    }

    /// Forgets the anchor (a rebuilt system: the next reading anchors again).
    pub fn reset(&mut self) {
        self.state = None;
    }
}

/// `x` wrapped into (−π, π] (rad).
fn wrap(x: f64) -> f64 {
    let y = x.rem_euclid(TAU);
    if y > PI {
        y - TAU
    } else {
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_reading_anchors_at_the_slave_angle_and_turns_follow() {
        let mut g = GripTwist::default();
        assert_eq!(g.target(1.2, 0.1), Some(0.1));
        let t = g.target(1.5, 99.0).unwrap();
        assert!((t - 0.4).abs() < 1e-12, "{t}");
        let t = g.target(1.0, 99.0).unwrap();
        assert!((t + 0.1).abs() < 1e-12, "{t}");
    }

    #[test]
    fn turning_past_pi_keeps_turning_the_same_way() {
        let mut g = GripTwist::default();
        g.target(3.0, 0.0);
        // 3.0 → −3.0 is a turn of +0.283 rad, not −6.
        let t = g.target(-3.0, 0.0).unwrap();
        assert!((t - (TAU - 6.0)).abs() < 1e-12, "{t}");
    }

    #[test]
    fn a_non_finite_reading_keeps_the_target_and_reset_re_anchors() {
        let mut g = GripTwist::default();
        assert_eq!(g.target(f64::NAN, 0.3), None);
        g.target(0.5, 0.3);
        assert_eq!(g.target(f64::NAN, 0.0), Some(0.3));
        g.reset();
        assert_eq!(g.target(2.0, -0.7), Some(-0.7));
    }
}
