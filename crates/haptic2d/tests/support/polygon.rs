//! Random convex polygons for the seeded collision suites.

use haptic2d::geom::{ConvexPolygon, Vec2};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// A random strictly convex polygon: `n ∈ [3, 12]` points on an ellipse with semi-axes in
/// `[0.5, 1.5]·r`, `r ∈ [r_min, r_max]` (m), one point per angular sector, jittered within the
/// middle 40 % of the sector so that no gap reaches π and the frame origin is inside.
pub fn random_polygon(rng: &mut ChaCha8Rng, r_min: f64, r_max: f64) -> ConvexPolygon {
    let n = rng.random_range(3..=12usize);
    let r = rng.random_range(r_min..r_max);
    let (sx, sy) = (rng.random_range(0.5..1.5), rng.random_range(0.5..1.5));
    let phase = rng.random_range(0.0..TAU);
    let pts = (0..n)
        .map(|k| {
            let a = phase + TAU * (k as f64 + 0.3 + 0.4 * rng.random::<f64>()) / n as f64;
            Vec2::new(r * sx * a.cos(), r * sy * a.sin())
        })
        .collect();
    ConvexPolygon::new(pts).expect("points on an ellipse, one per sector, are strictly convex")
}
