//! Python exceptions: [`SceneError`] carries the CLI's field-naming message plus `field`, `fix`,
//! `source` and `errors` attributes; everything else a user can get wrong is a `ValueError`.

use haptic2d::scene::SceneErrors;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};

pyo3::create_exception!(
    _haptic2d,
    SceneError,
    PyValueError,
    "A scene (or device file) that does not validate. The message is the one `haptic2d check` prints; \
     `field` and `fix` are those of the first problem, `errors` lists every `(field, message, fix)`, \
     `source` names the file or built-in scene."
);

/// A `SceneError` for `e`, with its attributes set.
pub fn scene_error(py: Python<'_>, e: &SceneErrors) -> PyErr {
    let err = SceneError::new_err(e.to_string().trim_end().to_string());
    let value = err.value(py);
    let first = e.errors.first();
    let set = || -> PyResult<()> {
        value.setattr("field", first.map(|f| f.field.as_str()))?;
        value.setattr("fix", first.map(|f| f.fix.as_str()))?;
        value.setattr("source", e.source.as_str())?;
        let items = PyList::empty(py);
        for x in &e.errors {
            items.append(PyTuple::new(
                py,
                [x.field.as_str(), x.message.as_str(), x.fix.as_str()],
            )?)?;
        }
        value.setattr("errors", items)?;
        Ok(())
    };
    match set() {
        Ok(()) => err,
        Err(other) => other,
    }
}

/// A `ValueError` with `msg`.
pub fn value_error(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

/// Checks that `v` is finite; the error names `what`.
pub fn finite(what: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(value_error(format!(
            "{what} must be a finite number, got {v}"
        )))
    }
}
