//! `study analyse`: per condition, the psychometric fit of the non-practice trials (maximum
//! likelihood, guess rate 0.5, lapse rate fitted in [0, 0.06]), a parametric-bootstrap 95 % interval
//! of the JND, the Weber fraction (JND / reference value), the staircases' reversal estimate, and
//! the plots (psychometric curves and staircase tracks).
//!
//! The PSE is not reported: in this 2AFC design the comparison is always the stiffer stimulus, so
//! the point of subjective equality is the reference by construction. A PSE needs a design with
//! comparisons on both sides of a reference of another law (not built yet).

use super::fit::{bootstrap_thresholds, fit, quantile, Point, PsyFit, Shape};
use super::rng::mix;
use super::trials::{self, TrialRow};
use crate::plot::{write_panels, Panel, Series, Stroke};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Options of an analysis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnalyseOptions {
    /// Shape of the psychometric function.
    pub shape: Shape,
    /// Bootstrap repetitions.
    pub bootstrap: u32,
    /// Bootstrap seed.
    pub seed: u64,
    /// Upper bound of the fitted lapse rate.
    pub max_lapse: f64,
}

impl Default for AnalyseOptions {
    fn default() -> Self {
        Self {
            shape: Shape::Weibull,
            bootstrap: 500,
            seed: 1,
            max_lapse: 0.06,
        }
    }
}

/// The result for one condition.
#[derive(Clone, Debug)]
pub struct ConditionResult {
    /// Condition name.
    pub condition: String,
    /// The varied parameter.
    pub vary: String,
    /// Its reference value.
    pub reference_value: f64,
    /// Analysed (non-practice) trials.
    pub trials: u32,
    /// Trials per level.
    pub points: Vec<Point>,
    /// The fit.
    pub fit: PsyFit,
    /// JND (threshold at 75 % correct), unit of `vary`.
    pub jnd: f64,
    /// Its bootstrap 95 % interval.
    pub jnd_ci: (f64, f64),
    /// Weber fraction `JND / reference_value` and its interval.
    pub weber: f64,
    /// The Weber fraction's 95 % interval.
    pub weber_ci: (f64, f64),
    /// Mean delta at the reversals after the first two, over all staircases (if any).
    pub staircase_estimate: Option<f64>,
    /// Staircase tracks: per track, `(trial, delta)`.
    pub tracks: BTreeMap<usize, Vec<(f64, f64)>>,
}

/// Every `trials.tsv` at or below `dir` (a session directory or a study's output directory).
pub fn find_sessions(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    let mut stack = vec![(dir.to_path_buf(), 0)];
    while let Some((d, depth)) = stack.pop() {
        let t = d.join("trials.tsv");
        if t.is_file() {
            out.push(t);
            continue;
        }
        if depth < 3 {
            if let Ok(rd) = std::fs::read_dir(&d) {
                for e in rd.flatten() {
                    if e.path().is_dir() {
                        stack.push((e.path(), depth + 1));
                    }
                }
            }
        }
    }
    out.sort();
    if out.is_empty() {
        return Err(format!(
            "no trials.tsv at or below {}\n    fix: give a session directory (OUT/sub-ID/ses-N) or the --out directory of `study run`",
            dir.display()
        ));
    }
    Ok(out)
}

/// Analyses the rows of one or more sessions (pooled per condition).
pub fn analyse_rows(
    rows: &[TrialRow],
    opts: &AnalyseOptions,
) -> Result<Vec<ConditionResult>, String> {
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        if !names.contains(&r.condition) {
            names.push(r.condition.clone());
        }
    }
    let mut out = Vec::new();
    for (ci, name) in names.iter().enumerate() {
        let rs: Vec<&TrialRow> = rows
            .iter()
            .filter(|r| &r.condition == name && !r.practice)
            .collect();
        let Some(first) = rs.first() else { continue };
        let mut levels: BTreeMap<u64, Point> = BTreeMap::new();
        for r in &rs {
            let p = levels.entry(r.delta.to_bits()).or_insert(Point {
                x: r.delta,
                n: 0,
                k: 0,
            });
            p.n += 1;
            p.k += u32::from(r.correct);
        }
        let mut points: Vec<Point> = levels.into_values().collect();
        points.sort_by(|a, b| a.x.total_cmp(&b.x));
        let f = fit(&points, opts.shape, 0.5, opts.max_lapse)
            .map_err(|e| format!("condition `{name}`: {e}"))?;
        let boot = bootstrap_thresholds(
            &f,
            &points,
            opts.bootstrap,
            mix(opts.seed, ci as u64),
            opts.max_lapse,
        );
        let jnd_ci = (quantile(&boot, 0.025), quantile(&boot, 0.975));
        let rv = first.reference_value;
        // Staircases.
        let mut tracks: BTreeMap<usize, Vec<(f64, f64)>> = BTreeMap::new();
        let mut reversal_deltas = Vec::new();
        let mut last_rev: BTreeMap<usize, u32> = BTreeMap::new();
        for r in &rs {
            if let (Some(t), Some(rev)) = (r.track, r.reversals) {
                tracks
                    .entry(t)
                    .or_default()
                    .push((f64::from(r.trial), r.delta));
                let prev = last_rev.insert(t, rev).unwrap_or(0);
                if rev > prev && rev > 2 {
                    reversal_deltas.push(r.delta);
                }
            }
        }
        let staircase_estimate = (!reversal_deltas.is_empty())
            .then(|| reversal_deltas.iter().sum::<f64>() / reversal_deltas.len() as f64);
        out.push(ConditionResult {
            condition: name.clone(),
            vary: first.vary.clone(),
            reference_value: rv,
            trials: rs.len() as u32,
            points,
            jnd: f.threshold(),
            jnd_ci,
            weber: f.threshold() / rv,
            weber_ci: (jnd_ci.0 / rv, jnd_ci.1 / rv),
            fit: f,
            staircase_estimate,
            tracks,
        });
    }
    if out.is_empty() {
        return Err("no analysable (non-practice) trials".into());
    }
    Ok(out)
}

/// The results as a TSV table (header + one row per condition).
pub fn results_tsv(res: &[ConditionResult]) -> String {
    let mut s = String::from("condition\tvary\treference_value\ttrials\tshape\talpha\tbeta\tlapse\tjnd\tjnd_ci_lo\tjnd_ci_hi\tweber\tweber_ci_lo\tweber_ci_hi\tstaircase_estimate\tpse\n");
    for r in res {
        s.push_str(&format!(
            "{}\t{}\t{}\t{}\t{}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{}\t-\n",
            r.condition, r.vary, r.reference_value, r.trials, r.fit.shape.name(), r.fit.alpha, r.fit.beta, r.fit.lapse,
            r.jnd, r.jnd_ci.0, r.jnd_ci.1, r.weber, r.weber_ci.0, r.weber_ci.1,
            r.staircase_estimate.map_or("-".into(), |v| format!("{v:.6}")),
        ));
    }
    s
}

/// The trials per stimulus level as a TSV table (`condition delta n_trials n_correct`: the
/// `[x, k, n]` data other fitting tools such as psignifit take).
pub fn levels_tsv(res: &[ConditionResult]) -> String {
    let mut s = String::from("condition\tdelta\tn_trials\tn_correct\n");
    for r in res {
        for p in &r.points {
            s.push_str(&format!("{}\t{}\t{}\t{}\n", r.condition, p.x, p.n, p.k));
        }
    }
    s
}

/// Three significant figures (at least the integer part).
fn short(x: f64) -> String {
    let digits = if x.abs() >= 100.0 {
        0
    } else if x.abs() >= 10.0 {
        1
    } else {
        3
    };
    format!("{x:.digits$}")
}

/// Draws the psychometric curves (one panel per condition: proportion correct per level, the fit,
/// 75 %) and, when there are staircases, their tracks; writes `<stem>.svg` and `.png`.
pub fn plot(res: &[ConditionResult], stem: &Path, title: &str) -> Result<Vec<PathBuf>, String> {
    let mut panels = Vec::new();
    for (i, r) in res.iter().enumerate() {
        let xmax = r.points.iter().map(|p| p.x).fold(0.0, f64::max) * 1.1;
        let curve: Vec<(f64, f64)> = (0..=200)
            .map(|j| {
                let x = xmax * f64::from(j) / 200.0;
                (x, r.fit.p(x))
            })
            .collect();
        let data: Vec<(f64, f64)> = r
            .points
            .iter()
            .map(|p| (p.x, f64::from(p.k) / f64::from(p.n)))
            .collect();
        panels.push(Panel {
            title: format!(
                "{}: JND {} [{}, {}], Weber {:.3}",
                r.condition,
                short(r.jnd),
                short(r.jnd_ci.0),
                short(r.jnd_ci.1),
                r.weber
            ),
            x_label: format!("delta of {} (comparison − reference)", r.vary),
            y_label: "proportion correct".into(),
            series: vec![
                Series::new("data", data, i, Stroke::Markers),
                Series::new(
                    format!("{} fit", r.fit.shape.name()),
                    curve,
                    i,
                    Stroke::Solid,
                ),
            ],
            h_lines: vec![0.5, 0.75],
            y_range: Some((0.0, 1.02)),
            ..Panel::default()
        });
    }
    let mut stair = Panel {
        title: "staircase tracks".into(),
        x_label: "trial".into(),
        y_label: "delta".into(),
        ..Panel::default()
    };
    for (i, r) in res.iter().enumerate() {
        for (t, pts) in &r.tracks {
            stair.series.push(Series::new(
                format!("{} #{t}", r.condition),
                pts.clone(),
                i,
                Stroke::LineMarkers,
            ));
        }
    }
    if !stair.series.is_empty() {
        panels.push(stair);
    }
    write_panels(stem, title, &panels, 2, (640, 440))
}

/// Analyses every session at or below `dir` and writes `analysis.tsv`, `analysis-levels.tsv` and
/// `psychometric.svg/.png` in `dir`. Returns the results and the written paths.
pub fn analyse_dir(
    dir: &Path,
    opts: &AnalyseOptions,
) -> Result<(Vec<ConditionResult>, Vec<PathBuf>), String> {
    let sessions = find_sessions(dir)?;
    let mut rows = Vec::new();
    for s in &sessions {
        let text = std::fs::read_to_string(s).map_err(|e| format!("{}: {e}", s.display()))?;
        let (r, _) = trials::read(&text).map_err(|e| format!("{}: {e}", s.display()))?;
        rows.extend(r);
    }
    let res = analyse_rows(&rows, opts)?;
    let tsv = dir.join("analysis.tsv");
    std::fs::write(&tsv, results_tsv(&res)).map_err(|e| format!("{}: {e}", tsv.display()))?;
    let levels = dir.join("analysis-levels.tsv");
    std::fs::write(&levels, levels_tsv(&res)).map_err(|e| format!("{}: {e}", levels.display()))?;
    let mut paths = vec![tsv, levels];
    paths.extend(plot(
        &res,
        &dir.join("psychometric"),
        &format!("{} session(s): psychometric functions", sessions.len()),
    )?);
    Ok((res, paths))
}
