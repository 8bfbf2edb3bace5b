//! Criterion benchmark `world_step`: one `World::step` (proximity every N_g samples, local stage,
//! contacts, impacts, laws, integration) on the built-in scenes, in a representative state: each
//! world is first run for `warm` seconds (box resting on the wall, peg sliding, pile settled), then
//! timed in windows of [`WINDOW`] steps, each from a fresh copy of that state. Stepping one world for
//! the whole measurement (millions of steps, hours of simulated time) would time whatever the scene
//! ends in instead: the peg, pushed for that long, leaves the hole and flies free.
//!
//! `cargo bench -p haptic2d --bench world_step`

use criterion::{criterion_group, criterion_main, Criterion};
use haptic2d::scene::builtin;
#[path = "support/windowed.rs"]
mod windowed;
use std::time::Duration;
use windowed::windowed_steps;

/// Steps timed from one copy of the warmed state (a few simulated seconds; a multiple of every
/// scene's proximity period, so each window sees the same share of global-stage steps).
const WINDOW: u64 = 2000;

fn warmed(scene: &str, warm_s: f64) -> haptic2d::world::World {
    let mut w = builtin(scene, None)
        .expect("built-in")
        .expect("valid")
        .world;
    for _ in 0..(warm_s / w.params.dt) as usize {
        w.step();
    }
    w
}

fn world_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("world_step");
    g.warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for (scene, warm) in [
        ("box-in-walls", 1.0),
        ("box-in-walls-tilt", 0.05),
        ("peg-in-hole", 0.5),
        ("pile:10", 2.0),
        ("pile:100", 2.0),
        ("pile:1000", 3.0),
    ] {
        let mut w = warmed(scene, warm);
        if scene == "pile:1000" {
            g.sample_size(20);
        }
        let w0 = w.clone();
        g.bench_function(scene, |b| {
            b.iter_custom(|iters| windowed_steps(&mut w, &w0, iters, WINDOW))
        });
    }
    g.finish();
}

criterion_group!(benches, world_step);
criterion_main!(benches);
