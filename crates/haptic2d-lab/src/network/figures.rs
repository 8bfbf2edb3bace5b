//! The delay figures of docs/TELEOP.md (issue 41 item 5): the lab's one-axis wall run across the
//! impaired link, for round trips 0, 10, 50 and 200 ms and loss 0, 5 and 10 % each way, with TDPA
//! and with wave variables (and, for reference, with neither), in two forms:
//!
//! - **wall contact**: the hand pushes the handle until the body is 20 mm into the wall's spring
//!   and holds it there (4 s, never released): energy the network created, mean force error
//!   `| |F_handle| − |F_wall| |` over the last second, the mean wall force, the largest handle force;
//! - **released handle**: the same push, and the hand lets go at 2.5 s in contact: energy created,
//!   and the drift `|x_m − x_s|` at 4 s (1.5 s after the release, nothing pushing).
//!
//! [`write_delay_figures`] writes `teleop-delays.md` (the table), `teleop-delays.csv` and one plot
//! per round trip (`teleop-delay-<ms>ms.svg` and `.png`: the handle force in contact, the
//! positions after the release, and the energy created, TDPA against waves at 5 % loss).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::delayed_wall::{run_delayed_wall_traced, DelayedWall, LinkMode, TracePoint};
use super::link::Impairment;
use super::wave::WaveParams;
use crate::plot::{write_panels, Panel, Series, Stroke};

/// Round trips of the figures (ms).
pub const ROUND_TRIPS_MS: [u32; 4] = [0, 10, 50, 200];
/// Losses of the figures, each way.
pub const LOSSES: [f64; 3] = [0.0, 0.05, 0.1];
/// Seed of the links' losses.
pub const SEED: u64 = 11;

/// One row of the table: one round trip, loss and link mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelayRow {
    /// Round trip (ms).
    pub round_trip_ms: u32,
    /// Loss each way.
    pub loss: f64,
    /// What keeps the link passive.
    pub mode: LinkMode,
    /// Wall contact: energy the network created (J; ≤ 0 is passive).
    pub contact_created: f64,
    /// Wall contact: mean `| |F_handle| − |F_wall| |` over the last second (N).
    pub force_error: f64,
    /// Wall contact: mean wall force over the last second (N).
    pub wall_force: f64,
    /// Wall contact: largest force on the handle (N).
    pub max_handle_force: f64,
    /// Released handle: energy the network created (J).
    pub released_created: f64,
    /// Released handle: `|x_m − x_s|` at the end (m).
    pub drift: f64,
}

/// The two runs of one cell, with their traces (every 5th sample).
fn cell(rt: u32, loss: f64, mode: LinkMode) -> (DelayRow, Vec<TracePoint>, Vec<TracePoint>) {
    let link = Impairment::delay_loss(rt / 2, loss, SEED);
    let held = DelayedWall {
        release_at: f64::INFINITY,
        ..DelayedWall::with_mode(link, mode)
    };
    let (c, ct) = run_delayed_wall_traced(&held, 5);
    let (r, rt_trace) = run_delayed_wall_traced(&DelayedWall::with_mode(link, mode), 5);
    // The held run's contact window is its last second before 4 s (the default's release_at - 1 s
    // window is for the released run): recompute the error over the last second of the trace.
    let last: Vec<&TracePoint> = ct.iter().filter(|p| p.t >= held.duration - 1.0).collect();
    let n = last.len().max(1) as f64;
    let force_error = last
        .iter()
        .map(|p| (p.f_m.abs() - p.f_wall.abs()).abs())
        .sum::<f64>()
        / n;
    let wall_force = last.iter().map(|p| p.f_wall.abs()).sum::<f64>() / n;
    let row = DelayRow {
        round_trip_ms: rt,
        loss,
        mode,
        contact_created: c.network.created,
        force_error,
        wall_force,
        max_handle_force: c.max_handle_force,
        released_created: r.network.created,
        drift: r.drift,
    };
    (row, ct, rt_trace)
}

/// Every row of the table: round trips × losses × {TDPA, waves, none}.
pub fn delay_table() -> Vec<DelayRow> {
    let mut rows = Vec::new();
    for rt in ROUND_TRIPS_MS {
        for loss in LOSSES {
            for mode in modes() {
                rows.push(cell(rt, loss, mode).0);
            }
        }
    }
    rows
}

fn modes() -> [LinkMode; 3] {
    [
        LinkMode::Tdpa,
        LinkMode::Wave(WaveParams::default()),
        LinkMode::None,
    ]
}

/// `rows` as a Markdown table (numbers a reader can compare; a run that ran away shows `runs away`).
pub fn markdown(rows: &[DelayRow]) -> String {
    let mut s = String::from(
        "| round trip | loss | link | contact: created (J) | force error (N) | wall force (N) | largest handle force (N) | released: created (J) | drift (mm) |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let runaway = !(r.max_handle_force.is_finite() && r.max_handle_force < 1e3);
        let num = |v: f64, f: fn(f64) -> String| if runaway { "runs away".into() } else { f(v) };
        let _ = writeln!(
            s,
            "| {} ms | {:.0} % | {} | {} | {} | {} | {} | {} | {} |",
            r.round_trip_ms,
            r.loss * 100.0,
            r.mode.name(),
            sci(r.contact_created),
            num(r.force_error, |v| format!("{v:.3}")),
            num(r.wall_force, |v| format!("{v:.2}")),
            num(r.max_handle_force, |v| format!("{v:.2}")),
            sci(r.released_created),
            num(r.drift * 1e3, |v| format!("{v:.2}")),
        );
    }
    s
}

fn sci(v: f64) -> String {
    if v.is_finite() && v.abs() < 1e3 {
        format!("{v:+.4}")
    } else {
        format!("{v:+.1e}")
    }
}

fn csv(rows: &[DelayRow]) -> String {
    let mut s = String::from(
        "round_trip_ms,loss,link,contact_created_j,force_error_n,wall_force_n,max_handle_force_n,released_created_j,drift_m\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{}",
            r.round_trip_ms,
            r.loss,
            r.mode.name(),
            r.contact_created,
            r.force_error,
            r.wall_force,
            r.max_handle_force,
            r.released_created,
            r.drift
        );
    }
    s
}

/// Writes the table (Markdown and CSV) and one plot per round trip into `dir` (created if
/// missing). Returns the table and the files written.
pub fn write_delay_figures(dir: &Path) -> Result<(Vec<DelayRow>, Vec<PathBuf>), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let rows = delay_table();
    let mut files = Vec::new();
    for (name, text) in [
        ("teleop-delays.md", markdown(&rows)),
        ("teleop-delays.csv", csv(&rows)),
    ] {
        let p = dir.join(name);
        std::fs::write(&p, text).map_err(|e| format!("cannot write {}: {e}", p.display()))?;
        files.push(p);
    }
    for rt in ROUND_TRIPS_MS {
        let mut force = Vec::new();
        let mut pos = Vec::new();
        let mut energy = Vec::new();
        for (i, mode) in [LinkMode::Tdpa, LinkMode::Wave(WaveParams::default())]
            .into_iter()
            .enumerate()
        {
            let (_, held, released) = cell(rt, 0.05, mode);
            let n = mode.name();
            force.push(Series::new(
                format!("handle, {n}"),
                held.iter().map(|p| (p.t, -p.f_m)).collect(),
                i,
                Stroke::Solid,
            ));
            force.push(Series::new(
                format!("wall on the body, {n}"),
                held.iter().map(|p| (p.t, -p.f_wall)).collect(),
                i,
                Stroke::Dashed,
            ));
            pos.push(Series::new(
                format!("handle x_m, {n}"),
                released.iter().map(|p| (p.t, p.x_m * 1e3)).collect(),
                i,
                Stroke::Solid,
            ));
            pos.push(Series::new(
                format!("body x_s, {n}"),
                released.iter().map(|p| (p.t, p.x_s * 1e3)).collect(),
                i,
                Stroke::Dashed,
            ));
            energy.push(Series::new(
                format!("contact, {n}"),
                held.iter().map(|p| (p.t, p.created * 1e3)).collect(),
                i,
                Stroke::Solid,
            ));
            energy.push(Series::new(
                format!("released, {n}"),
                released.iter().map(|p| (p.t, p.created * 1e3)).collect(),
                i,
                Stroke::Dashed,
            ));
        }
        let panels = [
            Panel {
                title: "Wall contact: force pushing back (N)".into(),
                x_label: "time (s)".into(),
                y_label: "force (N)".into(),
                series: force,
                ..Panel::default()
            },
            Panel {
                title: "Released at 2.5 s: positions (mm)".into(),
                x_label: "time (s)".into(),
                y_label: "position (mm)".into(),
                series: pos,
                h_lines: vec![40.0],
                ..Panel::default()
            },
            Panel {
                title: "Energy the network created (mJ; ≤ 0 passive)".into(),
                x_label: "time (s)".into(),
                y_label: "created (mJ)".into(),
                series: energy,
                h_lines: vec![0.0, 1.0],
                ..Panel::default()
            },
        ];
        let stem = dir.join(format!("teleop-delay-{rt}ms"));
        files.extend(write_panels(
            &stem,
            &format!("Round trip {rt} ms, 5 % loss each way: TDPA (blue) against waves (red)"),
            &panels,
            3,
            (520, 380),
        )?);
    }
    Ok((rows, files))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_delay_figures_write_a_table_row_per_cell_and_a_plot_per_round_trip() {
        let dir = std::env::temp_dir().join(format!("haptic2d-delays-{}", std::process::id()));
        let (rows, files) = write_delay_figures(&dir).unwrap();
        assert_eq!(rows.len(), 4 * 3 * 3);
        for rt in ROUND_TRIPS_MS {
            let svg = dir.join(format!("teleop-delay-{rt}ms.svg"));
            assert!(files.contains(&svg), "{files:?}");
            assert!(std::fs::metadata(&svg).unwrap().len() > 1000);
        }
        let md = std::fs::read_to_string(dir.join("teleop-delays.md")).unwrap();
        assert_eq!(md.lines().count(), 2 + rows.len());
        let _ = std::fs::remove_dir_all(&dir);
        // Issue 41 item 5: with TDPA and with waves, both runs stay passive (≤ 1 mJ) everywhere.
        for r in rows.iter().filter(|r| r.mode != LinkMode::None) {
            assert!(
                r.contact_created <= 1e-3 && r.released_created <= 1e-3,
                "{r:?}"
            );
        }
    }
}
