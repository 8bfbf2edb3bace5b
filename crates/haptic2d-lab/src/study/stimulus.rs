//! Stimuli: a named parameter set applied to the study's scene. The scene's `[normal]` and
//! `[friction]` tables are replaced by the stimulus's, the varied parameter is raised by the trial's
//! delta, and the result is validated and built exactly as a scene file is (so every law and every
//! parameter `set_param` accepts is available, with the scene's error messages).

use super::file::{StimulusSection, Study};
use haptic2d::scene::{Scene, SceneError};
use haptic2d::world::World;
use std::fmt;

/// A law parameter named `section.key`, e.g. `normal.kc`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Param {
    /// `normal` or `friction`.
    pub section: String,
    /// The law's parameter name (as in a scene file).
    pub key: String,
}

impl Param {
    /// Parses `normal.KEY` or `friction.KEY`.
    pub fn parse(s: &str) -> Result<Param, String> {
        match s.split_once('.') {
            Some((sec @ ("normal" | "friction"), key)) if !key.is_empty() && key != "model" => {
                Ok(Param {
                    section: sec.into(),
                    key: key.into(),
                })
            }
            _ => Err(format!(
                "`{s}` is not a law parameter (expected normal.KEY or friction.KEY, KEY not `model`)"
            )),
        }
    }
}

impl fmt::Display for Param {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.section, self.key)
    }
}

fn table<'a>(s: &'a StimulusSection, section: &str) -> Option<&'a toml::Table> {
    match section {
        "normal" => s.normal.as_ref(),
        _ => s.friction.as_ref(),
    }
}

/// The value of `p` set in stimulus `s` (a number), or why there is none.
pub fn param_value(s: &StimulusSection, p: &Param) -> Result<f64, String> {
    match table(s, &p.section).and_then(|t| t.get(&p.key)) {
        Some(toml::Value::Float(x)) => Ok(*x),
        Some(toml::Value::Integer(i)) => Ok(*i as f64),
        Some(other) => Err(format!("expected a number, got {other}")),
        None => Err(format!("the stimulus does not set {p}")),
    }
}

/// The scene TOML text of stimulus `name`, with `vary = (param, delta)` added to that parameter.
pub fn scene_text(
    study: &Study,
    name: &str,
    vary: Option<(&Param, f64)>,
) -> Result<String, Vec<SceneError>> {
    let stim = study.stimuli.get(name).ok_or_else(|| {
        vec![SceneError::new(
            "",
            format!("no stimulus called `{name}`"),
            "use a key of [stimuli]",
        )]
    })?;
    let mut scene: toml::Table = toml::from_str(&study.scene_text).map_err(|e| {
        vec![SceneError::from_toml(
            &study.scene_text,
            &e,
            "fix the scene file",
        )]
    })?;
    for (sec, t) in [("normal", &stim.normal), ("friction", &stim.friction)] {
        if let Some(t) = t {
            scene.insert(sec.into(), toml::Value::Table(t.clone()));
        }
    }
    if let Some((p, delta)) = vary {
        let base =
            param_value(stim, p).map_err(|e| vec![SceneError::new(p.to_string(), e, "set it")])?;
        let sec = scene
            .entry(p.section.clone())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        if let toml::Value::Table(t) = sec {
            t.insert(p.key.clone(), toml::Value::Float(base + delta));
        }
    }
    toml::to_string(&scene).map_err(|e| vec![SceneError::new("", e.to_string(), "report this")])
}

/// The world of stimulus `name` (with the varied parameter raised by `delta` when given), built
/// from the study's scene at the study's rate.
pub fn world(
    study: &Study,
    name: &str,
    vary: Option<(&Param, f64)>,
) -> Result<World, Vec<SceneError>> {
    let text = scene_text(study, name, vary)?;
    Scene::from_toml(&text, &study.scene_source, study.rate)
        .map(|s| s.world)
        .map_err(|e| e.errors)
}

/// The world of one interval of condition `c`: its comparison with the varied parameter raised by
/// `delta` when `comparison`, else its reference (`delta` unused). Scene errors are joined into one
/// message.
pub fn interval_world(
    study: &Study,
    c: usize,
    comparison: bool,
    delta: f64,
) -> Result<World, String> {
    let cond = &study.conditions[c];
    let (name, vary) = if comparison {
        (&cond.comparison, Some((&cond.vary, delta)))
    } else {
        (&cond.reference, None)
    };
    world(study, name, vary).map_err(|e| {
        e.iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join("; ")
    })
}
