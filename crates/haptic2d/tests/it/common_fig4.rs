//! Shared helpers for the Fig. 4 world tests (included with `mod`).

use haptic2d::contact::ContactEvent;
use haptic2d::integrate::IntegrationMode;
use haptic2d::metrics::BounceSample;
use haptic2d::scene::builtin;
use haptic2d::world::World;

/// A Fig. 4 run through the full world pipeline.
pub struct Run {
    pub world: World,
    pub samples: Vec<BounceSample>,
    pub events: Vec<ContactEvent>,
    pub max_abs_omega: f64,
    pub max_excess: f64,
}

/// The box's minimum vertex x (the gap to the wall surface at x = 0), from its current pose.
pub fn gap(world: &World, body: usize) -> f64 {
    world
        .colliders
        .iter()
        .filter(|c| c.body == body)
        .flat_map(|c| {
            c.local
                .vertices()
                .iter()
                .map(|v| world.bodies[body].pose.transform_point(*v).x)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Runs built-in `scene` for `secs` seconds in `mode` (optionally with the passivity guard).
pub fn run(scene: &str, mode: IntegrationMode, secs: f64, guard: Option<f64>) -> Run {
    let mut world = builtin(scene, None)
        .expect("built-in")
        .expect("valid")
        .world;
    world.params.mode = mode;
    if guard.is_some() {
        world = rebuild_with_guard(world, guard);
    }
    let b = world.body_index("box").unwrap();
    let n = (secs / world.params.dt).round() as usize;
    let mut samples = Vec::with_capacity(n);
    let mut events = Vec::new();
    let (mut max_abs_omega, mut max_excess) = (0.0f64, f64::NEG_INFINITY);
    for _ in 0..n {
        let body = &world.bodies[b];
        samples.push(BounceSample {
            t: world.time(),
            gap: gap(&world, b),
            v_n: body.vel.x,
            speed: body.vel.length(),
            omega: body.omega.abs(),
        });
        world.step();
        events.extend_from_slice(world.contacts().events());
        max_abs_omega = max_abs_omega.max(world.bodies[b].omega.abs());
        max_excess = max_excess.max(world.ledger().excess());
    }
    Run {
        world,
        samples,
        events,
        max_abs_omega,
        max_excess,
    }
}

fn rebuild_with_guard(w: World, guard: Option<f64>) -> World {
    let mut params = w.params;
    params.guard = guard;
    let shapes = {
        let mut s: Vec<Vec<_>> = vec![Vec::new(); w.bodies.len()];
        for c in &w.colliders {
            s[c.body].push(c.local.clone());
        }
        s
    };
    World::new(w.bodies, shapes, w.loads, w.normal, w.friction, params)
}
