//! Stiffness × damping sweeps of the wall laws on the 1-D Fig. 4 harness (§5.1, §13.1): which
//! combinations gain energy — a Z-width style chart.
//!
//! For each wall model, a log-spaced grid of stiffness `K` and damping. "Damping" is the model's own
//! damping parameter where it has one (Minsky `B_M`, Colgate's virtual `B` with no plant damping, the
//! paper law's `Bc`), and the plant damping `b` of the mass otherwise (ZOH, SEH, PI, hysteretic, braking
//! pulse). The hysteretic wall's stiffness is scaled as a whole (`k0` and every element `k_i`, keeping
//! the 1:½:½ split and the slip forces); the PI wall keeps its integral gain `K_I`. The paper law runs
//! with its entry impulse (`e = 0.5`).
//!
//! Each grid point runs the Fig. 4 harness (0.5 kg, 2 N push from 0.02 m, 10 s, exact-ZOH) at the
//! requested rate and is classified from the contact ratios (exit/entry speed) of its first (up to 10)
//! completed contacts: geometric mean `> 1` = **gains energy** (bounces grow); `≥ 0.97` = **marginal**
//! (bounces persist); otherwise, or with fewer than 3 completed contacts, **dissipative**. A run whose
//! state becomes non-finite gains energy.

use crate::csv::write_columns;
use crate::harness::wall::{run_wall, EntryImpulse, WallConfig};
use crate::plot::{write_panels, Panel, Series, Stroke};
use haptic2d::laws::normal::NormalModel;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What "damping" means for a model in the sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum DampingKind {
    /// The law's own damping parameter (named).
    Law(&'static str),
    /// The plant damping `b` of the mass.
    Plant,
}

/// A wall model in the sweep: `(name, law, damping meaning)`.
pub const MODELS: [(&str, DampingKind); 8] = [
    ("zoh", DampingKind::Plant),
    ("seh", DampingKind::Plant),
    ("minsky", DampingKind::Law("b_m")),
    ("colgate", DampingKind::Law("b")),
    ("pi", DampingKind::Plant),
    ("hysteretic", DampingKind::Plant),
    ("pulse", DampingKind::Plant),
    ("paper", DampingKind::Law("bc")),
];

/// Sweep options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepConfig {
    /// Sample rate (Hz); `T = 1/rate`.
    pub rate_hz: f64,
    /// Grid points per axis.
    pub points: usize,
    /// Stiffness range (N/m), log-spaced.
    pub k_range: (f64, f64),
    /// Damping range (N·s/m), log-spaced.
    pub b_range: (f64, f64),
    /// Duration of each run (s).
    pub duration: f64,
}

impl Default for SweepConfig {
    fn default() -> Self {
        Self {
            rate_hz: 500.0,
            points: 12,
            k_range: (100.0, 1e5),
            b_range: (0.01, 100.0),
            duration: 10.0,
        }
    }
}

impl SweepConfig {
    /// Checks the options; the message names the option.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return Err(format!(
                "--rate must be a finite sample rate > 0 Hz, got {}",
                self.rate_hz
            ));
        }
        if !(10.0..=1e6).contains(&self.rate_hz) {
            return Err(format!(
                "--rate {} Hz is outside the supported 10 Hz … 1 MHz",
                self.rate_hz
            ));
        }
        if !(2..=64).contains(&self.points) {
            return Err(format!(
                "--points must be between 2 and 64, got {}",
                self.points
            ));
        }
        let range = |name: &str, (a, b): (f64, f64)| {
            if a.is_finite() && b.is_finite() && a > 0.0 && b > a {
                Ok(())
            } else {
                Err(format!(
                    "{name} range must satisfy 0 < min < max, got {a} … {b}"
                ))
            }
        };
        range("stiffness", self.k_range)?;
        range("damping", self.b_range)?;
        if !(self.duration.is_finite() && self.duration > 0.0) {
            return Err(format!("duration must be > 0 s, got {}", self.duration));
        }
        Ok(())
    }
}

/// The class of a grid point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WallClass {
    /// Loses energy or settles.
    Dissipative,
    /// Bounces persist at nearly constant amplitude (mean ratio in `[0.97, 1]`).
    Marginal,
    /// Gains energy: bounces grow.
    GainsEnergy,
}

/// One grid point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepPoint {
    /// Wall model.
    pub model: String,
    /// Stiffness `K` (N/m, 1-D total).
    pub k_n_m: f64,
    /// Damping (N·s/m): the law's damping parameter or the plant damping (see `damping_kind`).
    pub damping_n_s_m: f64,
    /// `"plant"` or the law's parameter name.
    pub damping_kind: String,
    /// Separations in the run.
    pub separations: usize,
    /// Geometric mean of the first (up to 10) contact ratios; `null` with none.
    pub mean_ratio: Option<f64>,
    /// Class.
    pub class: WallClass,
}

/// Log-spaced values from `a` to `b` (inclusive), `n ≥ 2` of them.
pub fn log_space(a: f64, b: f64, n: usize) -> Vec<f64> {
    let (la, lb) = (a.ln(), b.ln());
    (0..n)
        .map(|i| (la + (lb - la) * i as f64 / (n - 1) as f64).exp())
        .collect()
}

/// The law and harness of one grid point.
pub fn setup(
    model: &str,
    damping: DampingKind,
    k: f64,
    b: f64,
    dt: f64,
    duration: f64,
) -> Result<(NormalModel, WallConfig), String> {
    let mut law = NormalModel::from_name(model, false)?;
    match model {
        "hysteretic" => {
            let s = k / 2000.0;
            law.set_param("k0", 1000.0 * s)?;
            law.set_param("k1", 500.0 * s)?;
            law.set_param("k2", 500.0 * s)?;
        }
        "paper" => law.set_param("kc", k)?,
        _ => law.set_param("k", k)?,
    }
    let mut cfg = WallConfig {
        dt,
        duration,
        ..WallConfig::fig4()
    };
    match damping {
        DampingKind::Law(key) => law.set_param(key, b)?,
        DampingKind::Plant => cfg.damping = b,
    }
    if model == "paper" {
        cfg.impulse = Some(EntryImpulse::paper());
    }
    law.validate()?;
    cfg.validate()?;
    Ok((law, cfg))
}

/// Classifies a run from its contact ratios (see the module docs).
pub fn classify(ratios: &[f64], finite: bool) -> (Option<f64>, WallClass) {
    if !finite {
        return (None, WallClass::GainsEnergy);
    }
    let r: Vec<f64> = ratios.iter().take(10).copied().collect();
    if r.is_empty() {
        return (None, WallClass::Dissipative);
    }
    let mean = (r.iter().map(|x| x.max(1e-12).ln()).sum::<f64>() / r.len() as f64).exp();
    let class = if r.len() < 3 {
        WallClass::Dissipative
    } else if mean > 1.0 {
        WallClass::GainsEnergy
    } else if mean >= 0.97 {
        WallClass::Marginal
    } else {
        WallClass::Dissipative
    };
    (Some(mean), class)
}

/// Outcome of [`sweep_walls`].
#[derive(Clone, Debug)]
pub struct SweepSummary {
    /// Every grid point.
    pub points: Vec<SweepPoint>,
    /// Files written.
    pub files: Vec<PathBuf>,
}

/// Runs the sweep in parallel and writes `walls.csv`, `walls.json` and `zwidth.svg/png` into `out`.
pub fn sweep_walls(
    cfg: &SweepConfig,
    out: &Path,
    show_progress: bool,
) -> Result<SweepSummary, String> {
    cfg.validate()?;
    crate::figures::create_out_dir(out)?;
    let dt = 1.0 / cfg.rate_hz;
    let ks = log_space(cfg.k_range.0, cfg.k_range.1, cfg.points);
    let bs = log_space(cfg.b_range.0, cfg.b_range.1, cfg.points);
    let mut grid = Vec::new();
    for m in MODELS {
        for &k in &ks {
            for &b in &bs {
                grid.push((m, k, b));
            }
        }
    }
    let bar = if show_progress {
        let b = ProgressBar::new(grid.len() as u64);
        if let Ok(s) =
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} sweep")
        {
            b.set_style(s);
        }
        b
    } else {
        ProgressBar::hidden()
    };
    let points: Vec<SweepPoint> = grid
        .par_iter()
        .map(|&((model, kind), k, b)| {
            let (law, wc) = setup(model, kind, k, b, dt, cfg.duration)?;
            let r = run_wall(&wc, law)?;
            let finite = r.samples.iter().all(|s| s.x.is_finite() && s.v.is_finite());
            let (mean, class) = classify(&r.metrics.ratios(), finite);
            bar.inc(1);
            Ok(SweepPoint {
                model: model.to_string(),
                k_n_m: k,
                damping_n_s_m: b,
                damping_kind: match kind {
                    DampingKind::Law(key) => key.to_string(),
                    DampingKind::Plant => "plant".to_string(),
                },
                separations: r.metrics.separations,
                mean_ratio: mean,
                class,
            })
        })
        .collect::<Result<_, String>>()?;
    bar.finish_and_clear();

    let mut files = Vec::new();
    // CSV (numeric columns; the model and class as indices are awkward, so a text CSV is written).
    let mut text =
        String::from("model,k_n_m,damping_n_s_m,damping_kind,separations,mean_ratio,class\n");
    for p in &points {
        text.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            p.model,
            p.k_n_m,
            p.damping_n_s_m,
            p.damping_kind,
            p.separations,
            p.mean_ratio.map_or(String::new(), |m| m.to_string()),
            match p.class {
                WallClass::Dissipative => "dissipative",
                WallClass::Marginal => "marginal",
                WallClass::GainsEnergy => "gains_energy",
            }
        ));
    }
    let csv = out.join("walls.csv");
    std::fs::write(&csv, text).map_err(|e| format!("cannot write {}: {e}", csv.display()))?;
    files.push(csv);
    let json = out.join("walls.json");
    let j = serde_json::to_string_pretty(&points).map_err(|e| e.to_string())?;
    std::fs::write(&json, j).map_err(|e| format!("cannot write {}: {e}", json.display()))?;
    files.push(json);
    // Also the per-model grids of mean ratios as numeric CSVs (for scripts).
    for (model, _) in MODELS {
        let sel: Vec<&SweepPoint> = points.iter().filter(|p| p.model == model).collect();
        let col = |f: fn(&SweepPoint) -> f64| sel.iter().map(|p| f(p)).collect::<Vec<f64>>();
        let path = out.join(format!("grid_{model}.csv"));
        write_columns(
            &path,
            &["k_n_m", "damping_n_s_m", "mean_ratio"],
            &[
                &col(|p| p.k_n_m),
                &col(|p| p.damping_n_s_m),
                &col(|p| p.mean_ratio.unwrap_or(f64::NAN)),
            ],
        )?;
        files.push(path);
    }
    // Z-width chart.
    let panels: Vec<Panel> = MODELS
        .iter()
        .map(|&(model, kind)| {
            let pick = |c: WallClass| {
                points
                    .iter()
                    .filter(|p| p.model == model && p.class == c)
                    .map(|p| (p.k_n_m, p.damping_n_s_m))
                    .collect::<Vec<_>>()
            };
            let mut series = vec![
                Series::new(
                    "dissipative",
                    pick(WallClass::Dissipative),
                    2,
                    Stroke::Squares,
                ),
                Series::new("marginal", pick(WallClass::Marginal), 3, Stroke::Squares),
                Series::new(
                    "gains energy",
                    pick(WallClass::GainsEnergy),
                    1,
                    Stroke::Squares,
                ),
            ];
            if kind == DampingKind::Plant {
                series.push(Series::new(
                    "b = K·T/2",
                    ks.iter().map(|&k| (k, k * dt / 2.0)).collect(),
                    7,
                    Stroke::Dashed,
                ));
            }
            let damping = match kind {
                DampingKind::Law(key) => format!("law damping {key} (N·s/m)"),
                DampingKind::Plant => "plant damping b (N·s/m)".to_string(),
            };
            Panel {
                title: model.to_string(),
                x_label: "stiffness K (N/m)".into(),
                y_label: damping,
                series,
                log_x: true,
                log_y: true,
                y_range: Some((cfg.b_range.0 / 1.5, cfg.b_range.1 * 1.5)),
                ..Panel::default()
            }
        })
        .collect();
    files.extend(write_panels(
        &out.join("zwidth"),
        &format!(
            "Wall sweep at {} Hz: which stiffness × damping pairs gain energy (Fig. 4 harness)",
            cfg.rate_hz
        ),
        &panels,
        2,
        (560, 420),
    )?);
    Ok(SweepSummary { points, files })
}
