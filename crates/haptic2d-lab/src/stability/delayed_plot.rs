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

/// Round trip at which the stiffnesses stable at every round trip are drawn (ms).
pub const EVERY_DELAY_MS: f64 = 1000.0;

/// Writes `<dir>/teleop-margin.svg` and `.png`. A finite margin is a line (broken where the
/// margin is not finite); a loop stable at every round trip is a square at
/// [`EVERY_DELAY_MS`]; one unstable without delay is left out.
pub fn write_margin_plot(cfg: &Teleop, dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut series = Vec::new();
    for (i, name) in ["position-force", "four-channel"].iter().enumerate() {
        let (mut seg, mut every) = (Vec::new(), Vec::new());
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
                seg.push((k, d.round_trip * 1e3));
                continue;
            }
            if d.round_trip.is_infinite() {
                every.push((k, EVERY_DELAY_MS));
            }
            if !seg.is_empty() {
                let label = if series.iter().any(|x: &Series| x.color == i) {
                    ""
                } else {
                    *name
                };
                series.push(Series::new(
                    label,
                    std::mem::take(&mut seg),
                    i,
                    Stroke::LineMarkers,
                ));
            }
        }
        if !seg.is_empty() {
            let label = if series.iter().any(|x: &Series| x.color == i) {
                ""
            } else {
                *name
            };
            series.push(Series::new(label, seg, i, Stroke::LineMarkers));
        }
        if !every.is_empty() {
            let label = format!("{name}: stable at every round trip (drawn at 1 s)");
            series.push(Series::new(label, every, i, Stroke::Squares));
        }
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
