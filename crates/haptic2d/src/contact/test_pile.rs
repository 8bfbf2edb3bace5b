//! Test helpers for the contact set's pile runs: the disturbances the law-slot and loaded-list
//! tests apply to a pile:20, and their bit-for-bit comparison of two worlds.

use crate::world::World;

/// A sideways shove that loads the records' friction springs: every dynamic body `i` gains
/// `0.05·(i mod 3)` m/s along x.
pub(crate) fn shove(w: &mut World) {
    for (i, b) in w.bodies.iter_mut().enumerate() {
        if b.inv_mass > 0.0 {
            b.vel.x += 0.05 * (i % 3) as f64;
        }
    }
}

/// Tosses the highest dynamic body up at 0.5 m/s: the others keep their records, and it lands
/// (creating new records) while they are live.
pub(crate) fn toss_top_box(w: &mut World) {
    let top = (0..w.bodies.len())
        .filter(|&i| w.bodies[i].inv_mass > 0.0)
        .max_by(|&i, &j| w.bodies[i].pose.pos.y.total_cmp(&w.bodies[j].pose.pos.y))
        .expect("a dynamic body");
    w.bodies[top].vel.y += 0.5;
}

/// Asserts that every body of `a` and `b` has bit for bit the same pose (after step `k`).
pub(crate) fn assert_same_poses(a: &World, b: &World, k: usize) {
    let bits = |p: &crate::geom::Pose| (p.pos.x.to_bits(), p.pos.y.to_bits(), p.angle.to_bits());
    for (x, y) in a.bodies.iter().zip(&b.bodies) {
        assert_eq!(bits(&x.pose), bits(&y.pose), "step {k}");
    }
}
