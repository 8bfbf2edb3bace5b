//! The `[safety]` table every device file may carry (Haply, UDP, Inverse3): the plausibility bounds on
//! the joint readings and the floor of the stall limit, passed to the shared safety layer
//! (`haptic2d::haptic::SafetyConfig`). Absent fields keep the shared defaults.
//!
//! ```toml
//! [safety]
//! max_angle = 12.566        # rad: |q_i| beyond this is an encoder fault (default 4π)
//! max_velocity = 1000.0     # rad/s: |Δq_i|/Δt beyond this is an encoder fault (default 1000)
//! stall_floor = 0.02        # s: the shortest loop stall that trips, whatever the period (default 0.02)
//! ```

use haptic2d::haptic::SafetyConfig;
use haptic2d::scene::SceneError;
use serde::Deserialize;

/// Largest `max_angle` accepted (rad): beyond 100 turns it bounds nothing.
pub const MAX_ANGLE_LIMIT: f64 = 200.0 * std::f64::consts::PI;
/// Largest `max_velocity` accepted (rad/s).
pub const MAX_VELOCITY_LIMIT: f64 = 1.0e5;
/// Largest `stall_floor` accepted (s): a device left unsupervised longer is not a safety setting.
pub const MAX_STALL_FLOOR: f64 = 1.0;

/// The device file's safety settings, validated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceSafety {
    /// Bound on every joint angle `|q_i|` (rad).
    pub max_angle: f64,
    /// Bound on every joint speed between two readings (rad/s).
    pub max_velocity: f64,
    /// Floor of the stall limit `max(max_stall_periods·T, stall_floor)` (s).
    pub stall_floor: f64,
}

impl Default for DeviceSafety {
    /// The shared safety layer's defaults (4π rad, 1000 rad/s, 0.02 s).
    fn default() -> Self {
        let d = SafetyConfig::default();
        Self {
            max_angle: d.max_joint_angle,
            max_velocity: d.max_joint_speed,
            stall_floor: d.min_stall_time,
        }
    }
}

impl DeviceSafety {
    /// `config` with this file's bounds and stall floor.
    pub fn apply(&self, config: SafetyConfig) -> SafetyConfig {
        SafetyConfig {
            max_joint_angle: self.max_angle,
            max_joint_speed: self.max_velocity,
            min_stall_time: self.stall_floor,
            ..config
        }
    }
}

/// The raw `[safety]` table.
#[derive(Deserialize, Clone, Copy, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct RawSafety {
    max_angle: Option<f64>,
    max_velocity: Option<f64>,
    stall_floor: Option<f64>,
}

impl RawSafety {
    /// Validates the table (errors pushed to `errs`, each naming `safety.FIELD`, the unit and the
    /// fix); absent fields take the defaults.
    pub fn check(raw: Option<&RawSafety>, errs: &mut Vec<SceneError>) -> DeviceSafety {
        let d = DeviceSafety::default();
        let Some(r) = raw else { return d };
        let mut out = d;
        let mut field = |name: &str,
                         v: Option<f64>,
                         lo_ok: bool,
                         max: f64,
                         unit: &str,
                         def: f64| {
            let Some(v) = v else { return def };
            let ok = v.is_finite() && (v > 0.0 || (lo_ok && v == 0.0)) && v <= max;
            if ok {
                v
            } else {
                errs.push(SceneError::new(
                    format!("safety.{name}"),
                    format!(
                        "{v} {unit} is not a bound (must be a finite number {} and at most {max} {unit})",
                        if lo_ok { ">= 0" } else { "> 0" }
                    ),
                    format!("give {name} in {unit}, or leave it out for the default {def}"),
                ));
                def
            }
        };
        out.max_angle = field(
            "max_angle",
            r.max_angle,
            false,
            MAX_ANGLE_LIMIT,
            "rad",
            d.max_angle,
        );
        out.max_velocity = field(
            "max_velocity",
            r.max_velocity,
            false,
            MAX_VELOCITY_LIMIT,
            "rad/s",
            d.max_velocity,
        );
        out.stall_floor = field(
            "stall_floor",
            r.stall_floor,
            true,
            MAX_STALL_FLOOR,
            "s",
            d.stall_floor,
        );
        out
    }
}
