//! Output of a comparison: the console table, `compare.json` and `compare.svg` (step time vs N).

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

use crate::state::State;

/// One engine's result on one case.
pub struct EngineResult {
    /// JSON key prefix and table label (`haptic2d`, `rapier2d`, `box2d`, `box2d_1sub`, `box2d_avx2`, ...).
    pub key: String,
    /// Median step time (µs).
    pub median_us: f64,
    /// 99th-percentile step time (µs).
    pub p99_us: f64,
    /// 99th-percentile step time (µs) without the first step of each interleaved chunk (the
    /// step that runs right after the other engines, with its data evicted from the caches).
    pub p99_warm_us: f64,
    /// Median of the first steps of the interleaved chunks (µs): what a step costs right after
    /// the other engines ran. They are `1/chunk` of the steps (2 % by default), so when they
    /// cost more than the others they alone set the p99.
    pub chunk_start_us: f64,
    /// Settle state after the run.
    pub state: State,
}

/// Label of the reference workload in the table, `compare.json` and `steps.csv`.
pub const REFERENCE: &str = "reference";

/// The reference workload's result on one case (`reference.rs`): the machine's spread.
pub struct ReferenceResult {
    /// Bytes one step touches.
    pub bytes: usize,
    /// Median step time (µs).
    pub median_us: f64,
    /// 99th-percentile step time (µs).
    pub p99_us: f64,
    /// 99th-percentile step time (µs) without the first step of each interleaved chunk.
    pub p99_warm_us: f64,
    /// Median of the first steps of the interleaved chunks (µs).
    pub chunk_start_us: f64,
}

/// One line of the comparison: haptic2d first, then the other engines.
pub struct Row {
    /// Scene label.
    pub scene: String,
    /// Number of dynamic bodies.
    pub n: usize,
    /// Results, haptic2d at index 0.
    pub engines: Vec<EngineResult>,
    /// The reference workload, interleaved with the engines in the same run.
    pub reference: ReferenceResult,
}

impl Row {
    /// haptic2d median / engine `k`'s median.
    pub fn ratio(&self, k: usize) -> f64 {
        self.engines[0].median_us / self.engines[k].median_us
    }
    /// haptic2d p99 / engine `k`'s p99.
    pub fn ratio_p99(&self, k: usize) -> f64 {
        self.engines[0].p99_us / self.engines[k].p99_us
    }
}

/// Appends one CSV line per timed step of `engine` to `csv` (`scene,n,engine,step,sample,us`):
/// `step` counts the timed steps, `sample` the engine's steps since the start (`warmup + step`).
pub fn step_rows(
    csv: &mut String,
    scene: &str,
    n: usize,
    engine: &str,
    warmup: usize,
    t: &crate::timing::Samples,
) {
    for (i, us) in t.0.iter().enumerate() {
        let _ = writeln!(csv, "{scene},{n},{engine},{i},{},{us:.3}", warmup + i);
    }
}

/// One line of [`table`]: an engine's times (µs) on row `r` and its two ratio columns, as text.
/// The times are `[median, p99, p99 warm, chunk start]`.
fn row(
    s: &mut String,
    r: &Row,
    engine: &str,
    [median_us, p99_us, p99_warm_us, chunk_start_us]: [f64; 4],
    (ratio, ratio_p99): (String, String),
) {
    let _ = writeln!(
        s,
        "{:<13} {:>5} | {:<15} {:>10.2} {:>10.2} {:>7.2} {:>8.2} {:>9.2} {:>+10.2} | {:>7} {:>7}",
        r.scene,
        r.n,
        engine,
        median_us,
        p99_us,
        p99_us / median_us,
        p99_warm_us / median_us,
        chunk_start_us / median_us,
        chunk_start_us - median_us,
        ratio,
        ratio_p99
    );
}

/// The tables printed to stdout: step times with ratios (haptic2d / engine, median and p99), then the
/// settle state after the run.
pub fn table(rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<13} {:>5} | {:<15} {:>10} {:>10} {:>7} {:>8} {:>9} {:>10} | {:>7} {:>7}",
        "scene",
        "n",
        "engine",
        "median µs",
        "p99 µs",
        "p99/med",
        "warm/med",
        "start/med",
        "start +µs",
        "ratio",
        "p99 rat"
    );
    let _ = writeln!(s, "{}", "-".repeat(116));
    for r in rows {
        for (k, e) in r.engines.iter().enumerate() {
            let ratios = (
                format!("{:.3}", r.ratio(k)),
                format!("{:.3}", r.ratio_p99(k)),
            );
            let times = [e.median_us, e.p99_us, e.p99_warm_us, e.chunk_start_us];
            row(&mut s, r, &e.key, times, ratios);
        }
        let e = &r.reference;
        let dash = ("—".to_string(), "—".to_string());
        let times = [e.median_us, e.p99_us, e.p99_warm_us, e.chunk_start_us];
        row(&mut s, r, REFERENCE, times, dash);
    }
    let _ = writeln!(
        s,
        "\n{REFERENCE}: the same shuffled pass over one buffer every step, sized in the warm-up to take haptic2d's median warm-up step ({}); its spread is the machine's, not an engine's.",
        rows.iter()
            .map(|r| format!("{} {}: {} KiB", r.scene, r.n, r.reference.bytes >> 10))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        s,
        "\n{:<13} {:>5} | {:<15} {:>10} {:>8} {:>8} {:>11}",
        "scene", "n", "engine", "|v|max m/s", ">1cm/s", "ȳ m", "overlap mm"
    );
    let _ = writeln!(s, "{}", "-".repeat(80));
    for r in rows {
        for e in &r.engines {
            let _ = writeln!(
                s,
                "{:<13} {:>5} | {:<15} {:>10.4} {:>8} {:>8.4} {:>11.3}",
                r.scene,
                r.n,
                e.key,
                e.state.max_speed,
                e.state.moving,
                e.state.mean_height,
                e.state.max_overlap * 1e3
            );
        }
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

/// `compare.json`: a list of objects `{"scene", "n", "haptic2d_median_us", "haptic2d_p99_us",
/// "rapier2d_median_us", "rapier2d_p99_us", "ratio", "box2d_median_us", "box2d_p99_us",
/// "ratio_box2d", "ratio_p99_box2d", ...}`: for every engine `K` but haptic2d `K_median_us`,
/// `K_p99_us`, `ratio_K` and `ratio_p99_K` (`ratio` alone is rapier2d's, as before), for every
/// engine `K_p99_warm_us` (the p99 without the first step of each interleaved chunk),
/// `K_chunk_start_us` (the median of those first steps) and the settle state `K_max_speed`,
/// `K_moving`, `K_mean_height`, `K_max_overlap` (SI units); and the reference workload's
/// `reference_median_us`, `reference_p99_us`, `reference_p99_warm_us`,
/// `reference_chunk_start_us` and `reference_bytes`.
pub fn json(rows: &[Row]) -> String {
    let items: Vec<String> = rows
        .iter()
        .map(|r| {
            let mut f = vec![
                format!("\"scene\": \"{}\"", r.scene.replace('"', "'")),
                format!("\"n\": {}", r.n),
            ];
            for (k, e) in r.engines.iter().enumerate() {
                f.push(format!("\"{}_median_us\": {}", e.key, num(e.median_us)));
                f.push(format!("\"{}_p99_us\": {}", e.key, num(e.p99_us)));
                f.push(format!("\"{}_p99_warm_us\": {}", e.key, num(e.p99_warm_us)));
                f.push(format!(
                    "\"{}_chunk_start_us\": {}",
                    e.key,
                    num(e.chunk_start_us)
                ));
                if k > 0 {
                    if e.key == "rapier2d" {
                        f.push(format!("\"ratio\": {}", num(r.ratio(k))));
                    }
                    f.push(format!("\"ratio_{}\": {}", e.key, num(r.ratio(k))));
                    f.push(format!("\"ratio_p99_{}\": {}", e.key, num(r.ratio_p99(k))));
                }
                f.push(format!(
                    "\"{}_max_speed\": {}",
                    e.key,
                    num(e.state.max_speed)
                ));
                f.push(format!("\"{}_moving\": {}", e.key, e.state.moving));
                f.push(format!(
                    "\"{}_mean_height\": {}",
                    e.key,
                    num(e.state.mean_height)
                ));
                f.push(format!(
                    "\"{}_max_overlap\": {}",
                    e.key,
                    num(e.state.max_overlap)
                ));
            }
            let e = &r.reference;
            f.push(format!("\"{REFERENCE}_median_us\": {}", num(e.median_us)));
            f.push(format!("\"{REFERENCE}_p99_us\": {}", num(e.p99_us)));
            f.push(format!(
                "\"{REFERENCE}_p99_warm_us\": {}",
                num(e.p99_warm_us)
            ));
            f.push(format!(
                "\"{REFERENCE}_chunk_start_us\": {}",
                num(e.chunk_start_us)
            ));
            f.push(format!("\"{REFERENCE}_bytes\": {}", e.bytes));
            format!("  {{{}}}", f.join(", "))
        })
        .collect();
    format!("[\n{}\n]\n", items.join(",\n"))
}

/// Engine colours, in the order of a row's engines.
const COLORS: [RGBColor; 5] = [BLUE, RED, GREEN, MAGENTA, CYAN];

/// The chart both plots share, of `size` pixels at `path`: the caption, `x` with its description,
/// step time on the y axis (µs, log scale over `t`), the series `draw` adds, and their legend at
/// `legend`.
fn plot<X>(
    path: &Path,
    size: (u32, u32),
    caption: &str,
    (x, x_desc): (X, &str),
    t: std::ops::Range<f64>,
    legend: SeriesLabelPosition,
    draw: impl FnOnce(
        &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<X::CoordDescType, LogCoord<f64>>>,
    ) -> Result<(), String>,
) -> Result<(), String>
where
    X: AsRangedCoord,
    X::CoordDescType: ValueFormatter<<X::CoordDescType as Ranged>::ValueType>,
{
    // With the workspace's plotters features unified (the lab enables ab_glyph), text needs a
    // registered font: use the lab's embedded one.
    haptic2d_lab::plot::register_font();
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x, t.log_scale())
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc("step time (µs)")
        .draw()
        .map_err(|e| err(&e))?;
    draw(&mut chart).map_err(|e| err(&e))?;
    chart
        .configure_series_labels()
        .position(legend)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// Writes `compare.svg`: median (solid) and p99 (thin) step time vs N for the `pile` rows, log–log.
pub fn svg(rows: &[Row], path: &Path) -> Result<(), String> {
    let pile: Vec<&Row> = rows.iter().filter(|r| r.scene == "pile").collect();
    if pile.is_empty() {
        return Ok(());
    }
    let n_lo = pile.iter().map(|r| r.n).min().unwrap_or(1) as f64;
    let n_hi = pile.iter().map(|r| r.n).max().unwrap_or(1) as f64;
    let times = pile
        .iter()
        .flat_map(|r| r.engines.iter().flat_map(|e| [e.median_us, e.p99_us]));
    let t_lo = times.clone().fold(f64::INFINITY, f64::min).max(1e-3);
    let t_hi = times.fold(0.0, f64::max).max(t_lo * 10.0);
    plot(
        path,
        (720, 480),
        "Step time vs number of boxes (pile, dt = 1 ms)",
        (((n_lo * 0.8)..(n_hi * 1.25)).log_scale(), "boxes N"),
        (t_lo * 0.5)..(t_hi * 2.0),
        SeriesLabelPosition::UpperLeft,
        |chart| {
            let n_eng = pile[0].engines.len();
            for k in 0..n_eng {
                let color = COLORS[k % COLORS.len()];
                let key = pile[0].engines[k].key.clone();
                for (what, width) in [("median", 2u32), ("p99", 1)] {
                    let pts: Vec<(f64, f64)> = pile
                        .iter()
                        .filter(|r| r.engines.len() == n_eng)
                        .map(|r| {
                            let e = &r.engines[k];
                            (r.n as f64, if width == 2 { e.median_us } else { e.p99_us })
                        })
                        .collect();
                    let style = color.stroke_width(width);
                    chart
                        .draw_series(LineSeries::new(pts.clone(), style))
                        .map_err(|e| e.to_string())?
                        .label(format!("{key} {what}"))
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                    chart
                        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
                        .map_err(|e| e.to_string())?;
                }
            }
            Ok(())
        },
    )
}

/// Every timed step of every engine on one case, step time (µs, log scale) against the step
/// index: the interleaved chunks' cold first steps, the machine's slow bursts and any periodic
/// spike show as what they are. Written by `--step-times` as `steps_<scene>_<n>.svg`.
pub fn steps_svg(
    label: &str,
    keys: &[String],
    samples: &[&crate::timing::Samples],
    path: &Path,
) -> Result<(), String> {
    let all = samples.iter().flat_map(|s| s.0.iter().copied());
    let t_lo = all
        .clone()
        .filter(|t| *t > 0.0)
        .fold(f64::INFINITY, f64::min)
        .max(1e-3);
    let t_hi = all.fold(0.0, f64::max).max(t_lo * 10.0);
    let steps = samples.iter().map(|s| s.0.len()).max().unwrap_or(1).max(2);
    plot(
        path,
        (960, 480),
        &format!("Every timed step, {label} (dt = 1 ms)"),
        (0f64..steps as f64, "timed step"),
        (t_lo * 0.8)..(t_hi * 1.25),
        SeriesLabelPosition::UpperRight,
        |chart| {
            for (k, (key, s)) in keys.iter().zip(samples).enumerate() {
                let color = COLORS[k % COLORS.len()];
                // Log scale: a zero time (below the clock's resolution) cannot be drawn.
                let pts: Vec<(f64, f64)> =
                    s.0.iter()
                        .enumerate()
                        .filter(|(_, t)| **t > 0.0)
                        .map(|(i, &t)| (i as f64, t))
                        .collect();
                let style = color.mix(0.7).stroke_width(1);
                chart
                    .draw_series(LineSeries::new(pts, style))
                    .map_err(|e| e.to_string())?
                    .label(format!(
                        "{key}: median {:.1} µs, p99 {:.1} µs",
                        s.median(),
                        s.p99()
                    ))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
            }
            Ok(())
        },
    )
}
