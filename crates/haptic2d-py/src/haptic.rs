//! `_haptic2d.HapticSystem`: the haptic tick (device estimator, controller, passivity controller,
//! world) driven from Python, one tick at a time from encoder angles, or closed around the simulated
//! twin-pantograph plant and a simulated hand for studies of the device loop at any rate.

use crate::errors::{scene_error, value_error};
use crate::world::PyWorld;
use haptic2d::control::passivity::PlanarPassivity;
use haptic2d::device::linalg::V3;
use haptic2d::device::HandModel;
use haptic2d::haptic::{
    ControllerKind, DeviceInTheLoop, HapticConfig, HapticSystem, SafetyConfig, TICK_COLUMNS,
};
use haptic2d::scene::device_params_from_toml;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Plant RK4 sub-steps per tick: at most 0.5 ms each (as `haptic2d run` does).
fn plant_substeps(dt: f64) -> u32 {
    ((dt / 0.0005).ceil() as u32).max(1)
}

/// The hand model `kind` with numbers `a` for a handle starting at `start` (m, m, rad).
fn hand_model(kind: &str, a: &[f64], start: V3) -> PyResult<HandModel> {
    if let Some(v) = a.iter().find(|v| !v.is_finite()) {
        return Err(value_error(format!(
            "hand `{kind}`: every number must be finite, got {v}"
        )));
    }
    let want = |n: &[usize]| -> PyResult<()> {
        if n.contains(&a.len()) {
            Ok(())
        } else {
            Err(value_error(format!(
                "hand `{kind}` takes {:?} numbers, got {}",
                n,
                a.len()
            )))
        }
    };
    Ok(match kind {
        "hold" | "follow" => {
            want(&[0])?;
            HandModel::grip(start)
        }
        "free" => {
            want(&[0])?;
            HandModel::Free
        }
        "constant" => {
            want(&[3])?;
            HandModel::Constant {
                wrench: [a[0], a[1], a[2]],
            }
        }
        "sine" => {
            want(&[2, 4])?;
            if a[0] < 0.0 || a[1] <= 0.0 {
                return Err(value_error(format!(
                    "hand `sine`: the peak must be >= 0 N and the frequency > 0 Hz, got {}, {}",
                    a[0], a[1]
                )));
            }
            let d = if a.len() == 4 {
                [a[2], a[3]]
            } else {
                [1.0, 0.0]
            };
            let n = d[0].hypot(d[1]);
            if n == 0.0 {
                return Err(value_error("hand `sine`: the direction must not be zero"));
            }
            HandModel::Sinusoid {
                direction: [d[0] / n, d[1] / n, 0.0],
                peak: a[0],
                frequency: a[1],
            }
        }
        "script" => {
            want(&[5, 8])?;
            if a[0] < 0.0 || a[4] < 0.0 {
                return Err(value_error(
                    "hand `script`: HOLD and PUSH are durations and must be >= 0 s",
                ));
            }
            let HandModel::SpringDamper {
                stiffness, damping, ..
            } = HandModel::grip(start)
            else {
                return Err(value_error("internal: grip is not a spring-damper hand"));
            };
            HandModel::Scripted {
                pose: start,
                stiffness,
                damping,
                t_hold: a[0],
                push: [a[1], a[2], a[3]],
                t_push: a[4],
                release: if a.len() == 8 {
                    [a[5], a[6], a[7]]
                } else {
                    [0.0; 3]
                },
            }
        }
        _ => {
            return Err(value_error(format!(
                "unknown hand `{kind}`; valid: hold, free, constant, sine, script"
            )))
        }
    })
}

/// A haptic system closed around a simulated plant and hand.
#[pyclass(module = "haptic2d._haptic2d", name = "HapticSystem")]
pub struct PyHapticSystem {
    /// The core's closed loop (the same one the lab's device-in-the-loop experiments step).
    dil: DeviceInTheLoop,
    controller: &'static str,
}

#[pymethods]
impl PyHapticSystem {
    /// Builds the system around a copy of `world` (its period is the tick period), with the
    /// start-up torque ramp `ramp_time` (s; 0 = none) and the other safety settings at their
    /// defaults.
    #[new]
    #[pyo3(signature = (world, controller, device_toml, device_source, hand, hand_args, passivity, slave, ramp_time))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        world: &PyWorld,
        controller: &str,
        device_toml: Option<&str>,
        device_source: &str,
        hand: &str,
        hand_args: Vec<f64>,
        passivity: bool,
        slave: Option<String>,
        ramp_time: f64,
    ) -> PyResult<Self> {
        let dt = world.world.params.dt;
        let kind = ControllerKind::from_name(controller).map_err(value_error)?;
        let mut config = HapticConfig {
            controller: kind,
            slave,
            passivity: passivity.then(PlanarPassivity::default),
            ..HapticConfig::default()
        };
        if let Some(text) = device_toml {
            config.device = device_params_from_toml(text, device_source, Some(dt))
                .map_err(|e| scene_error(py, &e))?;
        }
        let safety = SafetyConfig {
            ramp_time,
            ..SafetyConfig::default()
        };
        let system =
            HapticSystem::with_safety(world.world.clone(), &config, safety).map_err(value_error)?;
        let model = hand_model(hand, &hand_args, system.device_start())?;
        // The plant starts at rest at the device origin, with encoder quantisation.
        let dil =
            DeviceInTheLoop::new(system, model, plant_substeps(dt), true).map_err(value_error)?;
        Ok(Self {
            dil,
            controller: kind.name(),
        })
    }

    /// One haptic tick from the four encoder angles (rad) to the four motor torques (N·m).
    fn tick<'py>(
        &mut self,
        py: Python<'py>,
        encoders: [f64; 4],
    ) -> Bound<'py, numpy::PyArray1<f64>> {
        let out = self.dil.system.tick(&encoders);
        out.torques.to_vec().into_pyarray(py)
    }

    /// Runs `n` ticks closed around the simulated plant and hand; returns the record columns and the
    /// plant fault that ended the run early, if any.
    fn run_simulated<'py>(
        &mut self,
        py: Python<'py>,
        n: u64,
    ) -> PyResult<(Bound<'py, PyDict>, Option<String>)> {
        let dil = &mut self.dil;
        let (values, fault) = py.detach(|| {
            let mut cols: Vec<Vec<f64>> = (0..TICK_COLUMNS.len())
                .map(|_| Vec::with_capacity(n as usize))
                .collect();
            let mut fault = None;
            for _ in 0..n {
                match dil.step() {
                    Ok(o) => {
                        for (c, v) in cols.iter_mut().zip(o.record.values()) {
                            c.push(v);
                        }
                    }
                    Err(e) => {
                        fault = Some(e.to_string());
                        break;
                    }
                }
            }
            (cols, fault)
        });
        let d = PyDict::new(py);
        for (name, v) in TICK_COLUMNS.iter().zip(values) {
            d.set_item(*name, v.into_pyarray(py))?;
        }
        Ok((d, fault))
    }

    /// Replaces the simulated hand (same forms as the constructor).
    fn set_hand(&mut self, hand: &str, hand_args: Vec<f64>) -> PyResult<()> {
        self.dil.hand = hand_model(hand, &hand_args, self.dil.system.device_start())?;
        Ok(())
    }

    /// The simulated plant's encoder angles now (rad).
    fn plant_encoders<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
        let q = self
            .dil
            .plant
            .encoders()
            .map_err(|e| value_error(e.to_string()))?;
        Ok(q.to_vec().into_pyarray(py))
    }

    /// Columns of the per-tick records, in order.
    #[staticmethod]
    fn columns() -> Vec<&'static str> {
        TICK_COLUMNS.to_vec()
    }

    /// The last tick's record as a dict of numbers.
    fn last_record<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, v) in TICK_COLUMNS
            .iter()
            .zip(self.dil.system.last_record().values())
        {
            d.set_item(*name, v)?;
        }
        Ok(d)
    }

    /// Why the safety latch is set, or `None`.
    #[getter]
    fn safety_trip(&self) -> Option<String> {
        self.dil.system.safety_trip().map(|t| t.to_string())
    }

    /// Tick period `T` (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.dil.system.dt()
    }

    /// The controller's name.
    #[getter]
    fn controller(&self) -> &'static str {
        self.controller
    }

    /// The start-up ramp factor the next tick applies (0 before the first reading and at it, 1 once
    /// ramped in).
    #[getter]
    fn ramp(&self) -> f64 {
        self.dil.system.ramp()
    }

    /// The handle pose the device starts at (m, m, rad, handle coordinates).
    #[getter]
    fn device_start(&self) -> [f64; 3] {
        self.dil.system.device_start()
    }

    /// A copy of the world as it is now.
    fn world(&self) -> PyWorld {
        PyWorld {
            world: self.dil.system.world().clone(),
            name: String::new(),
            description: String::new(),
            source: "HapticSystem".into(),
            warnings: Vec::new(),
        }
    }
}
