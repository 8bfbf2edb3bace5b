//! Criterion benchmark `world_step`: one `World::step` (proximity every N_g samples, local stage,
//! contacts, impacts, laws, integration) on the built-in scenes, in a representative state: each
//! world is first run for `warm` seconds (box resting on the wall, peg sliding, pile settled).
//!
//! `cargo bench -p haptic2d --bench world_step`

use criterion::{criterion_group, criterion_main, Criterion};
use haptic2d::scene::builtin;
use std::hint::black_box;
use std::time::Duration;

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
        g.bench_function(scene, |b| b.iter(|| black_box(&mut w).step()));
    }
    g.finish();
}

criterion_group!(benches, world_step);
criterion_main!(benches);
