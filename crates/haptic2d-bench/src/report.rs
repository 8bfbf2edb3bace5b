//! Output of a comparison: the console table, `compare.json` and `compare.svg` (step time vs N).

use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// One line of the comparison.
pub struct Row {
    /// Scene label.
    pub scene: String,
    /// Number of dynamic bodies.
    pub n: usize,
    /// haptic2d median step time (µs).
    pub haptic_median_us: f64,
    /// haptic2d 99th-percentile step time (µs).
    pub haptic_p99_us: f64,
    /// rapier2d median step time (µs).
    pub rapier_median_us: f64,
    /// rapier2d 99th-percentile step time (µs).
    pub rapier_p99_us: f64,
    /// Sanity check after the run, haptic2d: (largest body speed m/s, mean centre height m).
    pub haptic_state: (f64, f64),
    /// The same for rapier2d.
    pub rapier_state: (f64, f64),
}

impl Row {
    /// haptic2d median / rapier2d median.
    pub fn ratio(&self) -> f64 {
        self.haptic_median_us / self.rapier_median_us
    }
}

/// The table printed to stdout.
pub fn table(rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<14} {:>5} | {:>12} {:>12} | {:>12} {:>12} | {:>6} | {:>21} | {:>21}",
        "scene",
        "n",
        "haptic2d med",
        "haptic2d p99",
        "rapier2d med",
        "rapier2d p99",
        "ratio",
        "haptic2d |v|max, ȳ",
        "rapier2d |v|max, ȳ"
    );
    let _ = writeln!(s, "{}", "-".repeat(140));
    for r in rows {
        let _ = writeln!(
            s,
            "{:<14} {:>5} | {:>9.2} µs {:>9.2} µs | {:>9.2} µs {:>9.2} µs | {:>6.3} | {:>8.4} m/s {:>6.3} m | {:>8.4} m/s {:>6.3} m",
            r.scene,
            r.n,
            r.haptic_median_us,
            r.haptic_p99_us,
            r.rapier_median_us,
            r.rapier_p99_us,
            r.ratio(),
            r.haptic_state.0,
            r.haptic_state.1,
            r.rapier_state.0,
            r.rapier_state.1
        );
    }
    s
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.4}")
    } else {
        "null".into()
    }
}

/// `compare.json`: a list of `{"scene","n","haptic2d_median_us","haptic2d_p99_us","rapier2d_median_us",
/// "rapier2d_p99_us","ratio"}`.
pub fn json(rows: &[Row]) -> String {
    let items: Vec<String> = rows
        .iter()
        .map(|r| {
            format!(
                "  {{\"scene\": \"{}\", \"n\": {}, \"haptic2d_median_us\": {}, \"haptic2d_p99_us\": {}, \"rapier2d_median_us\": {}, \"rapier2d_p99_us\": {}, \"ratio\": {}}}",
                r.scene.replace('"', "'"),
                r.n,
                num(r.haptic_median_us),
                num(r.haptic_p99_us),
                num(r.rapier_median_us),
                num(r.rapier_p99_us),
                num(r.ratio())
            )
        })
        .collect();
    format!("[\n{}\n]\n", items.join(",\n"))
}

/// Writes `compare.svg`: median (solid) and p99 (thin) step time vs N for the `pile` rows, log–log.
pub fn svg(rows: &[Row], path: &Path) -> Result<(), String> {
    // With the workspace's plotters features unified (the lab enables ab_glyph), text needs a
    // registered font: use the lab's embedded one.
    haptic2d_lab::plot::register_font();
    let pile: Vec<&Row> = rows.iter().filter(|r| r.scene == "pile").collect();
    if pile.is_empty() {
        return Ok(());
    }
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let n_lo = pile.iter().map(|r| r.n).min().unwrap_or(1) as f64;
    let n_hi = pile.iter().map(|r| r.n).max().unwrap_or(1) as f64;
    let times = pile.iter().flat_map(|r| {
        [
            r.haptic_median_us,
            r.haptic_p99_us,
            r.rapier_median_us,
            r.rapier_p99_us,
        ]
    });
    let t_lo = times.clone().fold(f64::INFINITY, f64::min).max(1e-3);
    let t_hi = times.fold(0.0, f64::max).max(t_lo * 10.0);
    let root = SVGBackend::new(path, (720, 480)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Step time vs number of boxes (pile, dt = 1 ms)",
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(
            ((n_lo * 0.8)..(n_hi * 1.25)).log_scale(),
            ((t_lo * 0.5)..(t_hi * 2.0)).log_scale(),
        )
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("boxes N")
        .y_desc("step time (µs)")
        .draw()
        .map_err(|e| err(&e))?;
    type Series = (&'static str, RGBColor, fn(&Row) -> f64, u32);
    let series: [Series; 4] = [
        ("haptic2d median", BLUE, |r| r.haptic_median_us, 2),
        ("haptic2d p99", BLUE, |r| r.haptic_p99_us, 1),
        ("rapier2d median", RED, |r| r.rapier_median_us, 2),
        ("rapier2d p99", RED, |r| r.rapier_p99_us, 1),
    ];
    for (label, color, get, width) in series {
        let pts: Vec<(f64, f64)> = pile.iter().map(|r| (r.n as f64, get(r))).collect();
        let style = color.stroke_width(width);
        chart
            .draw_series(LineSeries::new(pts.clone(), style))
            .map_err(|e| err(&e))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
            .map_err(|e| err(&e))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
