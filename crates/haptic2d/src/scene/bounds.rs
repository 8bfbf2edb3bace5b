//! The documented magnitude bounds of every number in a scene (docs/SCENES.md, "Bounds").
//!
//! Every number read from a scene must be finite and within these bounds; every allocation sized by
//! a scene (bodies, pieces, vertices) is capped here, so that no input can make the library allocate
//! without bound, loop without end or produce NaN rows. The limits are generous — orders of magnitude
//! beyond any haptic scene — and exist to turn typos and hostile files into clear errors.
//!
//! The same bounds, widened by [`DIVERGENCE_FACTOR`], define divergence during a run: a state beyond
//! them cannot come from a passive world started inside them within any allowed duration.

use super::SceneError;

/// Highest world rate (Hz): T ≥ 10 µs. Above it one simulated second costs > 10⁵ steps.
pub const MAX_RATE_HZ: f64 = 1e5;
/// Lowest world rate (Hz): T ≤ 1 s.
pub const MIN_RATE_HZ: f64 = 1.0;
/// Largest coordinate or length (m): positions, vertex coordinates, box sizes, grid origins and
/// spacings, margins. 1 km.
pub const MAX_LENGTH_M: f64 = 1e3;
/// Largest |angle| (rad), `angle` or `angle_deg` converted.
pub const MAX_ANGLE_RAD: f64 = 1e6;
/// Largest speed component (m/s).
pub const MAX_SPEED_M_S: f64 = 1e3;
/// Largest angular speed (rad/s).
pub const MAX_OMEGA_RAD_S: f64 = 1e4;
/// Largest mass (kg).
pub const MAX_MASS_KG: f64 = 1e6;
/// Largest areal density (kg/m²).
pub const MAX_DENSITY_KG_M2: f64 = 1e6;
/// Largest moment of inertia (kg·m²).
pub const MAX_INERTIA_KG_M2: f64 = 1e9;
/// Largest plant damping (N·s/m); the step also needs `b·T/m < 2` (see [`damping_ok`]).
pub const MAX_DAMPING_N_S_M: f64 = 1e6;
/// Largest load force component (N), or acceleration (m/s²) with `per_mass`.
pub const MAX_FORCE_N: f64 = 1e6;
/// Largest load torque (N·m).
pub const MAX_TORQUE_N_M: f64 = 1e6;
/// Largest load frequency (Hz).
pub const MAX_FREQUENCY_HZ: f64 = 1e4;
/// Largest contact speed parameter (`v_c`, `recollision_speed`, m/s).
pub const MAX_CONTACT_SPEED_M_S: f64 = 1e3;
/// Largest passivity-guard tolerance (J).
pub const MAX_GUARD_J: f64 = 1e6;
/// Largest chain-damper damping time `world.chain_tau` (s).
pub const MAX_CHAIN_TAU_S: f64 = 1e3;
/// Largest number of chain-damper sweeps `world.chain_sweeps` per sample.
pub const MAX_CHAIN_SWEEPS: u32 = 1000;
/// Largest `proximity_every` (samples).
pub const MAX_PROXIMITY_EVERY: u32 = 1_000_000;
/// Largest |parameter| of a normal law or friction model (stiffness N/m, damping N·s/m, …).
pub const MAX_LAW_PARAM: f64 = 1e9;
/// Largest number of vertices of one convex polygon (piece).
pub const MAX_VERTICES: usize = 128;
/// Largest number of convex pieces of one body.
pub const MAX_PIECES_PER_BODY: usize = 64;
/// Largest number of bodies in a scene (bodies plus every grid's boxes, and `pile:N`).
pub const MAX_BODIES: usize = 20_000;
/// Largest number of loads (after `body = "*"` expands to every dynamic body).
pub const MAX_LOADS: usize = 40_000;
/// Largest scene file read (bytes): 16 MiB, far above any scene (pile.toml is ~1 kB).
pub const MAX_FILE_BYTES: u64 = 16 << 20;
/// Largest number of samples one `simulate` may run (duration × rate).
pub const MAX_SAMPLES: f64 = 1e9;
/// A running world has diverged when a position, speed or angular speed exceeds its input bound
/// times this factor (or any state is non-finite).
pub const DIVERGENCE_FACTOR: f64 = 1e3;

/// True when explicit plant damping `b` on mass `m` is stable at period `dt`: the semi-implicit
/// step's velocity update is `v⁺ = v·(1 − b·T/m) + F·T/m`, whose amplification `|1 − b·T/m|` is < 1
/// iff `0 ≤ b·T/m < 2` (at 2 the velocity flips sign every sample without decaying).
pub fn damping_ok(b: f64, m: f64, dt: f64) -> bool {
    b * dt / m < 2.0
}

/// Checks that `x` is finite with `|x| ≤ max`; else an error on `field` naming the bound.
pub(super) fn check_abs(
    field: &str,
    x: f64,
    max: f64,
    unit: &str,
    errs: &mut Vec<SceneError>,
) -> bool {
    if x.is_finite() && x.abs() <= max {
        return true;
    }
    errs.push(SceneError::new(
        field,
        if x.is_finite() {
            format!("{x} {unit} is beyond the documented bound |x| ≤ {max:e} {unit}")
        } else {
            format!("is {x}: every number must be finite")
        },
        format!("give a finite value within ±{max:e} {unit} (bounds: docs/SCENES.md)"),
    ));
    false
}

/// Checks that `x` is finite and in `(0, max]`; else an error on `field`.
pub(super) fn check_pos(
    field: &str,
    x: f64,
    max: f64,
    unit: &str,
    errs: &mut Vec<SceneError>,
) -> bool {
    if x.is_finite() && x > 0.0 && x <= max {
        return true;
    }
    let noun = match unit {
        "kg" => "mass",
        "kg/m²" => "density",
        "kg·m²" => "inertia",
        "m" => "length",
        "m/s" => "speed",
        _ => "value",
    };
    errs.push(SceneError::new(
        field,
        format!("must be a positive {noun} in {unit}, at most {max:e}, got {x}"),
        format!("give a finite value in (0, {max:e}] {unit} (bounds: docs/SCENES.md)"),
    ));
    false
}

/// Checks a count `n` against `max`; else an error on `field`.
pub(super) fn check_count(
    field: &str,
    n: usize,
    max: usize,
    what: &str,
    errs: &mut Vec<SceneError>,
) -> bool {
    if n <= max {
        return true;
    }
    errs.push(SceneError::new(
        field,
        format!("{n} {what} is above the documented cap of {max}"),
        format!("use at most {max} {what} (bounds: docs/SCENES.md)"),
    ));
    false
}

/// Why a running world counts as diverged: the first body (in body order) whose state is non-finite
/// or beyond the input bounds × [`DIVERGENCE_FACTOR`], or a non-finite energy.
#[derive(Clone, Debug, PartialEq)]
pub struct Divergence {
    /// The body concerned (`None` for a non-finite energy).
    pub body: Option<String>,
    /// What is out of bounds, with the value and the bound.
    pub what: String,
}

impl std::fmt::Display for Divergence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.body {
            Some(b) => write!(f, "body \"{b}\": {}", self.what),
            None => write!(f, "{}", self.what),
        }
    }
}

/// Checks every body's pose and velocity and the energy ledger of `world` against the divergence
/// bounds. O(bodies), no allocation unless diverged: cheap enough to call every sample.
pub fn divergence(world: &crate::world::World) -> Option<Divergence> {
    let max_pos = MAX_LENGTH_M * DIVERGENCE_FACTOR;
    let max_v = MAX_SPEED_M_S * DIVERGENCE_FACTOR;
    let max_w = MAX_OMEGA_RAD_S * DIVERGENCE_FACTOR;
    let max_a = MAX_ANGLE_RAD * DIVERGENCE_FACTOR;
    // The common case first, branch-free: a body whose six numbers are all within their bounds
    // (`|x| ≤ max` fails for NaN and ±inf, as the test below does) needs no message. Called twice
    // a sample, so a pile:1000 spent 0.17 M instructions a step here with the tuple-array test.
    let within = |b: &crate::body::Body| {
        (b.pose.pos.x.abs() <= max_pos)
            & (b.pose.pos.y.abs() <= max_pos)
            & (b.pose.angle.abs() <= max_a)
            & (b.vel.x.abs() <= max_v)
            & (b.vel.y.abs() <= max_v)
            & (b.omega.abs() <= max_w)
    };
    for b in world.bodies.iter().filter(|b| !within(b)) {
        let checks = [
            ("x", b.pose.pos.x, max_pos, "m"),
            ("y", b.pose.pos.y, max_pos, "m"),
            ("theta", b.pose.angle, max_a, "rad"),
            ("vx", b.vel.x, max_v, "m/s"),
            ("vy", b.vel.y, max_v, "m/s"),
            ("omega", b.omega, max_w, "rad/s"),
        ];
        for (name, x, max, unit) in checks {
            // A NaN fails `is_finite`; ±inf and runaways fail the bound.
            if !x.is_finite() || x.abs() > max {
                return Some(Divergence {
                    body: Some(b.name.clone()),
                    what: format!("{name} = {x} {unit} (bound ±{max:e} {unit})"),
                });
            }
        }
    }
    let e = world.ledger();
    for (name, x) in [
        ("kinetic energy", e.kinetic),
        ("stored energy", e.stored),
        ("applied work", e.applied_work),
    ] {
        if !x.is_finite() {
            return Some(Divergence {
                body: None,
                what: format!("{name} = {x} J"),
            });
        }
    }
    None
}
