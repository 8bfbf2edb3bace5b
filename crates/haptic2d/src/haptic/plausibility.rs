//! Plausibility limits on the device's joint readings (DESIGN §7), shared by every system: a joint
//! angle beyond `±max_joint_angle` or a joint speed between two readings above `max_joint_speed`
//! is no motion a hand can make but an encoder or driver fault (a garbage word read as 1e30 rad, a
//! re-zeroed encoder, a burst of lost counts), and trips the latch in the tick that reads it, before
//! any kinematics runs on it. Non-finite readings are left to the device model (a lost reading).

use super::safety::{SafetyConfig, SafetyReason};

/// The check and the previous reading it differentiates against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointPlausibility {
    /// Bound on `|q_i|` (rad).
    pub max_angle: f64,
    /// Bound on `|Δq_i| / Δt` (rad/s).
    pub max_speed: f64,
    prev: [f64; 4],
    have_prev: bool,
}

impl JointPlausibility {
    /// The bounds of `config` (`max_joint_angle`, `max_joint_speed`).
    pub fn new(config: &SafetyConfig) -> Self {
        Self {
            max_angle: config.max_joint_angle,
            max_speed: config.max_joint_speed,
            prev: [0.0; 4],
            have_prev: false,
        }
    }

    /// Checks the joint angles `q` (rad, at most 4) read `elapsed` s after the previous reading;
    /// the first joint out of bounds is the reason. Never allocates.
    #[inline]
    pub fn check(&mut self, q: &[f64], elapsed: f64) -> Option<SafetyReason> {
        let n = q.len().min(4);
        let mut reason = None;
        let mut finite = true;
        for (index, &value) in q[..n].iter().enumerate() {
            if !value.is_finite() {
                finite = false;
                continue;
            }
            if reason.is_none() && value.abs() > self.max_angle {
                reason = Some(SafetyReason::JointAngle {
                    index,
                    value,
                    limit: self.max_angle,
                });
            }
            if reason.is_none() && self.have_prev && elapsed > 0.0 {
                let speed = (value - self.prev[index]).abs() / elapsed;
                if speed > self.max_speed {
                    reason = Some(SafetyReason::JointSpeed {
                        index,
                        value: speed,
                        limit: self.max_speed,
                    });
                }
            }
        }
        self.prev[..n].copy_from_slice(&q[..n]);
        self.have_prev = finite;
        reason
    }

    /// The angle bound alone, for a paused tick (the handle moves freely while the world stands
    /// still): the reading is not differentiated, and the next one is not differentiated against
    /// it. Never allocates.
    #[inline]
    pub fn check_angles(&mut self, q: &[f64]) -> Option<SafetyReason> {
        self.have_prev = false;
        let n = q.len().min(4);
        q[..n]
            .iter()
            .enumerate()
            .find(|(_, v)| v.is_finite() && v.abs() > self.max_angle)
            .map(|(index, &value)| SafetyReason::JointAngle {
                index,
                value,
                limit: self.max_angle,
            })
    }

    /// Forgets the previous reading (after a re-arm): the next reading is not differentiated.
    pub fn reset(&mut self) {
        self.have_prev = false;
    }
}
