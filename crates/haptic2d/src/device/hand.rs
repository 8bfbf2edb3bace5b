//! Simulated hand models: the wrench (N, N, N·m) a hand applies to the handle, from the handle state
//! and time. Used with the simulated device plant ([`super::sim::SimDevice`]) when no hardware and no
//! person are present. The hand is massless in all models (its mass can be lumped into the device).

use crate::geom::wrap_angle;

use super::linalg::V3;

/// A hand model. All vectors are handle-space `(x, y, θ)` 3-vectors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HandModel {
    /// No hand: zero wrench.
    Free,
    /// A constant wrench `wrench` (N, N, N·m).
    Constant {
        /// The applied wrench (N, N, N·m).
        wrench: V3,
    },
    /// A spring–damper hand pulling the handle toward `target`:
    /// `W = K·(target − x) − B·ẋ`, with the θ error wrapped to `(−π, π]` (shortest way round).
    SpringDamper {
        /// Target pose (m, m, rad); settable at run time with [`HandModel::set_target`].
        target: V3,
        /// Stiffness `K` per DOF (N/m, N/m, N·m/rad). Typical grip: (300, 300, 0.5).
        stiffness: V3,
        /// Damping `B` per DOF (N·s/m, N·s/m, N·m·s/rad). Typical grip: (5, 5, 0.005).
        damping: V3,
    },
    /// A unidirectional sinusoidal push `W = d·F_pk·(1 − cos 2πft)/2` (never reverses sign), as in the
    /// Fig. 7 peg experiment.
    Sinusoid {
        /// Direction `d` (dimensionless; normalise it for `F_pk` to be the peak magnitude).
        direction: V3,
        /// Peak magnitude `F_pk` (N, or N·m along a pure θ direction).
        peak: f64,
        /// Frequency `f` (Hz).
        frequency: f64,
    },
    /// A scripted sequence: for `t < t_hold` hold the handle at `pose` with the spring–damper
    /// `(stiffness, damping)`; for `t_hold ≤ t < t_hold + t_push` apply the constant wrench `push`;
    /// afterwards (released) apply the constant wrench `release` (zero for a full release).
    Scripted {
        /// Hold pose (m, m, rad).
        pose: V3,
        /// Hold stiffness (N/m, N/m, N·m/rad).
        stiffness: V3,
        /// Hold damping (N·s/m, N·s/m, N·m·s/rad).
        damping: V3,
        /// Hold duration `t1` (s).
        t_hold: f64,
        /// Push wrench (N, N, N·m).
        push: V3,
        /// Push duration (s).
        t_push: f64,
        /// Wrench after release (N, N, N·m).
        release: V3,
    },
    /// An environment rather than a hand: a one-sided spring–damper wall along x filling
    /// `x < surface`. At penetration `p = surface − x > 0` it pushes `+x` with
    /// `F_x = max(0, K·p − B·ẋ)` (it never pulls); out of contact, zero. The simulated slave's
    /// wall of `haptic2d teleop --live` (the lab's teleop wall, docs/TELEOP.md).
    Wall {
        /// The wall's surface (m, handle x).
        surface: f64,
        /// Stiffness `K` (N/m).
        stiffness: f64,
        /// Damping `B` (N·s/m).
        damping: f64,
    },
}

/// `K·(target − x) − B·ẋ` with the θ error wrapped.
#[inline]
fn spring_damper(target: &V3, k: &V3, b: &V3, x: &V3, xd: &V3) -> V3 {
    let err = [
        target[0] - x[0],
        target[1] - x[1],
        wrap_angle(target[2] - x[2]),
    ];
    std::array::from_fn(|i| k[i] * err[i] - b[i] * xd[i])
}

impl HandModel {
    /// A spring–damper hand with typical grip values, `K = (300 N/m, 300 N/m, 0.5 N·m/rad)` and
    /// `B = (5 N·s/m, 5 N·s/m, 0.005 N·m·s/rad)`, following `target`.
    pub fn grip(target: V3) -> Self {
        HandModel::SpringDamper {
            target,
            stiffness: [300.0, 300.0, 0.5],
            damping: [5.0, 5.0, 0.005],
        }
    }

    /// The wrench (N, N, N·m) on the handle at pose `x`, twist `xd` and time `t` (s).
    pub fn wrench(&self, x: &V3, xd: &V3, t: f64) -> V3 {
        match self {
            HandModel::Free => [0.0; 3],
            HandModel::Constant { wrench } => *wrench,
            HandModel::SpringDamper {
                target,
                stiffness,
                damping,
            } => spring_damper(target, stiffness, damping, x, xd),
            HandModel::Sinusoid {
                direction,
                peak,
                frequency,
            } => {
                let s = peak * 0.5 * (1.0 - (std::f64::consts::TAU * frequency * t).cos());
                direction.map(|d| d * s)
            }
            HandModel::Scripted {
                pose,
                stiffness,
                damping,
                t_hold,
                push,
                t_push,
                release,
            } => {
                if t < *t_hold {
                    spring_damper(pose, stiffness, damping, x, xd)
                } else if t < t_hold + t_push {
                    *push
                } else {
                    *release
                }
            }
            HandModel::Wall {
                surface,
                stiffness,
                damping,
            } => {
                let pen = surface - x[0];
                let f = if pen > 0.0 {
                    (stiffness * pen - damping * xd[0]).max(0.0)
                } else {
                    0.0
                };
                [f, 0.0, 0.0]
            }
        }
    }

    /// Moves the target of a spring–damper hand (or the hold pose of a scripted hand) to `target`
    /// (m, m, rad). Returns `false`, changing nothing, for models without a target.
    pub fn set_target(&mut self, new_target: V3) -> bool {
        match self {
            HandModel::SpringDamper { target, .. } => {
                *target = new_target;
                true
            }
            HandModel::Scripted { pose, .. } => {
                *pose = new_target;
                true
            }
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WALL: HandModel = HandModel::Wall {
        surface: 0.10,
        stiffness: 2000.0,
        damping: 2.0,
    };

    /// Hooke's law at rest: 3 mm into a 2 000 N/m wall is 6 N pushing out (+x), whatever y and θ.
    #[test]
    fn a_wall_at_rest_pushes_out_with_stiffness_times_penetration() {
        let f = WALL.wrench(&[0.097, 0.05, 1.0], &[0.0; 3], 0.0);
        assert!((f[0] - 6.0).abs() < 1e-9, "{f:?}");
        assert_eq!((f[1], f[2]), (0.0, 0.0));
    }

    /// Out of contact (at or right of the surface) the wall exerts nothing, even moving into it.
    #[test]
    fn a_wall_out_of_contact_exerts_nothing() {
        for x in [0.10, 0.12] {
            assert_eq!(
                WALL.wrench(&[x, 0.0, 0.0], &[-1.0, 0.0, 0.0], 0.0),
                [0.0; 3]
            );
        }
    }

    /// The damper adds `−B·ẋ`: moving in at 0.5 m/s, 1 mm deep: 2 N + 1 N = 3 N. Leaving fast, the
    /// damper would pull (2 N − 10 N < 0): a one-sided wall never pulls, so zero.
    #[test]
    fn the_damper_resists_motion_but_the_wall_never_pulls() {
        let into = WALL.wrench(&[0.099, 0.0, 0.0], &[-0.5, 0.0, 0.0], 0.0);
        assert!((into[0] - 3.0).abs() < 1e-9, "{into:?}");
        let leaving = WALL.wrench(&[0.099, 0.0, 0.0], &[5.0, 0.0, 0.0], 0.0);
        assert_eq!(leaving, [0.0; 3]);
    }
}
