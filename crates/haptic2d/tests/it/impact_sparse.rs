//! The sparse impact path (sets larger than `DENSE_MAX_ROWS`): a column of boxes landing on the floor
//! at once. I3 (energy never increases) and I4 (no approach left) must hold as on the dense path.

use haptic2d::body::Body;
use haptic2d::contact::impact::{ImpactRow, ImpactSolver, DENSE_MAX_ROWS};
use haptic2d::geom::{Pose, Vec2};

#[test]
fn i3_i4_hold_on_the_sparse_path() {
    // A tower of 16 boxes (0.05 m, 2 kg) falling at different speeds onto a fixed floor: two corner
    // rows per interface → 32 rows > DENSE_MAX_ROWS.
    let n_boxes = 16;
    let inertia = 2.0 * (0.05f64.powi(2) * 2.0) / 12.0;
    let mut bodies = vec![Body::fixed("floor", Pose::IDENTITY)];
    for k in 0..n_boxes {
        let mut b = Body::dynamic(
            format!("b{k}"),
            2.0,
            inertia,
            Pose::new(0.0, 0.025 + 0.05 * k as f64, 0.0),
        );
        b.vel = Vec2::new(0.01 * k as f64, -0.5 - 0.1 * k as f64);
        b.omega = 0.3 * (k as f64 - 8.0);
        bodies.push(b);
    }
    let mut rows = Vec::new();
    for k in 0..n_boxes {
        let (upper, lower) = (k + 1, k); // body indices: lower 0 is the floor
        let y = 0.05 * k as f64;
        for x in [-0.025, 0.025] {
            let p = Vec2::new(x, y);
            let e = if k % 2 == 0 { 0.5 } else { 0.0 };
            rows.push(ImpactRow::at_point(
                &bodies,
                upper,
                lower,
                Vec2::new(0.0, 1.0),
                p,
                e,
            ));
        }
    }
    assert!(rows.len() > DENSE_MAX_ROWS);
    let ke_before: f64 = bodies.iter().map(|b| b.kinetic_energy()).sum();
    let mut solver = ImpactSolver::new();
    let out = solver.solve(&rows, &mut bodies);
    let ke_after: f64 = bodies.iter().map(|b| b.kinetic_energy()).sum();
    assert!(
        ke_after <= ke_before + 1e-12,
        "I3: {ke_before} → {ke_after}"
    );
    for (i, r) in rows.iter().enumerate() {
        let vel = |b: &Body, r_: Vec2| b.vel + Vec2::new(-r_.y, r_.x) * b.omega;
        let c0 =
            r.n.dot(vel(&bodies[r.body_a], r.r_a) - vel(&bodies[r.body_b], r.r_b));
        assert!(
            c0 >= -1e-6,
            "I4: row {i} still approaches at {c0} m/s ({out:?})"
        );
    }
}
