//! `_haptic2d.wall_run` / `_haptic2d.peg_run`: the 1-D harnesses of Figs. 4 and 7 with every wall law
//! and friction model; the Python module `haptic2d.harness` maps keyword arguments onto them.

use crate::errors::value_error;
use crate::harness::{
    run_wall, EntryImpulse, PegHarness, PegPush, WallConfig, WallIntegration, WallSample,
};
use haptic2d::control::passivity::PassivityController;
use haptic2d::laws::friction::{FrictionMode, FrictionModel};
use haptic2d::laws::normal::NormalModel;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn integration_from(name: &str) -> PyResult<WallIntegration> {
    match name {
        "exact-zoh" => Ok(WallIntegration::ExactZoh),
        "semi-implicit" => Ok(WallIntegration::SemiImplicit),
        "explicit-euler" => Ok(WallIntegration::ExplicitEuler),
        _ => Err(value_error(format!(
            "unknown integration `{name}`; valid: exact-zoh, semi-implicit, explicit-euler"
        ))),
    }
}

/// Runs the Fig. 4 wall harness (§5.1, §13.1): law `law` (spec defaults, 1-D or per-contact values)
/// with `params` set by name, a mass `mass` (kg) with plant damping `damping` (N·s/m) pushed by `push`
/// (N) from gap `gap0` (m) at `v0` (m/s), period `dt` (s) for `duration` (s).
#[pyfunction]
#[pyo3(signature = (law, params, mass, damping, push, gap0, v0, dt, duration, integration, impulse, passivity, per_contact))]
#[allow(clippy::too_many_arguments)]
pub fn wall_run<'py>(
    py: Python<'py>,
    law: &str,
    params: Vec<(String, f64)>,
    mass: f64,
    damping: f64,
    push: f64,
    gap0: f64,
    v0: f64,
    dt: f64,
    duration: f64,
    integration: &str,
    impulse: Option<(f64, f64)>,
    passivity: bool,
    per_contact: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let mut model = NormalModel::from_name(law, per_contact).map_err(value_error)?;
    for (k, v) in &params {
        if !v.is_finite() {
            return Err(value_error(format!(
                "{}: parameter `{k}` must be a finite number, got {v}",
                model.name()
            )));
        }
        model.set_param(k, *v).map_err(value_error)?;
    }
    model.validate().map_err(value_error)?;
    let cfg = WallConfig {
        mass,
        damping,
        push,
        gap0,
        v0,
        dt,
        duration,
        integration: integration_from(integration)?,
        impulse: impulse.map(|(e, v_c)| EntryImpulse { e, v_c }),
        passivity: passivity.then(PassivityController::linear),
    };
    cfg.validate().map_err(value_error)?;
    let r = py.detach(|| run_wall(&cfg, model)).map_err(value_error)?;
    let s = &r.samples;
    let col = |f: fn(&WallSample) -> f64| s.iter().map(f).collect::<Vec<f64>>();
    let d = PyDict::new(py);
    d.set_item("law", r.law)?;
    d.set_item("t", col(|q| q.t).into_pyarray(py))?;
    d.set_item("x", col(|q| q.x).into_pyarray(py))?;
    d.set_item("v", col(|q| q.v).into_pyarray(py))?;
    d.set_item("f", col(|q| q.f).into_pyarray(py))?;
    d.set_item("f_env", col(|q| q.f_env).into_pyarray(py))?;
    d.set_item("alpha", col(|q| q.alpha).into_pyarray(py))?;
    d.set_item("e_obs", col(|q| q.e_obs).into_pyarray(py))?;
    d.set_item("stored", col(|q| q.stored).into_pyarray(py))?;
    let m = &r.metrics;
    let md = PyDict::new(py);
    md.set_item("separations", m.separations)?;
    md.set_item("settle_time", m.settle_time)?;
    md.set_item("final_penetration", m.final_penetration)?;
    md.set_item("max_penetration", m.max_penetration)?;
    md.set_item("min_e_obs", m.min_e_obs)?;
    md.set_item("max_alpha", m.max_alpha)?;
    md.set_item("ratios", m.ratios().into_pyarray(py))?;
    md.set_item("entry_speeds", m.entry_speeds().into_pyarray(py))?;
    let c = &m.contacts;
    md.set_item(
        "entry_index",
        c.iter()
            .map(|c| c.entry_index as i64)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    md.set_item(
        "exit_index",
        c.iter()
            .map(|c| c.exit_index.map_or(-1, |i| i as i64))
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    md.set_item(
        "exit_speeds",
        c.iter()
            .map(|c| c.exit_speed.unwrap_or(f64::NAN))
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("metrics", md)?;
    Ok(d)
}

/// Runs the Fig. 7 peg harness (§13.2): friction model `model` with `params`, a peg of `mass` (kg) on
/// `n_contacts` contacts of normal force `f_n` (N), period `dt` (s), `duration` (s), cycle `period` (s),
/// pushed by `push`: `("raised-cosine", f_pk, freq)`, `("ramp", rate, f_max)` or `("constant", f)`.
#[pyfunction]
#[pyo3(signature = (model, params, mass, n_contacts, f_n, dt, duration, period, push, per_contact))]
#[allow(clippy::too_many_arguments)]
pub fn peg_run<'py>(
    py: Python<'py>,
    model: &str,
    params: Vec<(String, f64)>,
    mass: f64,
    n_contacts: i64,
    f_n: f64,
    dt: f64,
    duration: f64,
    period: f64,
    push: (String, f64, f64),
    per_contact: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let mut fm = FrictionModel::from_name(model, per_contact).map_err(value_error)?;
    for (k, v) in &params {
        fm.set_param(k, *v).map_err(value_error)?;
    }
    if n_contacts < 1 {
        return Err(value_error(format!(
            "n_contacts must be at least 1, got {n_contacts}"
        )));
    }
    let h = PegHarness {
        mass,
        n_contacts: n_contacts as usize,
        f_n,
        dt,
        duration,
        period,
        model: fm,
    };
    h.validate().map_err(value_error)?;
    let (kind, a, b) = push;
    for (what, v) in [("push parameter 1", a), ("push parameter 2", b)] {
        if !v.is_finite() {
            return Err(value_error(format!("{what} must be finite, got {v}")));
        }
    }
    let p = match kind.as_str() {
        "raised-cosine" => PegPush::RaisedCosine { f_pk: a, freq: b },
        "ramp" => PegPush::Ramp { rate: a, f_max: b },
        "constant" => PegPush::Constant(a),
        _ => {
            return Err(value_error(format!(
                "unknown push `{kind}`; valid: raised-cosine, ramp, constant"
            )))
        }
    };
    let r = py.detach(|| h.run(&p)).map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item("model", r.model)?;
    d.set_item("t", r.t.into_pyarray(py))?;
    d.set_item("x", r.x.into_pyarray(py))?;
    d.set_item("v", r.v.into_pyarray(py))?;
    d.set_item("f_push", r.f_push.into_pyarray(py))?;
    d.set_item("f_friction", r.f_friction.into_pyarray(py))?;
    d.set_item(
        "slip",
        r.mode
            .iter()
            .map(|m| *m == FrictionMode::Slip)
            .collect::<Vec<bool>>()
            .into_pyarray(py),
    )?;
    d.set_item("u_f", r.u_f.into_pyarray(py))?;
    let md = PyDict::new(py);
    md.set_item("creep", r.creep.into_pyarray(py))?;
    md.set_item("advance", r.advance.into_pyarray(py))?;
    md.set_item("energy_balance", r.energy_balance.into_pyarray(py))?;
    md.set_item("max_abs_x", r.max_abs_x)?;
    d.set_item("metrics", md)?;
    Ok(d)
}

/// Names of the wall laws and friction models.
#[pyfunction]
pub fn model_names() -> (Vec<&'static str>, Vec<&'static str>) {
    (
        haptic2d::laws::normal::NORMAL_MODEL_NAMES.to_vec(),
        FrictionModel::NAMES.to_vec(),
    )
}

/// The declared parameters of the wall law or friction model `model` (`laws/params.rs`): one
/// dict per parameter with `key`, `aliases`, `unit`, `rule`, `meaning` and `default` (the
/// per-contact default when `per_contact`, the 1-D one otherwise).
#[pyfunction]
#[pyo3(signature = (model, per_contact = false))]
pub fn law_params<'py>(
    py: Python<'py>,
    model: &str,
    per_contact: bool,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let normal = NormalModel::from_name(model, per_contact);
    let friction = FrictionModel::from_name(model, per_contact);
    let law: &dyn haptic2d::laws::params::Params = match (&normal, &friction) {
        (Ok(n), _) => n.params(),
        (_, Ok(f)) => f.params(),
        (Err(e), Err(_)) => {
            return Err(value_error(format!(
                "{e}; friction models: {}",
                FrictionModel::NAMES.join(", ")
            )))
        }
    };
    let mut out = Vec::new();
    for s in law.specs() {
        let d = PyDict::new(py);
        d.set_item("key", s.key)?;
        d.set_item("aliases", s.aliases.to_vec())?;
        d.set_item("unit", s.unit)?;
        d.set_item("rule", s.rule.describe())?;
        d.set_item("meaning", s.meaning)?;
        d.set_item("default", law.get(s.key))?;
        out.push(d);
    }
    Ok(out)
}
