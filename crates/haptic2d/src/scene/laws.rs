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

/// What [`law_from`] needs of a law table's model (`[normal]`, `[friction]`).
trait TableModel: Sized {
    /// The table's name.
    const SECTION: &'static str;
    /// The model when the table names none.
    const DEFAULT: &'static str;
    /// The model the table stands for after an unknown name (the other problems are still found).
    fn fallback() -> Self;
    /// The model called `name`, with its per-contact defaults.
    fn per_contact(name: &str) -> Result<Self, String>;
    /// Sets the numeric parameter `key`.
    fn set(&mut self, key: &str, value: f64) -> Result<(), String>;
    /// Checks the parameters once all are set.
    fn check(&self) -> Result<(), String>;
    /// Takes `key` if it is one of the model's non-numeric keys (reporting a bad value); false if
    /// it is not. Default: there are none.
    fn set_other(&mut self, key: &str, v: &toml::Value, errs: &mut Vec<SceneError>) -> bool {
        let _ = (key, v, errs);
        false
    }
}

impl TableModel for NormalModel {
    const SECTION: &'static str = "normal";
    const DEFAULT: &'static str = "paper";
    fn fallback() -> Self {
        NormalModel::default()
    }
    fn per_contact(name: &str) -> Result<Self, String> {
        NormalModel::from_name(name, true)
    }
    fn set(&mut self, key: &str, value: f64) -> Result<(), String> {
        self.set_param(key, value)
    }
    fn check(&self) -> Result<(), String> {
        self.validate()
    }
}

impl TableModel for FrictionModel {
    const SECTION: &'static str = "friction";
    const DEFAULT: &'static str = "none";
    fn fallback() -> Self {
        FrictionModel::None
    }
    fn per_contact(name: &str) -> Result<Self, String> {
        FrictionModel::from_name(name, true)
    }
    fn set(&mut self, key: &str, value: f64) -> Result<(), String> {
        self.set_param(key, value)
    }
    fn check(&self) -> Result<(), String> {
        self.validate()
    }
    /// `load_scaling = "limit" | "stiffness"` (the reset integrator's, §1).
    fn set_other(&mut self, key: &str, v: &toml::Value, errs: &mut Vec<SceneError>) -> bool {
        if key != "load_scaling" {
            return false;
        }
        let r = match v {
            toml::Value::String(name) => {
                LoadScaling::from_name(name).and_then(|ls| self.set_load_scaling(ls))
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
        true
    }
}

/// Builds a law table's prototype: the named model (`model`, else the default) with its
/// per-contact defaults, then the given parameters, then the check of them all.
fn law_from<M: TableModel>(map: &BTreeMap<String, toml::Value>, errs: &mut Vec<SceneError>) -> M {
    let section = M::SECTION;
    let name = model_name(section, map, M::DEFAULT, errs);
    let mut m = match M::per_contact(&name) {
        Ok(m) => m,
        Err(e) => {
            errs.push(SceneError::new(
                format!("{section}.model"),
                e,
                "pick one of the listed models",
            ));
            return M::fallback();
        }
    };
    for (k, v) in map {
        if k == "model" || m.set_other(k, v, errs) {
            continue;
        }
        if let Some(x) = number(section, k, v, errs) {
            if let Err(e) = m.set(k, x) {
                errs.push(SceneError::new(
                    format!("{section}.{k}"),
                    e,
                    "remove it or use one of the listed keys",
                ));
            }
        }
    }
    if let Err(e) = m.check() {
        errs.push(SceneError::new(section, e, "fix the parameter named above"));
    }
    m
}

/// Builds the normal-law prototype (per-contact defaults, then the given parameters).
pub fn normal_from(map: &BTreeMap<String, toml::Value>, errs: &mut Vec<SceneError>) -> NormalModel {
    law_from(map, errs)
}

/// Builds the friction-model prototype (per-contact defaults, then the given parameters).
pub fn friction_from(
    map: &BTreeMap<String, toml::Value>,
    errs: &mut Vec<SceneError>,
) -> FrictionModel {
    law_from(map, errs)
}

/// The stiffest per-contact spring and damper of the chosen laws `(K, B)` (N/m, N·s/m), for the
/// minimum-mass check (§6.4).
pub fn stiffest(normal: &NormalModel, friction: &FrictionModel) -> (f64, f64) {
    let (kn, bn) = normal.stiffness_damping();
    let (kf, bf) = friction.stiffness_damping();
    (kn.max(kf), bn.max(bf))
}
