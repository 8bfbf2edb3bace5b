//! The lab's engines: one wall-sweep task (a grid of stiffness × damping for one law, the unit a
//! `concurrent.futures`/Dask executor runs) and `reproduce`.

use crate::errors::value_error;
use crate::harness::{classify, run_wall, sweep_setup, DampingKind, WallClass, MODELS};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Runs the Fig. 4 harness at every `(k, b)` of `ks × bs` for wall law `model` at `rate_hz` for
/// `duration` s, classified as `haptic2d sweep walls` does. Returns columns: `k_n_m`,
/// `damping_n_s_m`, `separations`, `mean_ratio` (NaN with no completed contact), `class` (0
/// dissipative, 1 marginal, 2 gains energy) and the damping meaning.
#[pyfunction]
pub fn sweep_task<'py>(
    py: Python<'py>,
    model: &str,
    ks: Vec<f64>,
    bs: Vec<f64>,
    rate_hz: f64,
    duration: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let kind = MODELS
        .iter()
        .find(|m| m.0 == model)
        .map(|m| m.1)
        .ok_or_else(|| {
            value_error(format!(
                "unknown sweep model `{model}`; valid: {}",
                MODELS.iter().map(|m| m.0).collect::<Vec<_>>().join(", ")
            ))
        })?;
    if !(rate_hz.is_finite() && (10.0..=1e6).contains(&rate_hz)) {
        return Err(value_error(format!(
            "rate must be between 10 Hz and 1 MHz, got {rate_hz}"
        )));
    }
    let dt = 1.0 / rate_hz;
    let out = py.detach(|| -> Result<_, String> {
        let mut cols = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for &k in &ks {
            for &b in &bs {
                let (law, wc) = sweep_setup(model, kind, k, b, dt, duration)?;
                let r = run_wall(&wc, law)?;
                let finite = r.samples.iter().all(|s| s.x.is_finite() && s.v.is_finite());
                let (mean, class) = classify(&r.metrics.ratios(), finite);
                cols.0.push(k);
                cols.1.push(b);
                cols.2.push(r.metrics.separations as i64);
                cols.3.push(mean.unwrap_or(f64::NAN));
                cols.4.push(match class {
                    WallClass::Dissipative => 0i64,
                    WallClass::Marginal => 1,
                    WallClass::GainsEnergy => 2,
                });
            }
        }
        Ok(cols)
    });
    let (k, b, sep, mean, class) = out.map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item("k_n_m", k.into_pyarray(py))?;
    d.set_item("damping_n_s_m", b.into_pyarray(py))?;
    d.set_item("separations", sep.into_pyarray(py))?;
    d.set_item("mean_ratio", mean.into_pyarray(py))?;
    d.set_item("class", class.into_pyarray(py))?;
    d.set_item(
        "damping_kind",
        match kind {
            DampingKind::Law(key) => key,
            DampingKind::Plant => "plant",
        },
    )?;
    Ok(d)
}

/// The wall laws of the sweep, in order.
#[pyfunction]
pub fn sweep_models() -> Vec<&'static str> {
    MODELS.iter().map(|m| m.0).collect()
}

/// Runs the paper's experiments (`all` or one figure) and writes them under `out`, as `haptic2d
/// reproduce` does. Returns `(report path, seconds, [(figure, passed, total, comparisons, failing)])`.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn reproduce(
    py: Python<'_>,
    figure: &str,
    out: PathBuf,
) -> PyResult<(
    PathBuf,
    f64,
    Vec<(String, usize, usize, usize, Vec<String>)>,
)> {
    let figure = figure.to_string();
    let s = py
        .detach(|| haptic2d_lab::reproduce(&figure, &out, false))
        .map_err(value_error)?;
    Ok((
        s.report,
        s.seconds,
        s.figures
            .into_iter()
            .map(|f| (f.name, f.passed, f.total, f.comparisons, f.failing))
            .collect(),
    ))
}
