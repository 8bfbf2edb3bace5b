//! The plot of `haptic2d stability`: per axis, the right-most continuous pole's real part and the
//! sampled-data growth rate against the hand's impedance, from released (0) to twice the grip.

use std::path::{Path, PathBuf};

use crate::plot::{write_panels, Panel, Series, Stroke};

use super::loop_model::{LoopModel, LoopPoles, AXES};

/// Hand impedance scales plotted (× the grip), 0 = released.
pub fn hand_scales() -> Vec<f64> {
    (0..=40).map(|i| i as f64 * 0.05).collect()
}

/// Writes `<dir>/<stem>.svg` and `.png`: one panel per axis.
pub fn write_pole_plot(
    model: &LoopModel,
    dir: &Path,
    stem: &str,
    title: &str,
) -> Result<Vec<PathBuf>, String> {
    let mut panels = Vec::new();
    let axes = model.analyse()?;
    for (i, r) in axes.iter().enumerate() {
        let a = &r.model;
        let (mut cont, mut samp) = (Vec::new(), Vec::new());
        for lam in hand_scales() {
            let mut h = *a;
            h.k_h = lam * a.k_h;
            h.b_h = lam * a.b_h;
            let p = LoopPoles::of(&h, model.dt, model.delay)?;
            cont.push((lam, p.rightmost().0));
            samp.push((lam, p.growth));
        }
        panels.push(Panel {
            title: format!("axis {} ({} spring)", AXES[i], r.contact),
            x_label: "hand impedance (x grip: 300 N/m, 5 N s/m; 0 = released)".into(),
            y_label: "growth rate (1/s)".into(),
            series: vec![
                Series::new("right-most continuous pole Re s", cont, 0, Stroke::Solid),
                Series::new("sampled-data ln(rho)/T", samp, 1, Stroke::Solid),
            ],
            h_lines: vec![0.0],
            ..Panel::default()
        });
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    write_panels(&dir.join(stem), title, &panels, 3, (520, 380))
}
