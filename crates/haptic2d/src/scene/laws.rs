//! `[normal]` and `[friction]` sections → law prototypes.

use super::bounds::{check_abs, MAX_LAW_PARAM};
use super::SceneError;
use crate::laws::friction::{FrictionModel, LoadScaling};
use crate::laws::normal::NormalModel;
use std::collections::BTreeMap;

fn model_name(
    section: &str,
    map: &BTreeMap<String, toml::Value>,
    default: &str,
    errs: &mut Vec<SceneError>,
) -> String {
    match map.get("model") {
        None => default.to_string(),
        Some(toml::Value::String(s)) => s.clone(),
        Some(v) => {
            errs.push(SceneError::new(
                format!("{section}.model"),
                format!("expected a model name in quotes, got {v}"),
                format!("write e.g. model = \"{default}\""),
            ));
            default.to_string()
        }
    }
}

fn number(section: &str, key: &str, v: &toml::Value, errs: &mut Vec<SceneError>) -> Option<f64> {
    let x = match v {
        toml::Value::Float(f) => *f,
        toml::Value::Integer(i) => *i as f64,
        other => {
            errs.push(SceneError::new(
                format!("{section}.{key}"),
                format!("expected a number, got {other}"),
                "write a plain number in SI units, e.g. 1000.0",
            ));
            return None;
        }
    };
    check_abs(
        &format!("{section}.{key}"),
        x,
        MAX_LAW_PARAM,
        "(SI units)",
        errs,
    )
    .then_some(x)
}

/// Builds the normal-law prototype (per-contact defaults, then the given parameters).
pub fn normal_from(map: &BTreeMap<String, toml::Value>, errs: &mut Vec<SceneError>) -> NormalModel {
    let name = model_name("normal", map, "paper", errs);
    let mut m = match NormalModel::from_name(&name, true) {
        Ok(m) => m,
        Err(e) => {
            errs.push(SceneError::new(
                "normal.model",
                e,
                "pick one of the listed models",
            ));
            return NormalModel::default();
        }
    };
    for (k, v) in map {
        if k == "model" {
            continue;
        }
        if let Some(x) = number("normal", k, v, errs) {
            if let Err(e) = m.set_param(k, x) {
                errs.push(SceneError::new(
                    format!("normal.{k}"),
                    e,
                    "remove it or use one of the listed keys",
                ));
            }
        }
    }
    if let Err(e) = m.validate() {
        errs.push(SceneError::new(
            "normal",
            e,
            "fix the parameter named above",
        ));
    }
    m
}

/// Builds the friction-model prototype (per-contact defaults, then the given parameters).
pub fn friction_from(
    map: &BTreeMap<String, toml::Value>,
    errs: &mut Vec<SceneError>,
) -> FrictionModel {
    let name = model_name("friction", map, "none", errs);
    let mut m = match FrictionModel::from_name(&name, true) {
        Ok(m) => m,
        Err(e) => {
            errs.push(SceneError::new(
                "friction.model",
                e,
                "pick one of the listed models",
            ));
            return FrictionModel::None;
        }
    };
    for (k, v) in map {
        if k == "model" {
            continue;
        }
        if k == "load_scaling" {
            let r = match v {
                toml::Value::String(name) => {
                    LoadScaling::from_name(name).and_then(|ls| m.set_load_scaling(ls))
                }
                other => Err(format!("expected \"limit\" or \"stiffness\", got {other}")),
            };
            if let Err(e) = r {
                errs.push(SceneError::new(
                    "friction.load_scaling",
                    e,
                    "load_scaling = \"limit\" (default) or \"stiffness\"",
                ));
            }
            continue;
        }
        if let Some(x) = number("friction", k, v, errs) {
            if let Err(e) = m.set_param(k, x) {
                errs.push(SceneError::new(
                    format!("friction.{k}"),
                    e,
                    "remove it or use one of the listed keys",
                ));
            }
        }
    }
    if let Err(e) = m.validate() {
        errs.push(SceneError::new(
            "friction",
            e,
            "fix the parameter named above",
        ));
    }
    m
}

/// The stiffest per-contact spring and damper of the chosen laws `(K, B)` (N/m, N·s/m), for the
/// minimum-mass check (§6.4).
pub fn stiffest(normal: &NormalModel, friction: &FrictionModel) -> (f64, f64) {
    let (kn, bn) = normal.stiffness_damping();
    let (kf, bf) = friction.stiffness_damping();
    (kn.max(kf), bn.max(bf))
}
