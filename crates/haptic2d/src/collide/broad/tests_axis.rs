//! Tests of the sweep axis (`axis.rs`): the same result swept along x and along y, against a
//! test of every pair, on wide and tall random worlds; and the axis chosen.

use super::tests::{uniform, update_along};
use super::*;
use crate::geom::{ConvexPolygon, Pose};

/// A random world of `n` rotated rectangles (0.02 to 0.07 m a side) in a `w` × `h` (m) region:
/// scattered, or (every other seed) a jittered grid of `columns` columns whose neighbours'
/// inflated boxes overlap, as in a pile. About one collider in ten shares the previous one's
/// body and one in six is fixed. Returns the colliders and their poses.
fn world(
    next: &mut impl FnMut() -> f64,
    n: usize,
    w: f64,
    h: f64,
    grid: bool,
) -> Vec<(Collider, Pose)> {
    let columns = ((n as f64 * w / h).sqrt().ceil() as usize).max(1);
    let rows = n.div_ceil(columns);
    (0..n)
        .map(|i| {
            let body = if i > 0 && next() < 0.1 { i - 1 } else { i };
            let dynamic = next() > 1.0 / 6.0;
            let (x, y) = if grid {
                let (c, r) = ((i % columns) as f64, (i / columns) as f64);
                let pitch = (w / columns as f64, h / rows as f64);
                (c * pitch.0 + 0.005 * next(), r * pitch.1 + 0.005 * next())
            } else {
                (w * next(), h * next())
            };
            let shape = ConvexPolygon::rectangle(0.02 + 0.05 * next(), 0.02 + 0.05 * next());
            let pose = Pose::new(x, y, 6.0 * next());
            (Collider::new(body, dynamic, shape.unwrap(), &pose), pose)
        })
        .collect()
}

/// Every pair of two bodies, not both fixed, with its cold GJK distance (m), when their inflated
/// boxes overlap: what an update from no caches tests, in pair order.
fn every_pair(cols: &[Collider], delta_prox: f64) -> Vec<((u32, u32), f64)> {
    let half = 0.5 * delta_prox;
    let mut all = Vec::new();
    for a in 0..cols.len() {
        for b in a + 1..cols.len() {
            let (ca, cb) = (&cols[a], &cols[b]);
            if ca.body == cb.body || !(ca.dynamic || cb.dynamic) {
                continue;
            }
            if ca.aabb.inflated(half).overlaps(&cb.aabb.inflated(half)) {
                let mut cache = GjkCache::default();
                let d = gjk_distance(ca.world_vertices(), cb.world_vertices(), &mut cache).distance;
                all.push(((a as u32, b as u32), d));
            }
        }
    }
    all
}

/// The smallest separation (m, the larger of the x and y gaps) of two inflated boxes of two
/// bodies, not both fixed, that do not overlap: what the certificate's gap must not exceed.
fn least_gap(cols: &[Collider], delta_prox: f64) -> f64 {
    let half = 0.5 * delta_prox;
    let mut least = f64::INFINITY;
    for a in 0..cols.len() {
        for b in a + 1..cols.len() {
            let (ca, cb) = (&cols[a], &cols[b]);
            let (p, q) = (ca.aabb.inflated(half), cb.aabb.inflated(half));
            if ca.body == cb.body || !(ca.dynamic || cb.dynamic) || p.overlaps(&q) {
                continue;
            }
            let gap_x = (q.min.x - p.max.x).max(p.min.x - q.max.x);
            let gap_y = (q.min.y - p.max.y).max(p.min.y - q.max.y);
            least = least.min(gap_x.max(gap_y));
        }
    }
    least
}

fn bits(d: &[f64]) -> Vec<u64> {
    d.iter().map(|x| x.to_bits()).collect()
}

/// Swept along x and along y, an update publishes the same pairs, distances (bit for bit),
/// caches, set and counters, and they are those of a test of every pair (cold GJK, the set the
/// pairs closer than `δ_prox`); a second update after the bodies moved (warm caches, reused
/// distances) agrees between the axes too. Wide (4 × 0.5 m) and tall (0.5 × 4 m) worlds,
/// scattered and grid-like, 2 to 300 colliders; each certificate's gap is at most the least gap
/// of unpaired boxes, along either axis.
#[test]
fn sweeping_along_x_or_y_gives_the_same_update() {
    let mut next = uniform(0x9e37_79b9_7f4a_7c15);
    let delta = DEFAULT_DELTA_PROX;
    let (mut longest, mut reused) = (0, 0);
    for trial in 0..120 {
        let n = 2 + (298.0 * next() * next()) as usize;
        let (w, h) = if trial % 2 == 0 {
            (4.0, 0.5)
        } else {
            (0.5, 4.0)
        };
        let (cols, poses): (Vec<_>, Vec<_>) = world(&mut next, n, w, h, trial % 4 >= 2)
            .into_iter()
            .unzip();
        let want = every_pair(&cols, delta);
        let (mut x, mut y) = (
            BroadPhase::new(delta).unwrap(),
            BroadPhase::new(delta).unwrap(),
        );
        let set_x = update_along(&mut x, &cols, &vec![0.0; n], Axis::X);
        let set_y = update_along(&mut y, &cols, &vec![0.0; n], Axis::Y);
        let want_set: Vec<_> = want
            .iter()
            .filter(|(_, d)| *d < delta)
            .map(|(p, _)| *p)
            .collect();
        let want_d: Vec<f64> = want.iter().map(|(_, d)| *d).collect();
        assert_eq!(set_x, want_set, "trial {trial}");
        assert_eq!(set_y, want_set, "trial {trial}");
        for bp in [&x, &y] {
            let (pairs, d) = bp.tested_pairs();
            assert_eq!(pairs.len(), want.len(), "trial {trial}");
            assert!(
                pairs.iter().zip(&want).all(|(p, (q, _))| p == q),
                "trial {trial}"
            );
            assert_eq!(bits(d), bits(&want_d), "trial {trial}");
            let gap = bp.certificate.unwrap().gap;
            assert!(gap <= least_gap(&cols, delta), "trial {trial}: {gap}");
        }
        longest = longest.max(want.len());
        // The colliders move (up to 1 cm and 0.1 rad) and the odometers bound it (a corner is
        // at most 0.05 m from the centre): warm caches, some distances reused.
        let mut moved = cols.clone();
        let mut odo = vec![0.0; n];
        for (c, p) in moved.iter_mut().zip(&poses) {
            let (dx, dy, da) = (0.01 * next(), 0.01 * next(), 0.1 * next());
            c.update(&Pose::new(p.pos.x + dx, p.pos.y + dy, p.angle + da));
            odo[c.body] += dx + dy + 0.05 * da;
        }
        let again_x = update_along(&mut x, &moved, &odo, Axis::X);
        let again_y = update_along(&mut y, &moved, &odo, Axis::Y);
        assert_eq!(again_x, again_y, "trial {trial}");
        assert_eq!(x.stats(), y.stats(), "trial {trial}");
        assert_eq!(x.cache_pairs, y.cache_pairs, "trial {trial}");
        assert_eq!(bits(&x.distances), bits(&y.distances), "trial {trial}");
        assert_eq!(bits(&x.odo_refs), bits(&y.odo_refs), "trial {trial}");
        assert_eq!(format!("{:?}", x.caches), format!("{:?}", y.caches));
        reused += x.stats().reused_distances;
    }
    assert!(
        reused > 1000,
        "distances reused in second updates: {reused}"
    );
    assert!(longest > 100, "some worlds have many pairs ({longest})");
}

/// The chosen axis is the one along which the boxes' runs (the pairs of boxes whose inflated
/// intervals overlap along it, counted over every pair) are shorter, on worlds ten times as
/// wide as tall and ten times as tall as wide.
#[test]
fn the_sweep_runs_along_the_axis_with_the_shorter_runs() {
    let mut next = uniform(0x2545_f491_4f6c_dd1d);
    let half = 0.5 * DEFAULT_DELTA_PROX;
    for trial in 0..40 {
        let (w, h) = if trial % 2 == 0 {
            (3.0, 0.3)
        } else {
            (0.3, 3.0)
        };
        let cols: Vec<_> = world(&mut next, 200, w, h, trial % 4 >= 2)
            .into_iter()
            .map(|(c, _)| c)
            .collect();
        let boxes: Vec<Aabb> = cols.iter().map(|c| c.aabb.inflated(half)).collect();
        let (mut run_x, mut run_y) = (0, 0);
        for (a, p) in boxes.iter().enumerate() {
            for q in &boxes[a + 1..] {
                run_x += usize::from(p.min.x <= q.max.x && q.min.x <= p.max.x);
                run_y += usize::from(p.min.y <= q.max.y && q.min.y <= p.max.y);
            }
        }
        let shorter = if run_y < run_x { Axis::Y } else { Axis::X };
        assert_eq!(
            sweep_axis(&cols, half),
            shorter,
            "trial {trial}: {run_x} {run_y}"
        );
        let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        bp.update(&cols, &mut Vec::new());
        assert_eq!(bp.axis, shorter, "trial {trial}");
    }
}
