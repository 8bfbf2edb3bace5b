//! `--push DX,DY,SPEED,AT`: a scripted push by a simulated gripping hand, whose target moves from
//! the start pose in a straight line (the device side of `run --world`, `teleop`'s simulated
//! master).

use haptic2d::device::linalg::V3;

/// A hand target moving in a straight line (the `--push` option).
#[derive(Clone, Copy, Debug)]
pub struct Push {
    /// Displacement (m, m).
    d: [f64; 2],
    /// Speed (m/s).
    speed: f64,
    /// Start time (s).
    at: f64,
}

impl Push {
    /// Parses `DX,DY,SPEED,AT` (m, m, m/s, s); the error says how to fix it.
    pub fn parse(text: &str) -> Result<Self, String> {
        let v: Vec<f64> = text
            .split(',')
            .map(|p| p.trim().parse::<f64>().unwrap_or(f64::NAN))
            .collect();
        let ok = v.len() == 4 && v.iter().all(|x| x.is_finite()) && v[2] > 0.0 && v[3] >= 0.0;
        let len = if ok { v[0].hypot(v[1]) } else { 0.0 };
        if !ok || len > 0.05 {
            return Err(format!(
                "--push {text}: expected DX,DY,SPEED,AT with |(DX, DY)| ≤ 0.05 m, SPEED > 0 m/s, AT ≥ 0 s\n    fix: e.g. --push -0.015,0,0.05,0.6"
            ));
        }
        Ok(Self {
            d: [v[0], v[1]],
            speed: v[2],
            at: v[3],
        })
    }

    /// The target at time `t` (s) from the start pose `origin`.
    pub fn target(&self, origin: &V3, t: f64) -> V3 {
        let len = self.d[0].hypot(self.d[1]);
        let f = if len > 0.0 {
            ((t - self.at).max(0.0) * self.speed / len).min(1.0)
        } else {
            0.0
        };
        [
            origin[0] + f * self.d[0],
            origin[1] + f * self.d[1],
            origin[2],
        ]
    }
}
