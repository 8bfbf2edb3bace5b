//! The simulated hand's explorations: what the observer model *feels* of a stimulus, measured in
//! the real world step (the stimulus's world, its contact laws, its rate), never computed from the
//! law's parameters. Three explorations, each a **model** of a way people explore a surface:
//!
//! - [`Exploration::Press`]: press the probe into the wall with `F1`, then `F2`, and feel the static
//!   stiffness `(F2 − F1)/(x2 − x1)` (N/m) from the mean probe positions at the end of each press.
//! - [`Exploration::Tap`]: launch the probe at the wall at `tap_speed` and feel its *rate-hardness*
//!   (Lawrence, Pao, Dougherty, Salada & Pavlou 2000): the largest wall force in the first
//!   `tap_window` after contact over `tap_window × entry speed` (N/m). A spring `K` gives
//!   `K·sin(ωτ)/(ωτ)` (`ω² = K/m`), a wall that pushes harder on entry (a braking pulse) more.
//! - [`Exploration::Stroke`]: press the probe on the wall with `stroke_normal` and push it along the
//!   wall with `F_t1`, then `F_t2` (below break-away), each with a tremor of `tremor_amplitude` at
//!   `tremor_hz`; feel the tangential stiffness `(F_t2 − F_t1)/(y2 − y1)` (N/m) of the stuck
//!   contact. Stick compliance lowers it; drift under the tremor (Dahl's creep) lowers it more, since
//!   the displacement grows during the hold. A stick that does not move at all feels rigid
//!   (`f64::INFINITY`).
//!
//! In every exploration the scene's loads are replaced by the simulated hand; the hand's own
//! damping `hand_damping` (N·s/m, on the probe's velocity) and its grip on the probe's angle
//! (`grip_stiffness`, `grip_damping`: a torsional spring–damper to the starting angle, as a hand
//! holding a handle) act during the presses and strokes. Without a grip, a tangential push at the
//! centre of mass turns the box on its corner springs, and that turn, not the friction, dominates
//! what the hand feels.

use super::observer::ObserverParams;
use haptic2d::geom::Vec2;
use haptic2d::load::{Load, Profile};
use haptic2d::world::World;

/// How the simulated hand explores a stimulus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exploration {
    /// Two static presses into the wall (static stiffness).
    Press,
    /// A tap at a given speed (rate-hardness).
    Tap,
    /// A press on the wall and two tangential pushes with tremor (stick stiffness and drift).
    Stroke,
}

impl Exploration {
    /// Parses `press`, `tap` or `stroke`.
    pub fn from_name(s: &str) -> Result<Self, String> {
        match s {
            "press" => Ok(Self::Press),
            "tap" => Ok(Self::Tap),
            "stroke" => Ok(Self::Stroke),
            _ => Err(format!("unknown exploration `{s}`")),
        }
    }
    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Press => "press",
            Self::Tap => "tap",
            Self::Stroke => "stroke",
        }
    }
}

/// What one exploration measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Felt {
    /// Press: mean probe positions along `toward` at the end of the two presses (m). Stroke: mean
    /// tangential positions at the end of the two pushes (m). Tap: `[entry speed (m/s), largest wall
    /// force in the window (N)]`.
    pub x: [f64; 2],
    /// The felt stiffness (N/m): static (press), rate-hardness (tap) or tangential (stroke).
    pub stiffness: f64,
}

/// Explores `world`'s probe toward the wall as `p.exploration` says (see the module documentation).
pub fn explore(
    world: World,
    probe: usize,
    toward: [f64; 2],
    p: &ObserverParams,
) -> Result<Felt, String> {
    let dir = Vec2::new(toward[0], toward[1]);
    match p.exploration {
        Exploration::Press => press(world, probe, dir, p),
        Exploration::Tap => tap(world, probe, dir, p),
        Exploration::Stroke => stroke(world, probe, dir, p),
    }
}

fn hand(world: &mut World, probe: usize, force: Vec2) {
    world.loads.clear();
    world.loads.push(Load {
        body: probe,
        force,
        torque: 0.0,
        per_mass: false,
        profile: Profile::Constant,
    });
}

fn along(world: &World, probe: usize, dir: Vec2) -> (f64, f64) {
    let b = &world.bodies[probe];
    (b.pose.pos.dot(dir), b.vel.dot(dir))
}

/// The force `t` s into a change from `from` to `to` ramped over `ramp` s (a step if 0).
fn ramp(from: f64, to: f64, t: f64, ramp: f64) -> f64 {
    if ramp <= 0.0 || t >= ramp {
        to
    } else {
        from + (to - from) * t / ramp
    }
}

/// The grip's torque holding the probe at the angle `theta0` (N·m).
fn grip(world: &World, probe: usize, theta0: f64, p: &ObserverParams) -> f64 {
    let b = &world.bodies[probe];
    -p.grip_stiffness * (b.pose.angle - theta0) - p.grip_damping * b.omega
}

/// One world step; a divergence (the step's own check, MODELS §0.5) ends the exploration with
/// an error instead of a percept.
fn step(world: &mut World) -> Result<(), String> {
    match world.step() {
        None => Ok(()),
        Some(d) => Err(format!(
            "the simulated observer's world diverged at t = {:.4} s: {d}",
            world.time()
        )),
    }
}

fn press(mut world: World, probe: usize, dir: Vec2, p: &ObserverParams) -> Result<Felt, String> {
    hand(&mut world, probe, dir * p.press_forces[0]);
    let theta0 = world.bodies[probe].pose.angle;
    let dt = world.params.dt;
    let n = (p.press_time / dt).round().max(10.0) as usize;
    let tail = (n as f64 * 0.4).ceil() as usize;
    let mut x = [0.0; 2];
    let mut from = 0.0;
    for (phase, &f) in p.press_forces.iter().enumerate() {
        let mut sum = 0.0;
        for k in 0..n {
            let v = world.bodies[probe].vel;
            let now = ramp(from, f, k as f64 * dt, p.press_ramp);
            world.loads[0].force = dir * now - v * p.hand_damping;
            world.loads[0].torque = grip(&world, probe, theta0, p);
            step(&mut world)?;
            if k >= n - tail {
                sum += along(&world, probe, dir).0;
            }
        }
        x[phase] = sum / tail as f64;
        from = f;
        let v = along(&world, probe, dir).1;
        if !v.is_finite() || v.abs() > 0.01 {
            return Err(format!(
                "the probe is still moving at {v:.3} m/s along `toward` after {:.2} s at {f} N: it did not come to rest against a wall (check `toward`, `probe` and the wall's damping, give the observer hand_damping, or lengthen observer.press_time)",
                p.press_time
            ));
        }
    }
    let dx = x[1] - x[0];
    if !(dx.is_finite() && dx > 0.0) {
        return Err(format!(
            "the probe did not move further toward the wall under the larger force (Δx = {dx:e} m): no stiffness to feel"
        ));
    }
    Ok(Felt {
        x,
        stiffness: (p.press_forces[1] - p.press_forces[0]) / dx,
    })
}

/// The wall force on the probe after the last step, against `dir` (N).
fn wall_force(world: &World, probe: usize, dir: Vec2) -> f64 {
    -world.contact_wrench(probe).force.dot(dir)
}

/// The deepest penetration of the probe's contacts at the last step (m).
fn depth(world: &World, probe: usize) -> f64 {
    world
        .contact_records()
        .filter(|r| r.state.is_some() && (r.body_a == probe || r.body_b == probe))
        .map(|r| -r.d[0])
        .fold(0.0, f64::max)
}

/// Launches the probe at `v` (no hand force) and steps until the wall pushes back; returns the
/// number of steps taken, with the world after the first step with a wall force.
fn launch(
    world: &mut World,
    probe: usize,
    dir: Vec2,
    v: f64,
    max_steps: usize,
) -> Result<Option<usize>, String> {
    world.loads.clear();
    world.bodies[probe].vel = dir * v;
    world.bodies[probe].omega = 0.0;
    for k in 1..=max_steps {
        step(world)?;
        if wall_force(world, probe, dir) > 0.0 {
            return Ok(Some(k));
        }
    }
    Ok(None)
}

/// The tap, phase-locked: a first launch at `tap_speed` finds when the probe crosses the surface
/// (from the penetration at the first sample with a wall force); the second launch, at a speed
/// adjusted by less than half a sample's travel, crosses it at mid-sample, so every stimulus is felt
/// at the same sampling phase (a real hand's taps land at random phases; the model removes that
/// nuisance). The rate-hardness is the largest wall force over the `tap_window` samples from the
/// first one inside, over `tap_window × speed`.
fn tap(world: World, probe: usize, dir: Vec2, p: &ObserverParams) -> Result<Felt, String> {
    let dt = world.params.dt;
    let max_steps = (5.0 / dt) as usize;
    let v = p.tap_speed;
    let mut first = world.clone();
    let k1 = launch(&mut first, probe, dir, v, max_steps)?.ok_or_else(|| {
        "the tapping probe met no wall within 5 s (check `toward` and `probe`)".to_string()
    })?;
    // Position after step k is x0 + v·k·T; the contact force of step k is computed at x0 + v·(k−1)·T.
    let crossing = (k1 - 1) as f64 * dt - depth(&first, probe) / v;
    let n = (crossing / dt).floor();
    if n < 3.0 {
        return Err(format!(
            "the probe starts {:.2e} m from the wall: too close to tap at {v} m/s (give the scene a gap of several samples' travel)",
            v * crossing
        ));
    }
    let v2 = v * crossing / ((n + 0.5) * dt);
    let mut second = world;
    let k2 = launch(&mut second, probe, dir, v2, max_steps)?
        .ok_or_else(|| "the phase-locked tap met no wall".to_string())?;
    if k2 != n as usize + 2 {
        return Err(format!(
            "the phase-locked tap touched at step {k2}, expected {} (the approach is not a free flight: check the scene's loads and damping)",
            n as usize + 2
        ));
    }
    let window = (p.tap_window / dt).round().max(1.0) as usize;
    let mut peak = wall_force(&second, probe, dir);
    for _ in 1..window {
        step(&mut second)?;
        peak = peak.max(wall_force(&second, probe, dir));
    }
    let rh = peak / (window as f64 * dt * v2);
    if !(rh.is_finite() && rh > 0.0) {
        return Err(format!(
            "no rate-hardness to feel (peak wall force {peak} N)"
        ));
    }
    Ok(Felt {
        x: [v2, peak],
        stiffness: rh,
    })
}

fn stroke(mut world: World, probe: usize, dir: Vec2, p: &ObserverParams) -> Result<Felt, String> {
    let t = Vec2::new(-dir.y, dir.x);
    let dt = world.params.dt;
    let n = (p.press_time / dt).round().max(10.0) as usize;
    let tail = (n as f64 * 0.4).ceil() as usize;
    let fnorm = p.stroke_normal;
    hand(&mut world, probe, dir * fnorm);
    let theta0 = world.bodies[probe].pose.angle;
    // The normal press ramps in with the tangential push at 0; then each push ramps from the
    // previous one, the tremor on top.
    let push = |world: &mut World, fnow: f64, ft: f64, shake: bool, k: usize| {
        let time = k as f64 * dt;
        let tremor = if shake {
            p.tremor_amplitude * (std::f64::consts::TAU * p.tremor_hz * time).sin()
        } else {
            0.0
        };
        let v = world.bodies[probe].vel;
        world.loads[0].force = dir * fnow + t * (ft + tremor) - v * p.hand_damping;
        world.loads[0].torque = grip(world, probe, theta0, p);
        step(world)
    };
    for k in 0..n {
        let fnow = ramp(0.0, fnorm, k as f64 * dt, p.press_ramp);
        push(&mut world, fnow, 0.0, false, k)?;
    }
    let v = along(&world, probe, dir).1;
    if !v.is_finite() || v.abs() > 0.01 {
        return Err(format!(
            "the probe is still moving at {v:.3} m/s toward the wall after {:.2} s at {fnorm} N: it did not come to rest against it (check `toward`, `probe`, the scene's gap and damping)",
            p.press_time
        ));
    }
    let mut y = [0.0; 2];
    let mut from = 0.0;
    for (phase, &ft) in p.stroke_forces.iter().enumerate() {
        let mut sum = 0.0;
        for k in 0..n {
            let now = ramp(from, ft, k as f64 * dt, p.press_ramp);
            push(&mut world, fnorm, now, true, k)?;
            if k >= n - tail {
                sum += along(&world, probe, t).0;
            }
        }
        y[phase] = sum / tail as f64;
        from = ft;
        let vt = along(&world, probe, t).1;
        if !vt.is_finite() || vt.abs() > 0.01 {
            return Err(format!(
                "the probe slides along the wall at {vt:.3} m/s under a tangential push of {ft} N: the push exceeds the friction's break-away (lower observer.stroke_forces or raise stroke_normal)"
            ));
        }
    }
    let dy = y[1] - y[0];
    let stiffness = if dy > 0.0 {
        (p.stroke_forces[1] - p.stroke_forces[0]) / dy
    } else if dy.is_finite() && dy.abs() < 1e-12 {
        f64::INFINITY // a stick that does not move: rigid
    } else {
        return Err(format!(
            "the probe moved against the larger tangential push (Δy = {dy:e} m): no stiffness to feel"
        ));
    };
    Ok(Felt { x: y, stiffness })
}
