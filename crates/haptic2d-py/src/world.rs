//! `_haptic2d.World`: a planar world loaded from a scene, stepped from Python. The Python class
//! `haptic2d.World` wraps it and documents it; state getters return copies (bodies are stored as an
//! array of structs, so there is nothing to view into).

use crate::columns::WorldColumns;
use crate::errors::{finite, scene_error, value_error, SceneError};
use haptic2d::contact::ContactState;
use haptic2d::geom::Vec2;
use haptic2d::scene::{builtin, builtin_names, Scene};
use haptic2d::world::World;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::Path;

/// Steps at or above this count release the GIL (below it the release costs more than it frees).
const DETACH_STEPS: u64 = 256;

/// A world and where it came from.
#[pyclass(module = "haptic2d._haptic2d", name = "World")]
#[derive(Clone)]
pub struct PyWorld {
    /// The world.
    pub world: World,
    /// Scene name.
    #[pyo3(get)]
    pub name: String,
    /// One-line description of the scene.
    #[pyo3(get)]
    pub description: String,
    /// File path or `built-in:<name>`.
    #[pyo3(get)]
    pub source: String,
    /// Non-fatal remarks from validation.
    #[pyo3(get)]
    pub warnings: Vec<String>,
}

impl PyWorld {
    fn from_scene(s: Scene) -> Self {
        Self {
            world: s.world,
            name: s.name,
            description: s.description,
            source: s.source,
            warnings: s.warnings,
        }
    }

    /// The index of `body` (a name or an index); the error lists the bodies.
    pub fn body_index(&self, body: &Bound<'_, PyAny>) -> PyResult<usize> {
        let n = self.world.bodies.len();
        let list = || {
            self.world
                .bodies
                .iter()
                .map(|b| b.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        if let Ok(i) = body.extract::<i64>() {
            return if i >= 0 && (i as usize) < n {
                Ok(i as usize)
            } else {
                Err(value_error(format!(
                    "body index {i} out of range: the world has {n} bodies ({})",
                    list()
                )))
            };
        }
        let name: String = body.extract().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(
                "body must be a body name (str) or an index (int)",
            )
        })?;
        self.world
            .body_index(&name)
            .ok_or_else(|| value_error(format!("no body named \"{name}\"; bodies: {}", list())))
    }
}

fn check_rate(rate: Option<f64>) -> PyResult<()> {
    if let Some(r) = rate {
        if !(r.is_finite() && r > 0.0) {
            return Err(value_error(format!(
                "rate must be a positive number of Hz, got {r}"
            )));
        }
    }
    Ok(())
}

/// The column arrays of a run as a dict (CSV order).
fn columns_dict<'py>(py: Python<'py>, cols: WorldColumns) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let WorldColumns {
        names,
        values,
        contacts,
        ..
    } = cols;
    let mut values = values.into_iter();
    let mut contacts = Some(contacts);
    for name in names {
        if name == "contacts" {
            d.set_item(name, contacts.take().unwrap_or_default().into_pyarray(py))?;
        } else if let Some(v) = values.next() {
            d.set_item(name, v.into_pyarray(py))?;
        }
    }
    Ok(d)
}

/// The message for a world that has diverged (the world's own check, MODELS §0.5 step 12).
fn diverged_message(world: &World, d: &haptic2d::scene::Divergence) -> String {
    format!(
        "the simulation diverged at t = {:.4} s: {d}\n    fix: lower the contact stiffness or raise the rate (see the minimum-mass rule, docs/SCENES.md)",
        world.time()
    )
}

#[pymethods]
impl PyWorld {
    /// Loads a scene file (a path that exists) or a built-in scene by name, as `haptic2d simulate`
    /// resolves its SCENE argument. `rate` (Hz) overrides the scene's rate.
    #[staticmethod]
    #[pyo3(signature = (name_or_path, rate=None))]
    fn load(py: Python<'_>, name_or_path: &str, rate: Option<f64>) -> PyResult<Self> {
        check_rate(rate)?;
        let path = Path::new(name_or_path);
        if path.exists() {
            let text = read_scene_file(path).map_err(value_error)?;
            return Scene::from_toml(&text, name_or_path, rate)
                .map(Self::from_scene)
                .map_err(|e| scene_error(py, &e));
        }
        if let Some(s) = builtin(name_or_path, rate) {
            return s.map(Self::from_scene).map_err(|e| scene_error(py, &e));
        }
        let fix = format!(
            "give a path to a .toml scene file, or one of the built-in scenes: {} (or pile:N)",
            builtin_names().collect::<Vec<_>>().join(", ")
        );
        let err = SceneError::new_err(format!(
            "no scene file or built-in scene named \"{name_or_path}\"\n    fix: {fix}"
        ));
        let v = err.value(py);
        v.setattr("field", "scene")?;
        v.setattr("fix", fix)?;
        v.setattr("source", name_or_path)?;
        v.setattr("errors", Vec::<(String, String, String)>::new())?;
        Err(err)
    }

    /// Parses and validates scene TOML text; `source` names it in messages.
    #[staticmethod]
    #[pyo3(signature = (text, source="<string>", rate=None))]
    fn from_toml(py: Python<'_>, text: &str, source: &str, rate: Option<f64>) -> PyResult<Self> {
        check_rate(rate)?;
        Scene::from_toml(text, source, rate)
            .map(Self::from_scene)
            .map_err(|e| scene_error(py, &e))
    }

    /// An independent copy (same state).
    fn copy(&self) -> Self {
        self.clone()
    }

    /// Advances `n` samples of `T` each; a `FloatingPointError` if the world diverges (MODELS
    /// §0.5 step 12: a non-finite state or one beyond the divergence bounds).
    #[pyo3(signature = (n=1))]
    fn step(&mut self, py: Python<'_>, n: i64) -> PyResult<()> {
        if n < 0 {
            return Err(value_error(format!("n must be >= 0 steps, got {n}")));
        }
        let n = n as u64;
        let w = &mut self.world;
        let steps = |w: &mut World| -> Result<(), String> {
            for _ in 0..n {
                if let Some(d) = w.step() {
                    return Err(diverged_message(w, &d));
                }
            }
            Ok(())
        };
        let done = if n < DETACH_STEPS {
            steps(w)
        } else {
            py.detach(|| steps(w))
        };
        done.map_err(pyo3::exceptions::PyFloatingPointError::new_err)
    }

    /// Runs `duration` s (rounded to whole samples) and returns the `haptic2d simulate` CSV columns,
    /// the initial row first, then every `every`-th sample.
    #[pyo3(signature = (duration, every=1))]
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        duration: f64,
        every: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        if !(duration.is_finite() && duration > 0.0) {
            return Err(value_error(format!(
                "duration must be a positive number of seconds, got {duration}"
            )));
        }
        if every < 1 {
            return Err(value_error(format!(
                "every must be at least 1, got {every}"
            )));
        }
        let every = every as u64;
        // As `haptic2d simulate`: the t = 0 state (contacts, stored energy) before the first row.
        self.world.prime();
        let dt = self.world.params.dt;
        let ticks = (duration / dt).round() as u64;
        let rows = (ticks / every + 1) as usize;
        let w = &mut self.world;
        let cols = py.detach(|| -> Result<WorldColumns, String> {
            let mut cols = WorldColumns::new(w, rows);
            cols.push(w);
            for k in 1..=ticks {
                if let Some(d) = w.step() {
                    return Err(diverged_message(w, &d));
                }
                if k % every == 0 {
                    cols.push(w);
                }
            }
            Ok(cols)
        });
        let cols = cols.map_err(pyo3::exceptions::PyFloatingPointError::new_err)?;
        columns_dict(py, cols)
    }

    /// Simulated time `k·T` (s).
    #[getter]
    fn time(&self) -> f64 {
        self.world.time()
    }

    /// Sample index `k` of the next step.
    #[getter]
    fn tick(&self) -> u64 {
        self.world.tick()
    }

    /// Sample period `T` (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.world.params.dt
    }

    /// Body names, in body order.
    #[getter]
    fn bodies(&self) -> Vec<String> {
        self.world.bodies.iter().map(|b| b.name.clone()).collect()
    }

    /// Whether each body is dynamic, in body order.
    #[getter]
    fn dynamic(&self) -> Vec<bool> {
        self.world.bodies.iter().map(|b| b.is_dynamic()).collect()
    }

    /// The normal law's name.
    #[getter]
    fn normal_law(&self) -> &'static str {
        self.world.normal.name()
    }

    /// The friction model's name.
    #[getter]
    fn friction_model(&self) -> &'static str {
        self.world.friction.name()
    }

    /// Copies of the body states: `x, y, theta, vx, vy, omega` arrays, one entry per body.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let b = &self.world.bodies;
        let col = |f: fn(&haptic2d::body::Body) -> f64| b.iter().map(f).collect::<Vec<f64>>();
        let d = PyDict::new(py);
        d.set_item("x", col(|b| b.pose.pos.x).into_pyarray(py))?;
        d.set_item("y", col(|b| b.pose.pos.y).into_pyarray(py))?;
        d.set_item("theta", col(|b| b.pose.angle).into_pyarray(py))?;
        d.set_item("vx", col(|b| b.vel.x).into_pyarray(py))?;
        d.set_item("vy", col(|b| b.vel.y).into_pyarray(py))?;
        d.set_item("omega", col(|b| b.omega).into_pyarray(py))?;
        Ok(d)
    }

    /// The energy ledger (J): kinetic, stored, applied_work, impact_loss, initial; and
    /// impact_energy_fallbacks (count): frictional impacts whose energy check scaled an impulse.
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = self.world.ledger();
        let d = PyDict::new(py);
        d.set_item("kinetic", e.kinetic)?;
        d.set_item("stored", e.stored)?;
        d.set_item("applied_work", e.applied_work)?;
        d.set_item("impact_loss", e.impact_loss)?;
        d.set_item("initial", e.initial)?;
        d.set_item("impact_energy_fallbacks", e.impact_energy_fallbacks)?;
        Ok(d)
    }

    /// The contact records of the last step as columns (see `haptic2d.World.contacts`).
    fn contact_columns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let recs: Vec<_> = self.world.contact_records().collect();
        let ints = |f: &dyn Fn(&haptic2d::contact::VeContact) -> i64| {
            recs.iter().map(|c| f(c)).collect::<Vec<i64>>()
        };
        let reals = |f: &dyn Fn(&haptic2d::contact::VeContact) -> f64| {
            recs.iter().map(|c| f(c)).collect::<Vec<f64>>()
        };
        let d = PyDict::new(py);
        d.set_item("body_a", ints(&|c| c.body_a as i64).into_pyarray(py))?;
        d.set_item("body_b", ints(&|c| c.body_b as i64).into_pyarray(py))?;
        d.set_item(
            "vertex_collider",
            ints(&|c| c.key.vertex_collider as i64).into_pyarray(py),
        )?;
        d.set_item("vertex", ints(&|c| c.key.vertex as i64).into_pyarray(py))?;
        d.set_item(
            "edge_collider",
            ints(&|c| c.key.edge_collider as i64).into_pyarray(py),
        )?;
        d.set_item("edge", ints(&|c| c.key.edge as i64).into_pyarray(py))?;
        d.set_item(
            "state",
            ints(&|c| match c.state {
                Some(ContactState::Colliding) => 0,
                _ => 1,
            })
            .into_pyarray(py),
        )?;
        d.set_item("normal_force", reals(&|c| c.f_n).into_pyarray(py))?;
        d.set_item("friction_force", reals(&|c| c.f_t).into_pyarray(py))?;
        d.set_item(
            "penetration",
            reals(&|c| (-c.d[0]).max(0.0)).into_pyarray(py),
        )?;
        d.set_item("distance", reals(&|c| c.d[0]).into_pyarray(py))?;
        d.set_item("point_x", reals(&|c| c.point.x).into_pyarray(py))?;
        d.set_item("point_y", reals(&|c| c.point.y).into_pyarray(py))?;
        d.set_item("normal_x", reals(&|c| c.n.x).into_pyarray(py))?;
        d.set_item("normal_y", reals(&|c| c.n.y).into_pyarray(py))?;
        d.set_item("god_x", reals(&|c| c.god_object().x).into_pyarray(py))?;
        d.set_item("god_y", reals(&|c| c.god_object().y).into_pyarray(py))?;
        Ok(d)
    }

    /// Sets the drive wrench on `body` (N, N, N·m at the centre of mass), held until changed.
    fn set_drive(&mut self, body: &Bound<'_, PyAny>, fx: f64, fy: f64, tau: f64) -> PyResult<()> {
        let i = self.body_index(body)?;
        finite("fx", fx)?;
        finite("fy", fy)?;
        finite("tau", tau)?;
        if !self.world.bodies[i].is_dynamic() {
            return Err(value_error(format!(
                "body \"{}\" is fixed; a drive needs a dynamic body",
                self.world.bodies[i].name
            )));
        }
        self.world.set_drive(i, Vec2::new(fx, fy), tau);
        Ok(())
    }

    /// Sets the pose of `body` (m, m, rad), for experiment set-up.
    fn set_pose(&mut self, body: &Bound<'_, PyAny>, x: f64, y: f64, theta: f64) -> PyResult<()> {
        let i = self.body_index(body)?;
        finite("x", x)?;
        finite("y", y)?;
        finite("theta", theta)?;
        let b = &mut self.world.bodies[i];
        b.pose.pos = Vec2::new(x, y);
        b.pose.angle = theta;
        Ok(())
    }

    /// Sets the velocity of `body` (m/s, m/s, rad/s), for experiment set-up.
    fn set_velocity(
        &mut self,
        body: &Bound<'_, PyAny>,
        vx: f64,
        vy: f64,
        omega: f64,
    ) -> PyResult<()> {
        let i = self.body_index(body)?;
        finite("vx", vx)?;
        finite("vy", vy)?;
        finite("omega", omega)?;
        let b = &mut self.world.bodies[i];
        if !b.is_dynamic() {
            return Err(value_error(format!(
                "body \"{}\" is fixed and cannot move",
                b.name
            )));
        }
        b.vel = Vec2::new(vx, vy);
        b.omega = omega;
        Ok(())
    }

    fn __repr__(&self) -> String {
        format!(
            "World({:?}, bodies={}, t={} s, T={} s)",
            self.name,
            self.world.bodies.len(),
            self.world.time(),
            self.world.params.dt
        )
    }
}

/// The scene file at `path`, at most `MAX_FILE_BYTES` (16 MiB, the CLI's cap), so
/// `World.load("/dev/zero")` is a clear `ValueError`, not a hang.
fn read_scene_file(path: &Path) -> Result<String, String> {
    use std::io::Read;
    let max = haptic2d::scene::MAX_FILE_BYTES;
    let shown = path.display();
    let file =
        std::fs::File::open(path).map_err(|e| format!("cannot read scene file {shown}: {e}"))?;
    let mut bytes = Vec::new();
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read scene file {shown}: {e}"))?;
    if bytes.len() as u64 > max {
        return Err(format!(
            "scene file {shown} is larger than the cap of {max} bytes ({} MiB)",
            max >> 20
        ));
    }
    String::from_utf8(bytes).map_err(|e| format!("scene file {shown} is not UTF-8 text ({e})"))
}
