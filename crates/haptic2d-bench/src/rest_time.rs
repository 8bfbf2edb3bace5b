//! `--rest-time SECONDS`: when each engine's scene comes to rest. Runs every engine (untimed) on
//! the selected cases for up to `SECONDS` of simulated time and reports the time from which every
//! dynamic body stays below [`MOVING`] (1 cm/s, the settle state's threshold), checked every
//! 10 ms.

use haptic2d::geom::Vec2;

use crate::state::MOVING;

/// Samples between two checks (10 ms at 1 ms).
const CHECK_EVERY: usize = 10;

/// Result of one engine's run.
#[derive(Clone, Copy, Debug)]
pub struct Rest {
    /// Simulated time (s) from which every dynamic body stayed below [`MOVING`] to the end of the
    /// run; `None` if bodies still moved at the end.
    pub at: Option<f64>,
    /// Bodies at or above [`MOVING`] at the end of the run.
    pub moving_at_end: usize,
    /// Largest speed at the end of the run (m/s).
    pub max_speed_at_end: f64,
}

/// Steps an engine `seconds / dt` times, checking every [`CHECK_EVERY`] steps with `poses`
/// (position, angle, velocity of every body, indexed like `dynamic`).
pub fn run(
    dynamic: &[bool],
    dt: f64,
    seconds: f64,
    step: &mut dyn FnMut(),
    poses: &mut dyn FnMut() -> Vec<(Vec2, f64, Vec2)>,
) -> Rest {
    let steps = (seconds / dt).round() as usize;
    let mut at = None;
    let (mut moving, mut vmax) = (0, 0.0);
    for k in 1..=steps {
        step();
        if k % CHECK_EVERY != 0 && k != steps {
            continue;
        }
        let p = poses();
        let speeds = p
            .iter()
            .zip(dynamic)
            .filter(|(_, &d)| d)
            .map(|(q, _)| q.2.length());
        vmax = speeds.clone().fold(0.0, f64::max);
        moving = speeds.filter(|v| v.is_nan() || *v >= MOVING).count();
        if moving > 0 {
            at = None;
        } else if at.is_none() {
            at = Some(k as f64 * dt);
        }
    }
    Rest {
        at,
        moving_at_end: moving,
        max_speed_at_end: vmax,
    }
}

/// One printed line: `label engine: at rest from 2.35 s` or `still moving at 6 s: 12 bodies …`.
pub fn line(label: &str, engine: &str, seconds: f64, r: &Rest) -> String {
    match r.at {
        Some(t) => format!("{label} {engine}: at rest (all < 1 cm/s) from {t:.2} s to {seconds} s"),
        None => format!(
            "{label} {engine}: still moving at {seconds} s: {} bodies ≥ 1 cm/s, largest {:.4} m/s",
            r.moving_at_end, r.max_speed_at_end
        ),
    }
}
