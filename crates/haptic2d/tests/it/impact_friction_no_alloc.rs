//! The frictional impact solver (issue 16) is on the hot path (the world step): once its buffers
//! have grown to the largest set seen, solving does not allocate (DESIGN §1).

use crate::counting_alloc;

use haptic2d::body::Body;
use haptic2d::contact::impact::{ImpactRow, ImpactSolver};
use haptic2d::contact::ImpactFriction;
use haptic2d::geom::{Pose, Vec2};

/// `n` rows of a box on the floor and a second box on it, approaching and sliding.
fn set(n: usize, k: usize) -> (Vec<Body>, Vec<ImpactRow>) {
    let mut bodies = vec![
        Body::fixed("floor", Pose::IDENTITY),
        Body::dynamic("a", 1.0, 0.01, Pose::IDENTITY),
        Body::dynamic("b", 2.0, 0.02, Pose::IDENTITY),
    ];
    bodies[1].vel = Vec2::new(0.5 + 0.1 * k as f64, -1.0);
    bodies[2].vel = Vec2::new(-0.2, -1.5);
    bodies[2].omega = 1.0 + k as f64;
    let rows = (0..n)
        .map(|i| {
            let x = 0.01 * i as f64 - 0.03;
            ImpactRow {
                body_a: 1 + i % 2,
                body_b: i % 2,
                n: Vec2::new(0.01 * i as f64, 1.0).normalize(),
                r_a: Vec2::new(x, -0.02),
                r_b: Vec2::new(x, 0.02),
                restitution: 0.5,
            }
        })
        .collect();
    (bodies, rows)
}

#[test]
fn frictional_solves_do_not_allocate_after_warm_up() {
    let mut s = ImpactSolver::with_capacity(8);
    s.set_friction(ImpactFriction::Coulomb, 0.6);
    let cases: Vec<_> = (0..40).map(|k| set(1 + k % 8, k)).collect();
    let mut scratch: Vec<Vec<Body>> = cases.iter().map(|c| c.0.clone()).collect();
    for ((b0, rows), b) in cases.iter().zip(scratch.iter_mut()) {
        b.clone_from(b0);
        s.solve(rows, b);
    }
    let before = counting_alloc::allocations();
    for _ in 0..5 {
        for ((b0, rows), b) in cases.iter().zip(scratch.iter_mut()) {
            for (d, o) in b.iter_mut().zip(b0) {
                d.vel = o.vel;
                d.omega = o.omega;
            }
            s.solve(rows, b);
        }
    }
    assert_eq!(counting_alloc::allocations() - before, 0);
}
