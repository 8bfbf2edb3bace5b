//! `haptic2d.devices()`: the device registry of `haptic2d-devices` (`registry::kinds`) — the same
//! kinds, device files and limits `haptic2d run --device …` uses — as a list of dicts.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// One dict per device kind and shipped device file: `device` (the `--device` form),
/// `device_file` (the shipped file's name), `model` (`"twin"`, `"five-bar"`, `"point"`, or `None`
/// when the driver is not in this build), `limit` (N·m or N, or `None`), `limit_unit` and `summary`.
#[pyfunction]
pub fn devices(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    let kinds = haptic2d_devices::registry::kinds::kinds().map_err(PyRuntimeError::new_err)?;
    kinds
        .into_iter()
        .map(|k| {
            let d = PyDict::new(py);
            d.set_item("device", k.device)?;
            d.set_item("device_file", k.device_file)?;
            d.set_item("model", k.model)?;
            d.set_item("limit", k.limit)?;
            d.set_item("limit_unit", k.limit_unit)?;
            d.set_item("summary", k.summary)?;
            Ok(d)
        })
        .collect()
}
