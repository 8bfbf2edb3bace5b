//! The Figs. 5–6 device-damping sweep: every wall of `crate::scenarios::walls_with_device` with the four-channel
//! loop, on devices whose physical damping is `margin` times Colgate's bound `K·T/2` (see
//! `crate::scenarios::walls_with_device::colgate_joint_damping`). It shows where the four claims hold together
//! and why the experiment's default margin is 2: it was identified from this sweep, not measured on
//! the paper's device, so the reproduction at that margin is a consistency check (such a device
//! exists), not a prediction.

use crate::csv::write_columns;
use crate::plot::{write_panels, Panel, Series, Stroke};
use crate::scenarios::walls_with_device::{run_case, Fig5Params, FIG5_CASES};
use indicatif::ProgressBar;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The margins swept (multiples of `K·T/2`), from below the bound to well above it.
pub const MARGINS: [f64; 13] = [
    0.25, 0.5, 0.75, 1.0, 1.1, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5, 3.0, 4.0,
];

/// One wall at one margin.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPoint {
    /// Damping margin (multiples of `K·T/2`).
    pub margin: f64,
    /// The joint viscous friction that realises it (N·m·s/rad).
    pub f_v: f64,
    /// Wall (case name of `FIG5_CASES`).
    pub wall: &'static str,
    /// Separations after the release.
    pub separations: usize,
    /// Separations in the last 2 s.
    pub late_separations: usize,
    /// First contact ratio, if the box left the wall at least once.
    pub first_ratio: Option<f64>,
    /// Whether the wall meets its claim.
    pub pass: bool,
}

/// Runs every wall at every margin of `margins` (in parallel), advancing `progress` by one per run.
pub fn run(
    base: &Fig5Params,
    margins: &[f64],
    progress: &ProgressBar,
) -> Result<Vec<SweepPoint>, String> {
    let jobs: Vec<(f64, usize)> = margins
        .iter()
        .flat_map(|&m| (0..FIG5_CASES.len()).map(move |j| (m, j)))
        .collect();
    crate::figures::par_jobs(progress, &jobs, |&(margin, j)| {
        let (name, normal, e) = FIG5_CASES[j];
        let p = base.with_margin(margin);
        let f_v = p.haptic_config()?.device.f_v;
        let c = run_case(&p, name, normal, e)
            .map_err(|e| format!("fig5 sweep, margin {margin}: {e}"))?;
        let b = &c.metrics.bounce;
        Ok(SweepPoint {
            margin,
            f_v,
            wall: name,
            separations: b.separations(),
            late_separations: c.metrics.late_separations,
            first_ratio: b.contact_ratios.first().copied(),
            pass: c.metrics.pass,
        })
    })
}

/// Writes `sweep.csv` (one row per margin and wall) and the `sweep` SVG/PNG chart into `dir`.
pub fn write(dir: &Path, points: &[SweepPoint]) -> Result<Vec<PathBuf>, String> {
    let csv = dir.join("sweep.csv");
    let col = |f: &dyn Fn(&SweepPoint) -> f64| points.iter().map(f).collect::<Vec<f64>>();
    let wall_index = |p: &SweepPoint| {
        FIG5_CASES
            .iter()
            .position(|c| c.0 == p.wall)
            .unwrap_or(usize::MAX) as f64
    };
    write_columns(
        &csv,
        &[
            "margin",
            "joint_f_v_nms_rad",
            "wall_index",
            "separations",
            "late_separations",
            "first_ratio",
            "pass",
        ],
        &[
            &col(&|p| p.margin),
            &col(&|p| p.f_v),
            &col(&wall_index),
            &col(&|p| p.separations as f64),
            &col(&|p| p.late_separations as f64),
            &col(&|p| p.first_ratio.unwrap_or(0.0)),
            &col(&|p| f64::from(u8::from(p.pass))),
        ],
    )?;
    let series = |y: &dyn Fn(&SweepPoint) -> f64| {
        FIG5_CASES
            .iter()
            .enumerate()
            .map(|(j, (wall, _, _))| {
                let pts = points
                    .iter()
                    .filter(|p| p.wall == *wall)
                    .map(|p| (p.margin, y(p)))
                    .collect();
                Series::new(*wall, pts, j, Stroke::LineMarkers)
            })
            .collect::<Vec<_>>()
    };
    let panels = [
        Panel {
            title: "Separations in the last 2 s (SEH/ZOH: ≥ 2; pulse: 0)".into(),
            x_label: "device damping / (K·T/2)".into(),
            y_label: "separations".into(),
            series: series(&|p| p.late_separations as f64),
            h_lines: vec![2.0],
            ..Panel::default()
        },
        Panel {
            title: "First contact ratio (pulse: ≤ 0.4; hysteretic: < 0.85; 0 = never left)".into(),
            x_label: "device damping / (K·T/2)".into(),
            y_label: "exit / entry speed".into(),
            series: series(&|p| p.first_ratio.unwrap_or(0.0)),
            h_lines: vec![0.4, 0.85],
            ..Panel::default()
        },
    ];
    let mut files = vec![csv];
    files.extend(write_panels(
        &dir.join("sweep"),
        "Figs. 5–6, four-channel loop: the walls against the device's physical damping",
        &panels,
        2,
        (620, 320),
    )?);
    Ok(files)
}

/// The sweep as a Markdown table: one row per margin, ✓/✗ per wall, and whether all four hold.
pub fn markdown(points: &[SweepPoint], margins: &[f64]) -> String {
    let mut s = String::from("| damping / (K·T/2) | joint f_v (N·m·s/rad) |");
    for (wall, _, _) in FIG5_CASES {
        let _ = write!(s, " {wall} |");
    }
    s.push_str(" all four |\n|---|---|");
    s.push_str(&"---|".repeat(FIG5_CASES.len() + 1));
    s.push('\n');
    for &m in margins {
        let row: Vec<&SweepPoint> = points.iter().filter(|p| p.margin == m).collect();
        let f_v = row.first().map_or(f64::NAN, |p| p.f_v);
        let _ = write!(s, "| {m} | {f_v:.2e} |");
        for (wall, _, _) in FIG5_CASES {
            let cell = row
                .iter()
                .find(|p| p.wall == wall)
                .map_or("—".to_string(), |p| {
                    format!(
                        "{} {} sep ({} late)",
                        if p.pass { "✓" } else { "✗" },
                        p.separations,
                        p.late_separations
                    )
                });
            let _ = write!(s, " {cell} |");
        }
        let all = row.len() == FIG5_CASES.len() && row.iter().all(|p| p.pass);
        let _ = writeln!(s, " {} |", if all { "**yes**" } else { "no" });
    }
    s
}
