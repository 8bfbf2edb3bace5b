//! The plot of `haptic2d teleop --stability --stability-plot DIR`: the delay margin of the linear
//! teleoperation loop ([`super::delayed`]) against the coupling stiffness, position–force and
//! four-channel, the coupling's damping and everything else as in the run.

use std::path::{Path, PathBuf};

use crate::network::{Architecture, FourChannel, Teleop};
use crate::plot::{write_panels, Panel, Series, Stroke};

use super::delayed::DelayedLoop;

/// Coupling stiffnesses plotted (N/m): 50 to 5 000, 10 a decade.
pub fn stiffnesses() -> Vec<f64> {
    (0..=20)
        .map(|i| 50.0 * 10f64.powf(i as f64 / 10.0))
        .collect()
}

/// Writes `<dir>/teleop-margin.svg` and `.png`. Margins that are infinite (stable at every
/// delay) or zero (unstable without delay) are left out of the curve.
pub fn write_margin_plot(cfg: &Teleop, dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut series = Vec::new();
    for (i, name) in ["position-force", "four-channel"].iter().enumerate() {
        let mut pts = Vec::new();
        for k in stiffnesses() {
            let mut c = *cfg;
            (c.k[0], c.k[1]) = (k, k);
            c.architecture = if i == 0 {
                Architecture::PositionForce
            } else {
                Architecture::FourChannel(FourChannel::lawrence(c.k, c.b))
            };
            let d = DelayedLoop::of_teleop(&c)?.margin()?;
            if d.round_trip.is_finite() && d.round_trip > 0.0 {
                pts.push((k, d.round_trip * 1e3));
            }
        }
        series.push(Series::new(*name, pts, i, Stroke::Solid));
    }
    let panel = Panel {
        title: format!(
            "delay margin, coupling damping {} N s/m, wall {} N/m",
            cfg.b[0], cfg.k_wall
        ),
        x_label: "coupling stiffness (N/m)".into(),
        y_label: "largest stable round trip (ms)".into(),
        series,
        log_x: true,
        log_y: true,
        ..Panel::default()
    };
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    write_panels(
        &dir.join("teleop-margin"),
        "teleoperation: delay margin of the linear loop (x axis, no TDPA)",
        &[panel],
        1,
        (720, 480),
    )
}
