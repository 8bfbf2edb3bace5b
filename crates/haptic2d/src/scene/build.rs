//! Validation and construction: a parsed [`SceneFile`] → a [`World`], collecting every problem.

use super::body_table::bodies_from;
use super::device::device_from_table;
use super::file::SceneFile;
use super::laws::{friction_from, normal_from};
use super::load_table::loads_from;
use super::static_sink::{static_sink_warnings, thicknesses, thinnest_other};
use super::world_table::{contact_params, world_params};
use super::{SceneError, SceneErrors};
use crate::body::Body;
use crate::collide::speed_limit;
use crate::device::DeviceParams;
use crate::geom::ConvexPolygon;
use crate::integrate::min_mass;
use crate::laws::friction::FrictionModel;
use crate::laws::normal::NormalModel;
use crate::world::World;

/// A validated scene: its world, ready to run, plus any warnings.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Scene name (from the file, or the built-in name).
    pub name: String,
    /// One-line description.
    pub description: String,
    /// Where it came from (file path or `built-in:<name>`).
    pub source: String,
    /// The world at its initial state.
    pub world: World,
    /// Non-fatal remarks (e.g. light bodies accepted with `allow_light_bodies`).
    pub warnings: Vec<String>,
    /// The device parameters of the file's `[device]` table (the spec defaults with the table's
    /// fields overriding them), validated at the scene's rate; `None` when the file has no `[device]`
    /// table. Only `haptic2d run` uses them; the world alone ignores them.
    pub device: Option<DeviceParams>,
    /// `world.allow_initial_overlap`: the file accepts bodies that start overlapping.
    pub allow_initial_overlap: bool,
}

impl Scene {
    /// Bodies that start overlapping deeper than the contact tolerance `δ_c` (`world.delta_c`):
    /// beyond it a vertex is no resting contact but an interpenetration the contact model was never
    /// asked to resolve. Shallower overlaps are resting contacts (booked as stored energy at t = 0).
    /// At most [`overlap::MAX_REPORTED`](super::overlap::MAX_REPORTED) pairs; the flag says the
    /// list was cut there.
    pub fn initial_overlaps(&self) -> (Vec<super::Overlap>, bool) {
        super::overlaps(&self.world, self.world.params.delta_c)
    }

    /// Parses and validates TOML scene text. `source` names the file in messages; `rate` overrides
    /// `world.rate` (Hz) when given.
    pub fn from_toml(text: &str, source: &str, rate: Option<f64>) -> Result<Scene, SceneErrors> {
        let file: SceneFile = SceneErrors::parse(
            text,
            source,
            "check the TOML syntax and field names against docs/SCENES.md",
        )?;
        build(&file, source, rate).map_err(|errors| SceneErrors::new(source, errors))
    }
}

/// Validates `file` and builds its world: one step per TOML table, in the file's order, every
/// problem collected (a bad table is reported and the next ones are still checked).
pub(super) fn build(
    file: &SceneFile,
    source: &str,
    rate: Option<f64>,
) -> Result<Scene, Vec<SceneError>> {
    let mut errs = Vec::new();
    let mut warnings = Vec::new();
    let w = &file.world;
    let (mut params, rate_ok) = world_params(w, rate, &mut errs, &mut warnings);
    let dt = params.dt;
    params.contact = contact_params(&file.contact, &mut errs, &mut warnings);
    let device = file
        .device
        .as_ref()
        .and_then(|t| device_from_table(t, "device.", rate_ok.then_some(dt), &mut errs));
    let normal = normal_from(&file.normal, &mut errs);
    let friction = friction_from(&file.friction, &mut errs);
    let (bodies, shapes) = bodies_from(file, dt, &mut errs);
    check_min_masses(
        &bodies,
        &shapes,
        (&normal, &friction),
        dt,
        w.allow_light_bodies.unwrap_or(false),
        &mut errs,
        &mut warnings,
    );
    // Where the no-tunnelling promise needs the contact springs (issue 35): with impacts off,
    // nothing but the normal law stops a body that reaches a part, so it is stopped before a
    // corner passes the middle of the thinnest part only below `(w/2)·√(K/m)`.
    if !params.contact.impacts {
        warnings.extend(spring_stop_warnings(
            &bodies,
            &shapes,
            &normal,
            speed_limit(params.delta_prox, params.delta_c) / dt,
        ));
    }
    if normal.name() == "pulse" {
        warnings.push(PULSE_NOT_PASSIVE_2D.to_string());
    }
    let loads = loads_from(&file.loads, &bodies, &mut errs);
    warnings.extend(static_sink_warnings(&bodies, &shapes, &loads, &normal));
    if !bodies.iter().any(|b| b.is_dynamic()) && errs.is_empty() {
        warnings.push("the scene has no dynamic body: nothing will move".into());
    }
    if !errs.is_empty() {
        return Err(errs);
    }
    let name = file.name.clone().unwrap_or_else(|| source.to_string());
    Ok(Scene {
        name,
        description: file.description.clone().unwrap_or_default(),
        source: source.to_string(),
        world: World::new(bodies, shapes, loads, normal, friction, params),
        warnings,
        device,
        allow_initial_overlap: w.allow_initial_overlap.unwrap_or(false),
    })
}

/// Minimum mass (§6.4): a flat face rests on two contacts in parallel, so every dynamic body's
/// mass and inertia are checked against 2K and 2B of the stiffest law at the sample time `dt` (s).
/// Too light is an error, or a warning with `allow_light`.
fn check_min_masses(
    bodies: &[Body],
    shapes: &[Vec<ConvexPolygon>],
    (normal, friction): (&NormalModel, &FrictionModel),
    dt: f64,
    allow_light: bool,
    errs: &mut Vec<SceneError>,
    warnings: &mut Vec<String>,
) {
    let (k, b) = super::laws::stiffest(normal, friction);
    let (k2, b2) = (2.0 * k, 2.0 * b);
    for (i, body) in bodies.iter().enumerate() {
        if !body.is_dynamic() {
            continue;
        }
        let m_min = min_mass(k2, b2, dt);
        let r2 = shapes[i]
            .iter()
            .flat_map(|p| p.vertices().iter().map(|v| v.length_squared()))
            .fold(0.0, f64::max);
        let i_min = min_mass(k2 * r2, b2 * r2, dt);
        for (what, have, need, unit) in [
            ("mass", body.mass, m_min, "kg"),
            ("inertia", body.inertia, i_min, "kg·m²"),
        ] {
            if have < 1.5 * need {
                let msg = format!(
                    "{what} {have:.4e} {unit} is below 1.5 × min_{what} = {:.4e} {unit} for the stiffest contact (K = {k2} N/m, B = {b2} N·s/m for a face on two contacts, T = {dt} s): the simulation would be unstable or nearly so (§6.4)",
                    1.5 * need
                );
                if allow_light {
                    warnings.push(format!("body \"{}\": {msg}", body.name));
                } else {
                    errs.push(SceneError::new(
                        format!("body \"{}\".{what}", body.name),
                        msg,
                        "increase the mass, lower the contact stiffness/damping, raise world.rate, or set world.allow_light_bodies = true to accept it with a warning",
                    ));
                }
            }
        }
    }
}

/// The `check` warning of a scene with the braking-pulse law (docs/MODELS.md §5.7): measured on
/// `pulse-energy.toml` (impacts off, two polygons in a box, 2 s at 1 kHz).
pub const PULSE_NOT_PASSIVE_2D: &str = "normal.model = \"pulse\" is not passive in 2-D: its pulse is sized from the pair's \
     reduced mass (no rotational inertia) and pushes for n_p samples after entry whatever the body does (a spinning \
     polygon, a corner that leaves early, other contacts), so it can return more energy than the entry had; measured \
     +1.545 J on pulse-energy.toml (2 s, impacts off). Passive only in the 1-D Fig. 4 case (a face flat against a \
     wall); prefer \"paper\", \"minsky\" or \"hysteretic\" for general scenes (docs/MODELS.md §5.7)";

/// With impacts off, the speed (m/s) below which the normal law alone stops a body of mass `m`
/// before one corner passes the middle of a part of thickness `w` (m): a corner spring `K`
/// (N/m) absorbs `½·m·v²` within `w/2` iff `v ≤ (w/2)·√(K/m)` (damping and other corners only
/// help). Beyond it, the nearest line of the corner is the far face and the body can pass.
pub fn spring_stop_speed(mass: f64, k: f64, w: f64) -> f64 {
    0.5 * w * (k / mass).sqrt()
}

/// One warning per dynamic body whose [`spring_stop_speed`] against the thinnest part of any
/// other body is below `limit` (m/s, the proximity guarantee), i.e. where `check` cannot promise
/// "no tunnelling below `limit`" with impacts off.
fn spring_stop_warnings(
    bodies: &[Body],
    shapes: &[Vec<ConvexPolygon>],
    normal: &NormalModel,
    limit: f64,
) -> Vec<String> {
    let (k, _) = normal.stiffness_damping();
    let thick = thicknesses(shapes);
    let mut out = Vec::new();
    for (i, b) in bodies.iter().enumerate() {
        if !b.is_dynamic() || k.is_nan() || k <= 0.0 {
            continue;
        }
        let Some((j, w)) = thinnest_other(&thick, i) else {
            continue;
        };
        let v = spring_stop_speed(b.mass, k, w);
        if v.is_finite() && v < limit {
            out.push(format!(
                "contact.impacts = false: only the contact springs stop body \"{}\" ({:.3} kg), so the \
                 no-tunnelling promise holds below {v:.2} m/s, not {limit:.1} m/s: faster, one corner \
                 (K = {k} N/m) is not stopped within half the thinnest part it can hit (\"{}\", {:.1} mm) \
                 and can pass through it, (w/2)·√(K/m); fix: contact.impacts = true, a stiffer normal \
                 law or thicker parts",
                b.name,
                b.mass,
                bodies[j].name,
                w * 1e3
            ));
        }
    }
    out
}
