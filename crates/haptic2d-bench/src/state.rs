//! The state of a world after the run, computed the same way for every engine from its final body
//! poses and velocities and the haptic2d pieces (so no engine reports its own overlap).

use haptic2d::geom::Vec2;
use haptic2d::world::World;

/// Speed above which a body counts as moving (m/s): 1 cm/s.
pub const MOVING: f64 = 0.01;

/// Settle state after the run.
#[derive(Clone, Copy, Debug)]
pub struct State {
    /// Largest speed of any dynamic body (m/s).
    pub max_speed: f64,
    /// Dynamic bodies faster than [`MOVING`].
    pub moving: usize,
    /// Mean height of the dynamic bodies' centres (m).
    pub mean_height: f64,
    /// Largest overlap depth of any two pieces of different bodies (m), by separating axes.
    pub max_overlap: f64,
}

/// World vertices of every piece: `(body, vertices)`.
fn pieces(w: &World, poses: &[(Vec2, f64, Vec2)]) -> Vec<(usize, Vec<Vec2>)> {
    w.colliders
        .iter()
        .map(|c| {
            let (p, a, _) = poses[c.body];
            let (s, co) = a.sin_cos();
            let v = c
                .local
                .vertices()
                .iter()
                .map(|q| Vec2::new(p.x + co * q.x - s * q.y, p.y + s * q.x + co * q.y))
                .collect();
            (c.body, v)
        })
        .collect()
}

/// Overlap depth of two convex polygons (counter-clockwise or not): the smallest projection overlap
/// over the edge normals of both (separating-axis theorem); ≤ 0 when they are apart.
fn overlap(a: &[Vec2], b: &[Vec2]) -> f64 {
    let mut depth = f64::INFINITY;
    for poly in [a, b] {
        for i in 0..poly.len() {
            let e = poly[(i + 1) % poly.len()] - poly[i];
            let len = e.length();
            if len == 0.0 {
                continue;
            }
            let n = Vec2::new(-e.y / len, e.x / len);
            let proj = |p: &[Vec2]| {
                p.iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        let d = n.x * v.x + n.y * v.y;
                        (lo.min(d), hi.max(d))
                    })
            };
            let (alo, ahi) = proj(a);
            let (blo, bhi) = proj(b);
            depth = depth.min(ahi.min(bhi) - alo.max(blo));
        }
    }
    depth
}

/// The state of `w`'s bodies at `poses` (position, angle, velocity per haptic2d body).
pub fn of(w: &World, poses: &[(Vec2, f64, Vec2)]) -> State {
    let dynamic: Vec<usize> = (0..w.bodies.len())
        .filter(|&i| w.bodies[i].is_dynamic())
        .collect();
    let speeds = dynamic.iter().map(|&i| poses[i].2.length());
    let max_speed = speeds.clone().fold(0.0, f64::max);
    let moving = speeds.filter(|&v| v.is_nan() || v > MOVING).count();
    let mean_height =
        dynamic.iter().map(|&i| poses[i].0.y).sum::<f64>() / dynamic.len().max(1) as f64;
    // Pairs by sweep along x over the pieces' bounds (fixed order, deterministic).
    let ps = pieces(w, poses);
    let bounds: Vec<(f64, f64, f64, f64)> = ps
        .iter()
        .map(|(_, v)| {
            v.iter().fold(
                (
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                ),
                |(x0, x1, y0, y1), p| (x0.min(p.x), x1.max(p.x), y0.min(p.y), y1.max(p.y)),
            )
        })
        .collect();
    let mut order: Vec<usize> = (0..ps.len()).collect();
    order.sort_by(|&i, &j| bounds[i].0.total_cmp(&bounds[j].0));
    let mut max_overlap: f64 = 0.0;
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            if bounds[j].0 > bounds[i].1 {
                break;
            }
            let dynamic_pair = w.bodies[ps[i].0].is_dynamic() || w.bodies[ps[j].0].is_dynamic();
            if ps[i].0 == ps[j].0 || !dynamic_pair {
                continue;
            }
            if bounds[j].2 > bounds[i].3 || bounds[i].2 > bounds[j].3 {
                continue;
            }
            max_overlap = max_overlap.max(overlap(&ps[i].1, &ps[j].1));
        }
    }
    State {
        max_speed,
        moving,
        mean_height,
        max_overlap: if max_speed.is_nan() {
            f64::NAN
        } else {
            max_overlap
        },
    }
}
