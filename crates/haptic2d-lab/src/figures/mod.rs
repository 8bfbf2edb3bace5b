//! The [`Figure`] trait, the registry of figures and the `reproduce` driver.
//!
//! A figure computes its cases (in parallel with rayon), writes its CSV series and plots into
//! `DIR/<figure>/`, and returns its metrics and a Markdown section. [`reproduce`] writes
//! `DIR/<figure>/metrics.json` and `DIR/<figure>/report.md` for each selected figure, then assembles
//! `DIR/REPORT.md` from the sections of every registered figure found in `DIR`. One file a figure.

pub mod fig4;
pub mod fig5;
pub mod fig5_sweep;
pub mod fig7;
pub mod fig8;

use crate::csv::write_columns;
use crate::plot::{Panel, Series};
use crate::schema::{CaseMetrics, FigureMetrics};
use haptic2d::haptic::{ControllerKind, TickRecord};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What a figure gets to run.
pub struct FigureContext<'a> {
    /// The figure's output folder `DIR/<figure>/` (exists).
    pub dir: PathBuf,
    /// Progress bar; a figure advances it by one per finished job (see [`Figure::jobs`]).
    pub progress: &'a ProgressBar,
    /// The controller that carries the claims of the device-in-the-loop figures instead of the
    /// default (`reproduce --controller-file`): its label and configuration. Figs. 4 and 7 do not
    /// use a controller.
    pub controller: Option<(String, ControllerKind)>,
}

/// What a figure returns.
#[derive(Clone, Debug)]
pub struct FigureReport {
    /// The metrics written to `metrics.json`.
    pub metrics: FigureMetrics,
    /// The figure's section of `REPORT.md` (Markdown; image links relative to `DIR`).
    pub markdown: String,
    /// Files written into the figure folder (CSV, SVG, PNG).
    pub files: Vec<PathBuf>,
}

impl FigureReport {
    /// The report of figure `figure`: its `cases` as the metrics, `report` of those metrics as its
    /// section of `REPORT.md`, and the `files` it wrote.
    pub fn new(
        figure: &str,
        cases: Vec<CaseMetrics>,
        files: Vec<PathBuf>,
        report: impl FnOnce(&FigureMetrics) -> String,
    ) -> Self {
        let metrics = FigureMetrics {
            figure: figure.into(),
            cases,
        };
        let markdown = report(&metrics);
        FigureReport {
            metrics,
            markdown,
            files,
        }
    }
}

/// Runs `job` on every element of `jobs` in parallel (rayon), advancing `progress` by one per
/// finished job: the results in the order of `jobs`, or the first error.
pub fn par_jobs<J: Sync, T: Send>(
    progress: &ProgressBar,
    jobs: &[J],
    job: impl Fn(&J) -> Result<T, String> + Sync + Send,
) -> Result<Vec<T>, String> {
    jobs.par_iter()
        .map(|j| {
            let r = job(j);
            progress.inc(1);
            r
        })
        .collect()
}

/// A device-in-the-loop figure's runs: `case(parameters, j)` for every configuration `(label,
/// parameters)` of `ctrl` and every case `j < cases`, in parallel (see [`par_jobs`]). Each result
/// comes with its configuration's index `i` and its case `j`; an error names the figure and the
/// configuration.
pub fn run_configurations<P: Sync, C: Send>(
    ctx: &FigureContext,
    figure: &str,
    ctrl: &[(String, P)],
    cases: usize,
    case: impl Fn(&P, usize) -> Result<C, String> + Sync + Send,
) -> Result<Vec<(usize, usize, C)>, String> {
    let jobs: Vec<(usize, usize)> = (0..ctrl.len())
        .flat_map(|i| (0..cases).map(move |j| (i, j)))
        .collect();
    par_jobs(ctx.progress, &jobs, |&(i, j)| {
        case(&ctrl[i].1, j)
            .map(|c| (i, j, c))
            .map_err(|e| format!("{figure} {}: {e}", ctrl[i].0))
    })
}

/// A case of a device-in-the-loop figure: a claim case when `carrier` (why configuration `label`
/// carries the claim) is given, a comparison run otherwise; `stability` is `haptic2d stability`'s
/// verdict for the configuration on the case's scene.
pub fn device_case(
    case: CaseMetrics,
    label: &str,
    carrier: Option<&str>,
    stability: String,
) -> CaseMetrics {
    let case = case
        .with_comparison(carrier.is_none())
        .with_stability(stability);
    match carrier {
        Some(why) => case.with_carrier(format!("{label}: {why}")),
        None => case,
    }
}

/// Writes the CSV of a device-in-the-loop run from its tick `records`: `t_s`, the slave body's
/// pose and x velocity (`{body}_x_m`, `{body}_y_m`, `{body}_theta_rad`, `{body}_vx_m_s`), the
/// device handle's x mapped to the world at mapping `scale` from the slave's start
/// (`device_x_world_m`), `f_e_x_n` and `contacts`; each of the figure's own columns `(index, name,
/// values)` stands at its index among them.
pub fn write_tick_csv(
    path: &Path,
    records: &[TickRecord],
    scale: f64,
    body: &str,
    own: &[(usize, &str, &[f64])],
) -> Result<(), String> {
    let r = records;
    let col = |f: &dyn Fn(usize) -> f64| (0..r.len()).map(f).collect::<Vec<f64>>();
    let x0 = (r[0].x_s[0], r[0].x_m[0]);
    let columns = [
        col(&|k| r[k].t),
        col(&|k| r[k].x_s[0]),
        col(&|k| r[k].x_s[1]),
        col(&|k| r[k].x_s[2]),
        col(&|k| r[k].v_s[0]),
        col(&|k| x0.0 + scale * (r[k].x_m[0] - x0.1)),
        col(&|k| r[k].f_e[0]),
        col(&|k| r[k].contacts as f64),
    ];
    let mut names = vec![
        "t_s".to_string(),
        format!("{body}_x_m"),
        format!("{body}_y_m"),
        format!("{body}_theta_rad"),
        format!("{body}_vx_m_s"),
        "device_x_world_m".to_string(),
        "f_e_x_n".to_string(),
        "contacts".to_string(),
    ];
    let mut values: Vec<&[f64]> = columns.iter().map(|c| c.as_slice()).collect();
    for &(at, name, v) in own {
        names.insert(at, name.to_string());
        values.insert(at, v);
    }
    let names: Vec<&str> = names.iter().map(|n| n.as_str()).collect();
    write_columns(path, &names, &values)
}

/// A device-in-the-loop figure's position panels: one panel per case (titled `titles[j]`), with
/// one series per configuration, `series(i, run)` for run `(i, j, run)` of `done` (see
/// [`run_configurations`]); time on x, `y_label` on y.
pub fn case_panels<C>(
    titles: &[&str],
    y_label: &str,
    done: &[(usize, usize, C)],
    series: impl Fn(usize, &C) -> Series,
) -> Vec<Panel> {
    titles
        .iter()
        .enumerate()
        .map(|(j, title)| Panel {
            title: title.to_string(),
            x_label: "time (s)".into(),
            y_label: y_label.into(),
            series: done
                .iter()
                .filter(|d| d.1 == j)
                .map(|(i, _, c)| series(*i, c))
                .collect(),
            ..Panel::default()
        })
        .collect()
}

/// A reproducible experiment of the paper.
pub trait Figure: Send + Sync {
    /// Short name, also the output folder and the `reproduce` argument (e.g. `fig4`).
    fn name(&self) -> &'static str;
    /// One-line title.
    fn title(&self) -> &'static str;
    /// Number of progress units the figure reports (one per simulated case).
    fn jobs(&self) -> u64;
    /// Runs every case and writes its files into `ctx.dir`.
    fn run(&self, ctx: &FigureContext) -> Result<FigureReport, String>;
}

/// Every registered figure, in report order. Add new figures here.
pub fn registry() -> Vec<Box<dyn Figure>> {
    vec![
        Box::new(crate::figures::fig4::Fig4),
        Box::new(crate::figures::fig5::Fig5),
        Box::new(crate::figures::fig7::Fig7),
        Box::new(crate::figures::fig8::Fig8),
    ]
}

/// Names of the registered figures.
pub fn figure_names() -> Vec<&'static str> {
    registry().iter().map(|f| f.name()).collect()
}

/// Per-figure outcome of a [`reproduce`] run.
#[derive(Clone, Debug)]
pub struct FigureSummary {
    /// Figure name.
    pub name: String,
    /// Cases that pass.
    pub passed: usize,
    /// Claim cases in total (comparison runs excluded).
    pub total: usize,
    /// Comparison runs (reported, not counted).
    pub comparisons: usize,
    /// Names (`model/dimension`) of the failing claim cases.
    pub failing: Vec<String>,
    /// Wall time of the figure (s).
    pub seconds: f64,
}

/// Outcome of a [`reproduce`] run.
#[derive(Clone, Debug)]
pub struct ReproduceSummary {
    /// One entry per figure run.
    pub figures: Vec<FigureSummary>,
    /// Path of `REPORT.md`.
    pub report: PathBuf,
    /// Total wall time (s).
    pub seconds: f64,
}

impl ReproduceSummary {
    /// Whether every case of every figure passes.
    pub fn all_pass(&self) -> bool {
        self.figures.iter().all(|f| f.passed == f.total)
    }
}

/// Runs figure `which` (`all` or a registered name) and writes the outputs under `out`. With
/// `show_progress`, a progress bar is drawn on stderr.
pub fn reproduce(which: &str, out: &Path, show_progress: bool) -> Result<ReproduceSummary, String> {
    reproduce_with(which, out, show_progress, None)
}

/// [`reproduce`] with the claims of the device-in-the-loop figures carried by `controller` (label,
/// configuration) instead of the default.
pub fn reproduce_with(
    which: &str,
    out: &Path,
    show_progress: bool,
    controller: Option<(String, ControllerKind)>,
) -> Result<ReproduceSummary, String> {
    let all = registry();
    let selected: Vec<&dyn Figure> = if which == "all" {
        all.iter().map(|f| f.as_ref()).collect()
    } else {
        match all.iter().find(|f| f.name() == which) {
            Some(f) => vec![f.as_ref()],
            None => {
                return Err(format!(
                    "unknown figure `{which}`; valid: all, {}",
                    figure_names().join(", ")
                ))
            }
        }
    };
    if out.as_os_str().is_empty() {
        return Err("--out: the output folder must not be empty".to_string());
    }
    create_out_dir(out)?;

    let total: u64 = selected.iter().map(|f| f.jobs()).sum();
    let bar = if show_progress {
        let b = ProgressBar::new(total);
        if let Ok(style) =
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} {msg}")
        {
            b.set_style(style);
        }
        b
    } else {
        ProgressBar::hidden()
    };
    let start = Instant::now();
    let mut summaries = Vec::new();
    for fig in &selected {
        bar.set_message(fig.name());
        let t0 = Instant::now();
        let dir = out.join(fig.name());
        std::fs::create_dir_all(&dir)
            .map_err(|e| format!("cannot create `{}`: {e}", dir.display()))?;
        let ctx = FigureContext {
            dir: dir.clone(),
            progress: &bar,
            controller: controller.clone(),
        };
        let rep = fig.run(&ctx)?;
        let json = serde_json::to_string_pretty(&rep.metrics)
            .map_err(|e| format!("{}: cannot encode metrics: {e}", fig.name()))?;
        write(&dir.join("metrics.json"), &json)?;
        write(&dir.join("report.md"), &rep.markdown)?;
        summaries.push(FigureSummary {
            name: fig.name().to_string(),
            passed: rep.metrics.passed(),
            total: rep.metrics.claim_count(),
            comparisons: rep.metrics.comparisons(),
            failing: rep
                .metrics
                .claims()
                .filter(|c| !c.pass)
                .map(|c| format!("{}/{}", c.model, c.dimension.as_str()))
                .collect(),
            seconds: t0.elapsed().as_secs_f64(),
        });
    }
    bar.finish_and_clear();
    let report = out.join("REPORT.md");
    write(&report, &assemble_report(out, &all)?)?;
    Ok(ReproduceSummary {
        figures: summaries,
        report,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Creates the output folder `out` (`--out`) with its parents; an error if `out` is a file or
/// cannot be created.
pub fn create_out_dir(out: &Path) -> Result<(), String> {
    if out.exists() && !out.is_dir() {
        return Err(format!(
            "--out: `{}` exists and is not a folder",
            out.display()
        ));
    }
    std::fs::create_dir_all(out)
        .map_err(|e| format!("--out: cannot create `{}`: {e}", out.display()))
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write `{}`: {e}", path.display()))
}

/// `REPORT.md`: a summary table of every figure present under `out`, then each figure's section.
fn assemble_report(out: &Path, all: &[Box<dyn Figure>]) -> Result<String, String> {
    let mut head = String::from(
        "# haptic2d: reproduction of the paper's experiments\n\n\
         Generated by `haptic2d reproduce`. Each figure folder holds the CSV time series, the plots \
         (SVG and PNG) and `metrics.json`; the reference values are those of the normative spec \
         (MODELS.md §5.10, §13). Comparison runs (another controller or device than the one that \
         carries a claim) are reported with their verdicts but not counted.\n\n\
         | figure | title | cases passing |\n|---|---|---|\n",
    );
    let mut body = String::new();
    for f in all {
        let dir = out.join(f.name());
        let (Ok(md), Ok(json)) = (
            std::fs::read_to_string(dir.join("report.md")),
            std::fs::read_to_string(dir.join("metrics.json")),
        ) else {
            continue;
        };
        let m: FigureMetrics = serde_json::from_str(&json)
            .map_err(|e| format!("{}: unreadable metrics.json: {e}", dir.display()))?;
        head.push_str(&format!(
            "| [{}](#{}) | {} | {} |\n",
            f.name(),
            f.name(),
            f.title(),
            m.pass_summary()
        ));
        body.push_str(&md);
        body.push('\n');
    }
    Ok(format!("{head}\n{body}"))
}

/// The claims of a device-in-the-loop figure as a Markdown table: each claim case, whether it is
/// reproduced, the configuration that carries it and why, and `haptic2d stability`'s verdict for
/// that configuration on that case's scene.
pub fn claims_table(m: &FigureMetrics) -> String {
    let mut s = String::from(
        "| claim case | reproduced | configuration and why | `stability` verdict |\n|---|---|---|---|\n",
    );
    for c in m.claims() {
        s.push_str(&format!(
            "| {} | {} | {} | {} |\n",
            c.model,
            c.verdict(),
            c.carrier.as_deref().unwrap_or("—"),
            c.stability.as_deref().unwrap_or("—")
        ));
    }
    s
}
