//! Magnitude estimation (Stevens 1957): each trial presents the reference — the modulus, which
//! stands for the study's `[task] modulus` — and then the comparison, and the participant gives the
//! comparison a number. The analysis fits Stevens' power law per condition,
//! `m = c·(v / v_ref)^b` (`v` the varied parameter's value in the comparison, `v_ref` in the
//! reference), by least squares on `ln m` against `ln(v / v_ref)` (the usual fit in log–log
//! coordinates: magnitude judgements scatter multiplicatively), with a 95 % interval of the exponent
//! `b` from a nonparametric bootstrap over trials. It writes `magnitude.tsv` (exponent, interval,
//! scale `c` = the number the reference itself gets, per condition) and `magnitude.svg/.png` (the
//! geometric mean number per level and the fitted line, log–log).

use super::fit::{Point, PsyFit, Shape};
use super::rng::{mix, Rng};
use super::trials::TrialRow;
use super::ConditionResult;
use crate::plot::{write_panels, Panel, Series, Stroke};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The power-law fit of one condition.
#[derive(Clone, Debug, PartialEq)]
pub struct MagnitudeResult {
    /// Stevens' exponent `b`.
    pub exponent: f64,
    /// Its bootstrap 95 % interval.
    pub exponent_ci: (f64, f64),
    /// The scale `c`: the fitted number of a comparison equal to the reference.
    pub scale: f64,
    /// Per level: the comparison's value, the geometric mean number and the trials.
    pub levels: Vec<(f64, f64, u32)>,
}

/// Least squares of `y = a + b·x`: `(a, b)`; `None` without two distinct `x`.
fn line(xy: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = xy.len() as f64;
    let (mx, my) = xy
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: f64 = xy.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: f64 = xy.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    (sxx > 1e-12).then(|| (my - sxy / sxx * mx, sxy / sxx))
}

/// The magnitude-estimation analysis of one condition's non-practice rows `rs`.
pub fn analyse(
    name: &str,
    rs: &[&TrialRow],
    bootstrap: u32,
    seed: u64,
) -> Result<ConditionResult, String> {
    let first = rs[0];
    let rv = first.reference_value;
    let mut xy = Vec::with_capacity(rs.len());
    for r in rs {
        let m = r.magnitude.ok_or_else(|| {
            format!(
                "condition `{name}`, trial {}: no magnitude (a magnitude-estimation row needs its number)",
                r.trial
            )
        })?;
        if !(m.is_finite() && m > 0.0 && r.comparison_value > 0.0 && rv > 0.0) {
            return Err(format!(
                "condition `{name}`, trial {}: magnitude {m} at value {} (reference {rv}): a power law needs positive numbers and values",
                r.trial, r.comparison_value
            ));
        }
        xy.push(((r.comparison_value / rv).ln(), m.ln()));
    }
    let (a, b) = line(&xy).ok_or_else(|| {
        format!("condition `{name}`: all trials at one level; a power law needs at least two")
    })?;
    let mut rng = Rng::new(seed);
    let mut boot: Vec<f64> = (0..bootstrap)
        .filter_map(|_| {
            let sample: Vec<(f64, f64)> = (0..xy.len()).map(|_| xy[rng.below(xy.len())]).collect();
            line(&sample).map(|(_, b)| b)
        })
        .collect();
    boot.sort_by(f64::total_cmp);
    let q = |p: f64| {
        boot.get(((boot.len() as f64 - 1.0) * p).round() as usize)
            .copied()
    };
    let ci = (q(0.025).unwrap_or(f64::NAN), q(0.975).unwrap_or(f64::NAN));
    let mut by_level: BTreeMap<u64, (f64, f64, u32)> = BTreeMap::new();
    for (r, &(_, y)) in rs.iter().zip(&xy) {
        let e =
            by_level
                .entry(r.comparison_value.to_bits())
                .or_insert((r.comparison_value, 0.0, 0));
        e.1 += y;
        e.2 += 1;
    }
    let mut levels: Vec<(f64, f64, u32)> = by_level
        .into_values()
        .map(|(v, sy, n)| (v, (sy / f64::from(n)).exp(), n))
        .collect();
    levels.sort_by(|x, y| x.0.total_cmp(&y.0));
    Ok(ConditionResult {
        condition: name.to_string(),
        vary: first.vary.clone(),
        reference_value: rv,
        trials: rs.len() as u32,
        points: levels
            .iter()
            .map(|&(x, _, n)| Point { x, n, k: 0 })
            .collect(),
        fit: PsyFit {
            shape: Shape::Normal,
            alpha: f64::NAN,
            beta: f64::NAN,
            guess: f64::NAN,
            symmetric: false,
            lapse: f64::NAN,
            nll: f64::NAN,
        },
        jnd: f64::NAN,
        jnd_ci: (f64::NAN, f64::NAN),
        weber: f64::NAN,
        weber_ci: (f64::NAN, f64::NAN),
        staircase_estimate: None,
        tracks: BTreeMap::new(),
        pse: None,
        sd: None,
        magnitude: Some(MagnitudeResult {
            exponent: b,
            exponent_ci: ci,
            scale: a.exp(),
            levels,
        }),
    })
}

/// The bootstrap seed of condition number `ci`.
pub fn seed(base: u64, ci: u64) -> u64 {
    mix(base, ci)
}

/// The text report of a magnitude condition.
pub fn report(r: &ConditionResult, m: &MagnitudeResult, bootstrap: u32) -> String {
    format!(
        "{} ({}, reference {}): {} trials, Stevens' power law m = c·(value/{})^b\n  exponent b {:.4} [{:.4}, {:.4}] (95 % bootstrap over trials, {bootstrap} reps)\n  scale c {:.4} (the number of a comparison equal to the reference)\n",
        r.condition, r.vary, r.reference_value, r.trials, r.reference_value,
        m.exponent, m.exponent_ci.0, m.exponent_ci.1, m.scale
    )
}

/// Writes `magnitude.tsv` and the log–log plot `magnitude.svg/.png` in `dir`.
pub fn write(dir: &Path, res: &[ConditionResult], title: &str) -> Result<Vec<PathBuf>, String> {
    let mut tsv = String::from("condition\tvary\treference_value\ttrials\texponent\texponent_ci_lo\texponent_ci_hi\tscale\n");
    let mut panels = Vec::new();
    for (i, r) in res.iter().enumerate() {
        let Some(m) = &r.magnitude else { continue };
        tsv.push_str(&format!(
            "{}\t{}\t{}\t{}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\n",
            r.condition,
            r.vary,
            r.reference_value,
            r.trials,
            m.exponent,
            m.exponent_ci.0,
            m.exponent_ci.1,
            m.scale
        ));
        let (lo, hi) = m.levels.iter().fold((f64::INFINITY, 0.0f64), |(a, b), l| {
            (a.min(l.0), b.max(l.0))
        });
        let fit: Vec<(f64, f64)> = (0..=50)
            .map(|j| {
                let v = lo * (hi / lo).powf(f64::from(j) / 50.0);
                (v, m.scale * (v / r.reference_value).powf(m.exponent))
            })
            .collect();
        let data = m.levels.iter().map(|l| (l.0, l.1)).collect();
        panels.push(Panel {
            title: format!(
                "{}: exponent {:.3} [{:.3}, {:.3}]",
                r.condition, m.exponent, m.exponent_ci.0, m.exponent_ci.1
            ),
            x_label: format!("{} (comparison)", r.vary),
            y_label: "number given (geometric mean)".into(),
            series: vec![
                Series::new("trials' geometric mean", data, i, Stroke::Markers),
                Series::new("power law", fit, i, Stroke::Solid),
            ],
            log_x: true,
            log_y: true,
            ..Panel::default()
        });
    }
    let path = dir.join("magnitude.tsv");
    std::fs::write(&path, tsv).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = vec![path];
    if !panels.is_empty() {
        out.extend(write_panels(
            &dir.join("magnitude"),
            title,
            &panels,
            2,
            (560, 420),
        )?);
    }
    Ok(out)
}
