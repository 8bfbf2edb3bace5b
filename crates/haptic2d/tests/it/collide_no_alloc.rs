//! The per-sample collision functions do not allocate once their buffers have grown (DESIGN §1).

use crate::counting_alloc;
use counting_alloc::allocations;
use haptic2d::collide::{BroadPhase, Collider, LocalStage, DEFAULT_DELTA_C, DEFAULT_DELTA_PROX};
use haptic2d::geom::{ConvexPolygon, Pose};

/// A box falling onto a wall between two posts, with the global stage every 10 samples: after a
/// first pass over the motion (warm-up), a second identical pass allocates nothing.
#[test]
fn collide_update_functions_do_not_allocate_after_warm_up() {
    let wall = ConvexPolygon::rectangle(0.4, 0.02).unwrap();
    let post = ConvexPolygon::rectangle(0.02, 0.1).unwrap();
    let boxp = ConvexPolygon::rectangle(0.04, 0.02).unwrap();
    let pose_box = |k: usize| Pose::new(0.0, 0.05 - 0.0002 * k as f64, 0.001 * k as f64);
    let mut cols = vec![
        Collider::new(0, false, wall, &Pose::new(0.0, -0.01, 0.0)),
        Collider::new(0, false, post.clone(), &Pose::new(-0.03, 0.05, 0.0)),
        Collider::new(0, false, post, &Pose::new(0.03, 0.05, 0.0)),
        Collider::new(1, true, boxp, &pose_box(0)),
    ];
    let mut broad = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let mut local = LocalStage::new();
    let mut pairs = Vec::new();
    let mut out = Vec::new();
    let mut run = |cols: &mut Vec<Collider>| {
        let mut total = 0;
        for k in 0..300 {
            cols[3].update(&pose_box(k));
            if k % 10 == 0 {
                broad.update(cols, &mut pairs);
            }
            local.update(cols, &pairs, DEFAULT_DELTA_C, &mut out);
            total += out.len();
        }
        total
    };
    let first = run(&mut cols);
    let before = allocations();
    let second = run(&mut cols);
    let after = allocations();
    assert_eq!(first, second);
    assert!(first > 0, "the box must touch something");
    assert_eq!(after - before, 0, "allocations in the second pass");
}
