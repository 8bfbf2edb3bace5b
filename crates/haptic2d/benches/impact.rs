//! Criterion benchmark `impact`: the impact solve (§7 frictionless against issue 16's Coulomb
//! friction) and a `pile:100` world step with frictional impacts on.
//!
//! - `impact_solve/{none,coulomb}/N`: one `ImpactSolver::solve` of `N` = 2, 4, 8 simultaneous contacts
//!   of a box landing tilted and sliding on a fixed floor and on a second box (one island), from the
//!   same pre-impact velocities every iteration. With friction: 2 and 4 contacts use the exact
//!   enumeration of the mixed LCP, 8 the projected Gauss–Seidel.
//! - `pile_step/{none,coulomb}/pile:100`: one `World::step` of `pile:100`, timed in windows of
//!   [`WINDOW`] steps from a fresh copy of the state after `warm` seconds (0.25 s: boxes landing,
//!   impacts every few samples; 2 s: settled), as `world_step` does.
//!
//! `cargo bench -p haptic2d --bench impact`

use criterion::{criterion_group, criterion_main, Criterion};
use haptic2d::body::Body;
use haptic2d::contact::impact::{ImpactRow, ImpactSolver};
use haptic2d::contact::ImpactFriction;
use haptic2d::geom::{Pose, Vec2};
use haptic2d::scene::builtin;
#[path = "support/windowed.rs"]
mod windowed;
use std::hint::black_box;
use std::time::Duration;
use windowed::windowed_steps;

/// Steps timed from one copy of the warmed state.
const WINDOW: u64 = 250;

/// `n` contacts: alternately the lower box on the floor and the upper box on the lower one, at
/// spread lever arms, normals tilted a little; bodies approaching and sliding.
fn impact_set(n: usize) -> (Vec<Body>, Vec<ImpactRow>) {
    let mut bodies = vec![
        Body::fixed("floor", Pose::IDENTITY),
        Body::dynamic(
            "low",
            2.0,
            2.0 * 0.05 * 0.05 / 6.0,
            Pose::new(0.0, 0.025, 0.0),
        ),
        Body::dynamic("up", 1.0, 0.05 * 0.05 / 6.0, Pose::new(0.01, 0.075, 0.0)),
    ];
    bodies[1].vel = Vec2::new(0.8, -1.0);
    bodies[1].omega = 2.0;
    bodies[2].vel = Vec2::new(-0.3, -1.5);
    bodies[2].omega = -1.0;
    let rows = (0..n)
        .map(|i| {
            let x = -0.025 + 0.05 * (i / 2) as f64 / ((n / 2).max(1) as f64);
            let tilt = 0.02 * (i as f64 - n as f64 / 2.0);
            let nrm = Vec2::new(tilt.sin(), tilt.cos());
            if i % 2 == 0 {
                ImpactRow {
                    body_a: 1,
                    body_b: 0,
                    n: nrm,
                    r_a: Vec2::new(x, -0.025),
                    r_b: Vec2::new(x, 0.0),
                    restitution: 0.5,
                }
            } else {
                ImpactRow {
                    body_a: 2,
                    body_b: 1,
                    n: nrm,
                    r_a: Vec2::new(x - 0.01, -0.025),
                    r_b: Vec2::new(x, 0.025),
                    restitution: 0.5,
                }
            }
        })
        .collect();
    (bodies, rows)
}

fn impact_solve(c: &mut Criterion) {
    let mut g = c.benchmark_group("impact_solve");
    g.warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    for (mode, friction) in [
        ("none", ImpactFriction::None),
        ("coulomb", ImpactFriction::Coulomb),
    ] {
        for n in [2usize, 4, 8] {
            let (b0, rows) = impact_set(n);
            let mut bodies = b0.clone();
            let mut s = ImpactSolver::with_capacity(n);
            s.set_friction(friction, 0.5);
            g.bench_function(format!("{mode}/{n}"), |b| {
                b.iter(|| {
                    bodies.clone_from(&b0);
                    black_box(s.solve(black_box(&rows), &mut bodies));
                })
            });
        }
    }
    g.finish();
}

fn pile_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("pile_step");
    g.warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20);
    for (mode, friction) in [
        ("none", ImpactFriction::None),
        ("coulomb", ImpactFriction::Coulomb),
    ] {
        for warm in [0.25, 2.0] {
            let mut w = builtin("pile:100", None)
                .expect("built-in")
                .expect("valid")
                .world;
            w.params.contact.impact_friction = friction;
            for _ in 0..(warm / w.params.dt) as usize {
                w.step();
            }
            let w0 = w.clone();
            g.bench_function(format!("{mode}/pile:100/warm {warm} s"), |b| {
                b.iter_custom(|iters| windowed_steps(&mut w, &w0, iters, WINDOW))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, impact_solve, pile_step);
criterion_main!(benches);
