//! `haptic2d._haptic2d`: the compiled half of the Python package `haptic2d`. The Python package
//! (`python/haptic2d/`) checks inputs, documents the API and turns columns into structured arrays;
//! this module runs every loop in Rust with the GIL released.

mod columns;
mod devices;
mod errors;
mod haptic;
mod harness;
mod harness_py;
mod lab;
mod study;
mod world;

use pyo3::prelude::*;

#[pymodule]
fn _haptic2d(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SceneError", m.py().get_type::<errors::SceneError>())?;
    m.add_class::<world::PyWorld>()?;
    m.add_class::<haptic::PyHapticSystem>()?;
    m.add_function(wrap_pyfunction!(harness_py::wall_run, m)?)?;
    m.add_function(wrap_pyfunction!(harness_py::peg_run, m)?)?;
    m.add_function(wrap_pyfunction!(harness_py::model_names, m)?)?;
    m.add_function(wrap_pyfunction!(harness_py::law_params, m)?)?;
    m.add_function(wrap_pyfunction!(lab::sweep_task, m)?)?;
    m.add_function(wrap_pyfunction!(lab::sweep_models, m)?)?;
    m.add_function(wrap_pyfunction!(lab::reproduce, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_present, m)?)?;
    m.add_function(wrap_pyfunction!(devices::devices, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
