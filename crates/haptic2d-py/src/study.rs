//! Trial execution for labs that drive their own experiment (PsychoPy's `StairHandler` /
//! `QuestHandler`): present one stimulus of a study file to the simulated hand and return what it
//! felt.

use crate::errors::value_error;
use haptic2d_lab::study::explore::explore;
use haptic2d_lab::study::{stimulus, Study};
use pyo3::prelude::*;
use std::path::PathBuf;

/// Builds the stimulus of `condition` in the study file `study` — its reference (`delta` `None`)
/// or its comparison with the varied parameter raised by `delta` (the unit of the condition's
/// `vary`) — in a fresh world of the study's scene (the stimulus's laws are installed before the
/// hand touches anything: no switch in contact), lets the study's simulated hand explore it (its
/// `[observer]` exploration: press, tap or stroke, through the real world step), and returns
/// `(felt stiffness N/m, [x1, x2], condition's reference value, varied parameter)`.
#[pyfunction]
#[pyo3(signature = (study, condition, delta=None))]
pub fn study_present(
    py: Python<'_>,
    study: PathBuf,
    condition: &str,
    delta: Option<f64>,
) -> PyResult<(f64, [f64; 2], f64, String)> {
    let s = Study::load(&study).map_err(value_error)?;
    let c = s
        .conditions
        .iter()
        .find(|c| c.name == condition)
        .ok_or_else(|| {
            value_error(format!(
                "{}: no condition `{condition}`; valid: {}",
                study.display(),
                s.conditions
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
    if let Some(d) = delta {
        if !d.is_finite() {
            return Err(value_error(format!("delta = {d}: give a finite number")));
        }
    }
    let (name, vary) = match delta {
        Some(d) => (&c.comparison, Some((&c.vary, d))),
        None => (&c.reference, None),
    };
    let world = stimulus::world(&s, name, vary).map_err(|e| {
        value_error(
            e.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join("; "),
        )
    })?;
    let probe = world
        .body_index(&s.probe)
        .ok_or_else(|| value_error(format!("the scene has no body called `{}`", s.probe)))?;
    let felt = py
        .detach(|| explore(world, probe, s.toward, &s.observer))
        .map_err(value_error)?;
    Ok((
        felt.stiffness,
        felt.x,
        c.reference_value,
        c.vary.to_string(),
    ))
}
