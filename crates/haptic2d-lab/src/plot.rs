//! Multi-panel line and marker charts written as SVG and PNG (plotters), with an embedded font.
//!
//! Text is drawn with DejaVu Sans (embedded in the binary and registered as `sans-serif` with plotters'
//! `ab_glyph` backend), so PNG output does not depend on the fonts installed on the machine.

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Once;

/// The embedded font (DejaVu Sans, see `assets/`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
/// The font family name the charts use.
pub const FONT_FAMILY: &str = "sans-serif";

static REGISTER: Once = Once::new();

/// Registers the embedded font with plotters (idempotent).
pub fn register_font() {
    REGISTER.call_once(|| {
        // The embedded file is a valid TrueType font; if registration were refused, text would be
        // skipped by the backend rather than fail the run.
        let _ = plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT);
    });
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stroke {
    /// Solid line.
    Solid,
    /// Dashed line.
    Dashed,
    /// Filled circles at the points, no line.
    Markers,
    /// Solid line with circles at the points.
    LineMarkers,
    /// Filled squares at the points (for grids).
    Squares,
}

/// One series of a panel.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label (empty = not in the legend).
    pub label: String,
    /// Points `(x, y)` in axis units.
    pub points: Vec<(f64, f64)>,
    /// Colour index in the chart palette.
    pub color: usize,
    /// How it is drawn.
    pub stroke: Stroke,
}

impl Series {
    /// A series with `label`, colour index `color` and `stroke`.
    pub fn new(
        label: impl Into<String>,
        points: Vec<(f64, f64)>,
        color: usize,
        stroke: Stroke,
    ) -> Self {
        Self {
            label: label.into(),
            points,
            color,
            stroke,
        }
    }
}

/// One chart of a figure.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    /// Title above the chart.
    pub title: String,
    /// X-axis label, with units.
    pub x_label: String,
    /// Y-axis label, with units.
    pub y_label: String,
    /// The series.
    pub series: Vec<Series>,
    /// Logarithmic x axis (points with `x ≤ 0` are dropped).
    pub log_x: bool,
    /// Logarithmic y axis (points with `y ≤ 0` are dropped).
    pub log_y: bool,
    /// Horizontal reference lines (dotted grey), in y units.
    pub h_lines: Vec<f64>,
    /// Fixed y range, if any (otherwise from the data).
    pub y_range: Option<(f64, f64)>,
}

/// Palette colour `i` (dark, distinguishable).
pub fn color(i: usize) -> RGBColor {
    const C: [RGBColor; 10] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(127, 127, 127),
        RGBColor(188, 189, 34),
        RGBColor(23, 190, 207),
    ];
    C[i % C.len()]
}

/// Draws `panels` in a grid of `cols` columns, each `panel_px` pixels, under an overall `title`, and
/// writes `<stem>.svg` and `<stem>.png`. Returns both paths.
pub fn write_panels(
    stem: &Path,
    title: &str,
    panels: &[Panel],
    cols: usize,
    panel_px: (u32, u32),
) -> Result<Vec<PathBuf>, String> {
    register_font();
    if panels.is_empty() {
        return Err(format!("{}: nothing to plot", stem.display()));
    }
    let cols = cols.clamp(1, panels.len());
    let rows = panels.len().div_ceil(cols);
    let size = (panel_px.0 * cols as u32, panel_px.1 * rows as u32 + 40);
    let svg = stem.with_extension("svg");
    let png = stem.with_extension("png");
    {
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        draw_all(&root, title, panels, rows, cols)?;
        root.present()
            .map_err(|e| format!("cannot write {}: {e}", svg.display()))?;
    }
    {
        let root = BitMapBackend::new(&png, size).into_drawing_area();
        draw_all(&root, title, panels, rows, cols)?;
        root.present()
            .map_err(|e| format!("cannot write {}: {e}", png.display()))?;
    }
    Ok(vec![svg, png])
}

fn err<E: std::fmt::Display>(e: E) -> String {
    format!("plot: {e}")
}

fn draw_all<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    panels: &[Panel],
    rows: usize,
    cols: usize,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, (FONT_FAMILY, 22)).map_err(err)?;
    let areas = root.split_evenly((rows, cols));
    for (area, p) in areas.iter().zip(panels) {
        draw_panel(area, p)?;
    }
    Ok(())
}

/// Data bounds of a panel, padded; honours log axes and a fixed y range.
fn bounds(p: &Panel) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for s in &p.series {
        for &(x, y) in &s.points {
            if !(x.is_finite() && y.is_finite()) || (p.log_x && x <= 0.0) || (p.log_y && y <= 0.0) {
                continue;
            }
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    for &h in &p.h_lines {
        if h.is_finite() && (!p.log_y || h > 0.0) {
            y0 = y0.min(h);
            y1 = y1.max(h);
        }
    }
    if !x0.is_finite() {
        (x0, x1) = (1.0, 10.0);
    }
    if !y0.is_finite() {
        (y0, y1) = (1.0, 10.0);
    }
    if let Some((a, b)) = p.y_range {
        (y0, y1) = (a, b);
    }
    let pad = |a: f64, b: f64, log: bool| {
        if log {
            (a / 1.5, b * 1.5)
        } else if b > a {
            let d = 0.05 * (b - a);
            (a - d, b + d)
        } else {
            let d = if a == 0.0 { 1.0 } else { 0.1 * a.abs() };
            (a - d, b + d)
        }
    };
    let (x0, x1) = if p.log_x {
        pad(x0, x1, true)
    } else {
        (x0, if x1 > x0 { x1 } else { x0 + 1.0 })
    };
    let (y0, y1) = if p.y_range.is_some() {
        (y0, y1)
    } else {
        pad(y0, y1, p.log_y)
    };
    (x0, x1, y0, y1)
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> Result<(), String> {
    let (x0, x1, y0, y1) = bounds(p);
    match (p.log_x, p.log_y) {
        (false, false) => fill(area, p, x0..x1, y0..y1, (x0, x1)),
        (true, false) => fill(area, p, (x0..x1).log_scale(), y0..y1, (x0, x1)),
        (false, true) => fill(area, p, x0..x1, (y0..y1).log_scale(), (x0, x1)),
        (true, true) => fill(
            area,
            p,
            (x0..x1).log_scale(),
            (y0..y1).log_scale(),
            (x0, x1),
        ),
    }
}

fn fill<DB, XR, YR>(
    area: &DrawingArea<DB, Shift>,
    p: &Panel,
    xr: XR,
    yr: YR,
    (x0, x1): (f64, f64),
) -> Result<(), String>
where
    DB: DrawingBackend,
    XR: AsRangedCoord<Value = f64>,
    YR: AsRangedCoord<Value = f64>,
    XR::CoordDescType: ValueFormatter<f64>,
    YR::CoordDescType: ValueFormatter<f64>,
{
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, (FONT_FAMILY, 16))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(75)
        .build_cartesian_2d(xr, yr)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(p.x_label.as_str())
        .y_desc(p.y_label.as_str())
        .label_style((FONT_FAMILY, 12))
        .axis_desc_style((FONT_FAMILY, 13))
        .x_labels(6)
        .y_labels(6)
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    for &h in &p.h_lines {
        if p.log_y && h <= 0.0 {
            continue;
        }
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x0, h), (x1, h)],
                4,
                4,
                ShapeStyle::from(&RGBColor(120, 120, 120)).stroke_width(1),
            ))
            .map_err(err)?;
    }
    let mut any_label = false;
    for s in &p.series {
        let c = color(s.color);
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|&(x, y)| {
                x.is_finite() && y.is_finite() && (!p.log_x || x > 0.0) && (!p.log_y || y > 0.0)
            })
            .collect();
        let line = ShapeStyle::from(&c).stroke_width(2);
        let filled = ShapeStyle::from(&c).filled();
        let anno = match s.stroke {
            Stroke::Solid => chart.draw_series(LineSeries::new(pts, line)).map_err(err)?,
            Stroke::Dashed => chart
                .draw_series(DashedLineSeries::new(pts, 6, 4, line))
                .map_err(err)?,
            Stroke::Markers => chart
                .draw_series(pts.into_iter().map(|q| Circle::new(q, 3, filled)))
                .map_err(err)?,
            Stroke::LineMarkers => {
                chart
                    .draw_series(LineSeries::new(pts.clone(), line))
                    .map_err(err)?;
                chart
                    .draw_series(pts.into_iter().map(|q| Circle::new(q, 3, filled)))
                    .map_err(err)?
            }
            Stroke::Squares => chart
                .draw_series(
                    pts.into_iter()
                        .map(|q| EmptyElement::at(q) + Rectangle::new([(-5, -5), (5, 5)], filled)),
                )
                .map_err(err)?,
        };
        if !s.label.is_empty() {
            any_label = true;
            let stroke = s.stroke;
            let (path, radius) = match stroke {
                Stroke::Markers | Stroke::Squares => (vec![(10, 0), (10, 0)], 4),
                Stroke::LineMarkers => (vec![(0, 0), (20, 0)], 3),
                Stroke::Solid | Stroke::Dashed => (vec![(0, 0), (20, 0)], 0),
            };
            anno.label(s.label.as_str()).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(path.clone(), c.stroke_width(2))
                    + Circle::new((10, 0), radius, c.filled())
            });
        }
    }
    if any_label {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(150, 150, 150))
            .label_font((FONT_FAMILY, 12))
            .draw()
            .map_err(err)?;
    }
    Ok(())
}
