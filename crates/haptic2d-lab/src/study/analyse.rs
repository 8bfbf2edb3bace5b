//! `study analyse`: per condition, the psychometric fit of the non-practice trials (maximum
//! likelihood, guess rate 0.5, lapse rate fitted in [0, 0.06]), a parametric-bootstrap 95 % interval
//! of the JND, the Weber fraction (JND / reference value), the staircases' reversal estimate, and
//! the plots (psychometric curves and staircase tracks).
//!
//! A **PSE condition** (its comparison is another stimulus than its reference: a spring against a
//! pulse wall) has no correct answer (`correct` is `-`): there the analysis fits
//! `P(comparison named stiffer) = λ/2 + (1 − λ)·Φ((ln x − ln PSE)/σ)` against the comparison's value
//! `x` (a log axis: Weber's law) and reports the PSE (the comparison value that feels as stiff as the
//! reference), its ratio to the reference's nominal value, and the JND `PSE·(exp(σ·z₀.₇₅) − 1)`
//! (from 50 % to 75 %), each with a parametric-bootstrap 95 % interval. A PSE outside the tested comparisons is reported as such, without an interval.

use super::file::Task;
use super::fit::{bootstrap, bootstrap_thresholds, fit, fit_pse, quantile, Point, PsyFit, Shape};
use super::rng::mix;
use super::same_different::{self, SdFit};
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
    /// The task's guess rate (0.5 for 2AFC, 1/3 for 3AFC); [`analyse_dir`] reads it from the
    /// sessions' `study.toml`.
    pub guess: f64,
    /// The sessions are same–different trials (signal detection, `same_different.rs`).
    pub same_different: bool,
    /// The sessions are magnitude estimation (Stevens' power law, `magnitude.rs`).
    pub magnitude: bool,
}

impl Default for AnalyseOptions {
    fn default() -> Self {
        Self {
            shape: Shape::Weibull,
            bootstrap: 500,
            seed: 1,
            max_lapse: 0.06,
            guess: 0.5,
            same_different: false,
            magnitude: false,
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
    /// The point of subjective equality of a PSE condition.
    pub pse: Option<Pse>,
    /// The differencing model of a same–different condition.
    pub sd: Option<SdResult>,
    /// The power law of a magnitude-estimation condition.
    pub magnitude: Option<super::magnitude::MagnitudeResult>,
}

/// A same–different condition's fit (`same_different.rs`).
#[derive(Clone, Debug, PartialEq)]
pub struct SdResult {
    /// The fitted model.
    pub fit: SdFit,
    /// The criterion's 95 % interval (units of the percept noise).
    pub criterion_ci: (f64, f64),
    /// The observed false-alarm rate ("different" on same trials).
    pub false_alarms: f64,
    /// Same trials.
    pub same_trials: u32,
}

/// The PSE of a PSE condition (unit of the varied parameter).
#[derive(Clone, Debug, PartialEq)]
pub struct Pse {
    /// The comparison value judged stiffer half the time (without lapses).
    pub value: f64,
    /// Its bootstrap 95 % interval (`NaN`s when outside the tested range).
    pub ci: (f64, f64),
    /// `value / reference_value` (the reference's nominal value of the varied parameter).
    pub ratio: f64,
    /// Its 95 % interval.
    pub ratio_ci: (f64, f64),
    /// `Some("above")` / `Some("below")` when the PSE lies beyond the tested comparisons: the
    /// comparison was (almost) never / always named stiffer.
    pub outside: Option<&'static str>,
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
        if opts.same_different {
            out.push(analyse_sd(name, first, &rs, opts, ci as u64)?);
            continue;
        }
        if opts.magnitude {
            let seed = super::magnitude::seed(opts.seed, ci as u64);
            out.push(super::magnitude::analyse(name, &rs, opts.bootstrap, seed)?);
            continue;
        }
        let is_pse = rs.iter().any(|r| r.correct.is_none());
        let mut levels: BTreeMap<u64, Point> = BTreeMap::new();
        for r in &rs {
            let x = if is_pse { r.comparison_value } else { r.delta };
            let p = levels.entry(x.to_bits()).or_insert(Point { x, n: 0, k: 0 });
            p.n += 1;
            p.k += u32::from(if is_pse {
                r.comparison_chosen()
            } else {
                r.correct == Some(true)
            });
        }
        let mut points: Vec<Point> = levels.into_values().collect();
        points.sort_by(|a, b| a.x.total_cmp(&b.x));
        let rv = first.reference_value;
        if is_pse {
            out.push(analyse_pse(name, first, points, opts, ci as u64)?);
            continue;
        }
        let f = fit(&points, opts.shape, opts.guess, opts.max_lapse)
            .map_err(|e| format!("condition `{name}`: {e}"))?;
        let boot = bootstrap_thresholds(
            &f,
            &points,
            opts.bootstrap,
            mix(opts.seed, ci as u64),
            opts.max_lapse,
        );
        let jnd_ci = (quantile(&boot, 0.025), quantile(&boot, 0.975));
        // Staircases.
        let mut tracks: BTreeMap<usize, Vec<(f64, f64)>> = BTreeMap::new();
        let mut reversal_deltas = Vec::new();
        let mut last_rev: BTreeMap<usize, u32> = BTreeMap::new();
        for r in &rs {
            if let Some(t) = r.track {
                tracks
                    .entry(t)
                    .or_default()
                    .push((f64::from(r.trial), r.delta));
            }
            if let (Some(t), Some(rev)) = (r.track, r.reversals) {
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
            pse: None,
            sd: None,
            magnitude: None,
        });
    }
    if out.is_empty() {
        return Err("no analysable (non-practice) trials".into());
    }
    Ok(out)
}

/// The same–different analysis of one condition: the differencing model fitted to the "different"
/// answers of the same trials and of each comparison level (x = ln(1 + Δ/reference)).
fn analyse_sd(
    name: &str,
    first: &TrialRow,
    rs: &[&TrialRow],
    opts: &AnalyseOptions,
    ci: u64,
) -> Result<ConditionResult, String> {
    let rv = first.reference_value;
    let mut levels: BTreeMap<u64, Point> = BTreeMap::new();
    for r in rs {
        let x = if r.comparison_interval == 0 {
            0.0
        } else {
            (1.0 + r.delta / rv).ln()
        };
        let p = levels.entry(x.to_bits()).or_insert(Point { x, n: 0, k: 0 });
        p.n += 1;
        p.k += u32::from(r.response == 1);
    }
    let mut points: Vec<Point> = levels.into_values().collect();
    points.sort_by(|a, b| a.x.total_cmp(&b.x));
    let f = same_different::fit(&points).map_err(|e| format!("condition `{name}`: {e}"))?;
    let boot = same_different::bootstrap(&f, &points, opts.bootstrap, mix(opts.seed, ci));
    let q = |g: &dyn Fn(&SdFit) -> f64| {
        let mut v: Vec<f64> = boot.iter().map(g).filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        (quantile(&v, 0.025), quantile(&v, 0.975))
    };
    let jnd_ci = q(&|b| b.jnd(rv));
    let same = points
        .iter()
        .find(|p| p.x == 0.0)
        .copied()
        .unwrap_or(Point { x: 0.0, n: 0, k: 0 });
    // For the table and plot: the levels as deltas.
    let shown: Vec<Point> = points
        .iter()
        .map(|p| Point {
            x: rv * (p.x.exp() - 1.0),
            ..*p
        })
        .collect();
    Ok(ConditionResult {
        condition: name.to_string(),
        vary: first.vary.clone(),
        reference_value: rv,
        trials: rs.len() as u32,
        points: shown,
        fit: PsyFit {
            shape: Shape::Normal,
            alpha: f.slope,
            beta: f.criterion,
            guess: f64::from(same.k) / f64::from(same.n.max(1)),
            symmetric: false,
            lapse: 0.0,
            nll: f64::NAN,
        },
        jnd: f.jnd(rv),
        jnd_ci,
        weber: f.jnd(rv) / rv,
        weber_ci: (jnd_ci.0 / rv, jnd_ci.1 / rv),
        staircase_estimate: None,
        tracks: BTreeMap::new(),
        pse: None,
        magnitude: None,
        sd: Some(SdResult {
            fit: f,
            criterion_ci: q(&|b| b.criterion),
            false_alarms: f64::from(same.k) / f64::from(same.n.max(1)),
            same_trials: same.n,
        }),
    })
}

/// The PSE analysis of one condition (see the module documentation).
fn analyse_pse(
    name: &str,
    first: &TrialRow,
    points: Vec<Point>,
    opts: &AnalyseOptions,
    ci: u64,
) -> Result<ConditionResult, String> {
    // Fitted on the log of the comparison's value: a Weber-law observer's judgement is a cumulative
    // normal of the log stimulus ratio, so the fit is not skewed where a linear axis would be.
    if let Some(p) = points.iter().find(|p| p.x.is_nan() || p.x <= 0.0) {
        return Err(format!(
            "condition `{name}`: comparison value {} is not positive: the PSE is fitted on a log axis",
            p.x
        ));
    }
    let logs: Vec<Point> = points.iter().map(|p| Point { x: p.x.ln(), ..*p }).collect();
    let f = fit_pse(&logs, opts.max_lapse).map_err(|e| format!("condition `{name}`: {e}"))?;
    let rv = first.reference_value;
    let lo = points.first().map_or(f64::NAN, |p| p.x);
    let hi = points.last().map_or(f64::NAN, |p| p.x);
    let prop = |p: &Point| f64::from(p.k) / f64::from(p.n);
    let pse = |f: &PsyFit| f.alpha.exp();
    let jnd = |f: &PsyFit| (f.alpha + f.spread()).exp() - f.alpha.exp();
    let outside = if points.iter().all(|p| prop(p) < 0.5) || pse(&f) > hi {
        Some("above")
    } else if points.iter().all(|p| prop(p) > 0.5) || pse(&f) < lo {
        Some("below")
    } else {
        None
    };
    let boot = bootstrap(
        &f,
        &logs,
        opts.bootstrap,
        mix(opts.seed, ci),
        opts.max_lapse,
    );
    let sorted = |g: &dyn Fn(&PsyFit) -> f64| {
        let mut v: Vec<f64> = boot.iter().map(g).filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        (quantile(&v, 0.025), quantile(&v, 0.975))
    };
    let nan = (f64::NAN, f64::NAN);
    let (pse_ci, jnd_ci) = if outside.is_some() {
        (nan, nan)
    } else {
        (sorted(&pse), sorted(&jnd))
    };
    let weber = jnd(&f) / pse(&f);
    let weber_ci = if outside.is_some() {
        nan
    } else {
        sorted(&|b| jnd(b) / pse(b))
    };
    let jnd = jnd(&f);
    Ok(ConditionResult {
        condition: name.to_string(),
        vary: first.vary.clone(),
        reference_value: rv,
        trials: points.iter().map(|p| p.n).sum(),
        points,
        jnd,
        jnd_ci,
        weber,
        weber_ci,
        staircase_estimate: None,
        tracks: BTreeMap::new(),
        sd: None,
        magnitude: None,
        pse: Some(Pse {
            value: pse(&f),
            ci: pse_ci,
            ratio: pse(&f) / rv,
            ratio_ci: (pse_ci.0 / rv, pse_ci.1 / rv),
            outside,
        }),
        fit: f,
    })
}

/// The results as a TSV table (header + one row per condition).
pub fn results_tsv(res: &[ConditionResult]) -> String {
    let mut s = String::from("condition\tvary\treference_value\ttrials\tshape\talpha\tbeta\tlapse\tjnd\tjnd_ci_lo\tjnd_ci_hi\tweber\tweber_ci_lo\tweber_ci_hi\tstaircase_estimate\tpse\tpse_ci_lo\tpse_ci_hi\tpse_ratio\tpse_outside\n");
    for r in res {
        s.push_str(&format!(
            "{}\t{}\t{}\t{}\t{}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{}\t{}\n",
            r.condition, r.vary, r.reference_value, r.trials, r.fit.shape.name(), r.fit.alpha, r.fit.beta, r.fit.lapse,
            r.jnd, r.jnd_ci.0, r.jnd_ci.1, r.weber, r.weber_ci.0, r.weber_ci.1,
            r.staircase_estimate.map_or("-".into(), |v| format!("{v:.6}")),
            r.pse.as_ref().map_or("-\t-\t-\t-\t-".into(), |p| format!(
                "{:.6}\t{:.6}\t{:.6}\t{:.6}\t{}",
                p.value,
                p.ci.0,
                p.ci.1,
                p.ratio,
                p.outside.unwrap_or("-")
            )),
        ));
    }
    s
}

/// The trials per stimulus level as a TSV table (`condition level n_trials n_yes`: the `[x, k, n]`
/// data other fitting tools such as psignifit take). `level` is the delta and `n_yes` the correct
/// answers in a discrimination; in a PSE condition `level` is the comparison's value and `n_yes`
/// the answers naming the comparison stiffer.
pub fn levels_tsv(res: &[ConditionResult]) -> String {
    let mut s = String::from("condition\tlevel\tn_trials\tn_yes\n");
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
        let xmin = if r.pse.is_some() {
            r.points.first().map_or(0.0, |p| p.x) * 0.9
        } else {
            0.0
        };
        let curve: Vec<(f64, f64)> = (0..=200)
            .map(|j| {
                let x = xmin + (xmax - xmin) * f64::from(j) / 200.0;
                let y = if let Some(sd) = &r.sd {
                    sd.fit.p_different((1.0 + x / r.reference_value).ln())
                } else if r.pse.is_some() {
                    r.fit.p(x.max(1e-300).ln())
                } else {
                    r.fit.p(x)
                };
                (x, y)
            })
            .collect();
        let data: Vec<(f64, f64)> = r
            .points
            .iter()
            .map(|p| (p.x, f64::from(p.k) / f64::from(p.n)))
            .collect();
        let (title, x_label, y_label, h_lines) = match (&r.pse, &r.sd) {
            (_, Some(sd)) => (
                format!(
                    "{}: JND {} [{}, {}] (d' = 0.954), criterion {:.2}",
                    r.condition,
                    short(r.jnd),
                    short(r.jnd_ci.0),
                    short(r.jnd_ci.1),
                    sd.fit.criterion
                ),
                format!("delta of {} (0: same trials)", r.vary),
                "proportion \"different\"".to_string(),
                vec![sd.false_alarms],
            ),
            (pse, None) => match pse {
                Some(p) => (
                    match p.outside {
                        Some(side) => format!("{}: PSE {side} the tested range", r.condition),
                        None => format!(
                            "{}: PSE {} [{}, {}] ({:.2} × nominal)",
                            r.condition,
                            short(p.value),
                            short(p.ci.0),
                            short(p.ci.1),
                            p.ratio
                        ),
                    },
                    format!("{} of the comparison", r.vary),
                    "proportion comparison named stiffer".to_string(),
                    vec![0.5],
                ),
                None => (
                    format!(
                        "{}: JND {} [{}, {}], Weber {:.3}",
                        r.condition,
                        short(r.jnd),
                        short(r.jnd_ci.0),
                        short(r.jnd_ci.1),
                        r.weber
                    ),
                    format!("delta of {} (comparison − reference)", r.vary),
                    "proportion correct".to_string(),
                    vec![r.fit.guess, r.fit.guess + (1.0 - r.fit.guess) / 2.0],
                ),
            },
        };
        panels.push(Panel {
            title,
            x_label,
            y_label,
            series: vec![
                Series::new("data", data, i, Stroke::Markers),
                Series::new(
                    if r.sd.is_some() {
                        "differencing model".to_string()
                    } else if r.pse.is_some() {
                        "cumulative normal of ln x".to_string()
                    } else {
                        format!("{} fit", r.fit.shape.name())
                    },
                    curve,
                    i,
                    Stroke::Solid,
                ),
            ],
            h_lines,
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

/// The task of the session whose `trials.tsv` is `tsv`, from the `study.toml` stored beside it
/// (2AFC when there is none: sessions written before the task was recorded).
fn session_task(tsv: &Path) -> Result<Task, String> {
    let p = tsv.with_file_name("study.toml");
    let Ok(text) = std::fs::read_to_string(&p) else {
        return Ok(Task::TwoAfc);
    };
    let t: toml::Table = toml::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))?;
    let kind = t
        .get("task")
        .and_then(|t| t.get("kind"))
        .and_then(|k| k.as_str())
        .unwrap_or("2afc");
    Task::from_name(kind).ok_or_else(|| format!("{}: unknown task `{kind}`", p.display()))
}

/// Analyses every session at or below `dir` and writes `analysis.tsv`, `analysis-levels.tsv` and
/// `psychometric.svg/.png` in `dir`. Returns the results and the written paths.
pub fn analyse_dir(
    dir: &Path,
    opts: &AnalyseOptions,
) -> Result<(Vec<ConditionResult>, Vec<PathBuf>), String> {
    let sessions = find_sessions(dir)?;
    let mut opts = *opts;
    let mut task: Option<Task> = None;
    for s in &sessions {
        let t = session_task(s)?;
        if task.is_some_and(|k| k != t) {
            return Err(format!(
                "{}: the sessions below {} are of different tasks; analyse them separately",
                s.display(),
                dir.display()
            ));
        }
        task = Some(t);
    }
    opts.guess = task.unwrap_or(Task::TwoAfc).guess_rate();
    opts.same_different = task == Some(Task::SameDifferent);
    opts.magnitude = task == Some(Task::Magnitude);
    let opts = &opts;
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
    if opts.magnitude {
        let title = format!("{} session(s): magnitude estimation", sessions.len());
        paths.extend(super::magnitude::write(dir, &res, &title)?);
        return Ok((res, paths));
    }
    paths.extend(plot(
        &res,
        &dir.join("psychometric"),
        &format!("{} session(s): psychometric functions", sessions.len()),
    )?);
    Ok((res, paths))
}

/// The text report of one condition (what `haptic2d study analyse` prints).
pub fn report(r: &ConditionResult, bootstrap: u32) -> String {
    let mut s = format!(
        "{} ({}, reference {}): {} trials, {} fit (α = {:.4}, β = {:.3}, lapse {:.3})\n",
        r.condition,
        r.vary,
        r.reference_value,
        r.trials,
        if r.pse.is_some() {
            "PSE: cumulative normal of ln(comparison value)"
        } else {
            r.fit.shape.name()
        },
        r.fit.alpha,
        r.fit.beta,
        r.fit.lapse
    );
    if let Some(m) = &r.magnitude {
        return super::magnitude::report(r, m, bootstrap);
    }
    if let Some(sd) = &r.sd {
        return format!(
            "{} ({}, reference {}): {} trials ({} same), differencing model: d' = {:.3}·ln(1 + Δ/{}), criterion {:.3} [{:.3}, {:.3}], false alarms {:.3}\n  JND (d' = 0.954, the 2AFC 75 % point) {:.4} [{:.4}, {:.4}] (95 % parametric bootstrap, {bootstrap} reps)\n  Weber fraction {:.4} [{:.4}, {:.4}]\n",
            r.condition, r.vary, r.reference_value, r.trials, sd.same_trials, sd.fit.slope, r.reference_value,
            sd.fit.criterion, sd.criterion_ci.0, sd.criterion_ci.1, sd.false_alarms,
            r.jnd, r.jnd_ci.0, r.jnd_ci.1, r.weber, r.weber_ci.0, r.weber_ci.1
        );
    }
    match &r.pse {
        Some(p) => {
            match p.outside {
                Some(side) => s.push_str(&format!(
                    "  PSE {side} the tested comparisons ({} to {}): the comparison was {} named stiffer; no interval\n",
                    r.points.first().map_or(f64::NAN, |q| q.x),
                    r.points.last().map_or(f64::NAN, |q| q.x),
                    if side == "above" { "(almost) never" } else { "(almost) always" }
                )),
                None => {
                    s.push_str(&format!(
                        "  PSE {:.4} [{:.4}, {:.4}] (95 % parametric bootstrap, {bootstrap} reps): the comparison value that feels as stiff as the reference\n",
                        p.value, p.ci.0, p.ci.1
                    ));
                    s.push_str(&format!(
                        "  PSE / nominal {:.4} [{:.4}, {:.4}] (nominal {} = {}: the reference's value, or the comparison's base when the reference has no such parameter)\n",
                        p.ratio, p.ci.0 / r.reference_value, p.ci.1 / r.reference_value, r.vary, r.reference_value
                    ));
                    s.push_str(&format!(
                        "  JND (PSE to 75 %) {:.4} [{:.4}, {:.4}], Weber fraction at the PSE {:.4} [{:.4}, {:.4}]\n",
                        r.jnd, r.jnd_ci.0, r.jnd_ci.1, r.weber, r.weber_ci.0, r.weber_ci.1
                    ));
                }
            }
        }
        None => {
            s.push_str(&format!(
                "  JND ({:.0} % correct) {:.4} [{:.4}, {:.4}] (95 % parametric bootstrap, {bootstrap} reps)\n",
                100.0 * (r.fit.guess + (1.0 - r.fit.guess) / 2.0),
                r.jnd, r.jnd_ci.0, r.jnd_ci.1
            ));
            s.push_str(&format!(
                "  Weber fraction {:.4} [{:.4}, {:.4}]\n",
                r.weber, r.weber_ci.0, r.weber_ci.1
            ));
            if let Some(e) = r.staircase_estimate {
                s.push_str(&format!(
                    "  staircase estimate (mean delta at reversals after the second) {e:.4}\n"
                ));
            }
            s.push_str(
                "  PSE: not defined by this design (the comparison is always the stiffer stimulus)\n",
            );
        }
    }
    s
}
