//! The local stage's reused vertex scans (issue 17, `collide/reuse.rs`): a penetrating pair whose
//! bodies have not moved enough to change any comparison of its scan keeps its candidates
//! without scanning (its bodies' motion relative to each other: a common drift does not count).
//! Checked against a local stage that tracks and scans every pair every sample.

use crate::polygon_support;
use haptic2d::collide::{nearest_line, Collider, LocalStage, DEFAULT_DELTA_C};
use haptic2d::geom::{ConvexPolygon, Pose, Vec2};
use polygon_support::random_polygon;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// A motion of size drawn log-uniformly in `[1e-9, 10^top]` (m or rad).
fn small(rng: &mut ChaCha8Rng, top: f64) -> f64 {
    let s = 10f64.powf(rng.random_range(-9.0..top));
    if rng.random::<bool>() {
        s
    } else {
        -s
    }
}

#[test]
fn reused_vertex_scans_give_the_candidates_of_scanning_every_sample() {
    let mut reused_total = 0usize;
    let mut scanned_total = 0usize;
    let mut flagged_total = 0usize;
    for seed in 0..12u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // A row of overlapping polygons (each overlaps its neighbours by up to a few mm), one of
        // them fixed, plus every pair as proximate.
        let n = 6;
        let shapes: Vec<ConvexPolygon> = (0..n)
            .map(|_| random_polygon(&mut rng, 0.02, 0.05))
            .collect();
        let radius: Vec<f64> = shapes.iter().map(ConvexPolygon::radius).collect();
        let mut x = 0.0;
        let home: Vec<Pose> = (0..n)
            .map(|i| {
                if i > 0 {
                    x += 0.8 * (radius[i - 1] + radius[i]) - rng.random_range(0.0..0.004);
                }
                Pose::new(x, rng.random_range(-0.01..0.01), rng.random_range(0.0..TAU))
            })
            .collect();
        let mut colliders: Vec<Collider> = (0..n)
            .map(|i| Collider::new(i, i != 0, shapes[i].clone(), &home[i]))
            .collect();
        let pairs: Vec<(u32, u32)> = (0..n as u32)
            .flat_map(|a| (a + 1..n as u32).map(move |b| (a, b)))
            .collect();
        let mut poses = home.clone();
        // Every body, the fixed one too, also drifts with the whole group (a pile sinking as a
        // whole): 0.1 mm per sample, which alone would exhaust any absolute-motion bound.
        let mut drift = Vec2::ZERO;
        let mut world = home.clone();
        let (mut fast, mut every) = (LocalStage::new(), LocalStage::new());
        let (mut out_fast, mut out_every) = (Vec::new(), Vec::new());
        for k in 0..3000 {
            // Most samples creep (down to 1 nm), many jump (up to 1 mm or 10 mrad), some rest;
            // every body stays within 3 mm and 0.05 rad of home (relative to the drift).
            drift += Vec2::new(3e-5, -1e-4);
            for i in 1..n {
                let top = match rng.random_range(0..10) {
                    0..=2 => -3.0,
                    3 => -20.0, // at rest (below 1e-9 the motion is nil in practice)
                    _ => -5.0,
                };
                if top < -10.0 {
                    continue;
                }
                let last = poses[i];
                let mut p = Pose::new(
                    last.pos.x + small(&mut rng, top),
                    last.pos.y + small(&mut rng, top),
                    last.angle + small(&mut rng, top - 1.0) / radius[i],
                );
                p.pos = home[i].pos + (p.pos - home[i].pos).clamp_length_max(0.003);
                p.angle = home[i].angle + (p.angle - home[i].angle).clamp(-0.05, 0.05);
                poses[i] = p;
            }
            for i in 0..n {
                world[i] = Pose::new(
                    poses[i].pos.x + drift.x,
                    poses[i].pos.y + drift.y,
                    poses[i].angle,
                );
                colliders[i].update(&world[i]);
            }
            fast.update_with_motion(&colliders, &pairs, DEFAULT_DELTA_C, &world, &mut out_fast);
            every.update(&colliders, &pairs, DEFAULT_DELTA_C, &mut out_every);
            assert_eq!(out_fast, out_every, "seed {seed}, sample {k}");
            // A vertex-scan candidate's edge passes the contact manager's hand-over check
            // exactly (`d_e ≥ max_j d_j − δ_c` from the same world features), which is why its
            // record skips that check.
            let flags = fast.from_vertex_scan();
            assert_eq!(flags.len(), out_fast.len());
            assert_eq!(flags, every.from_vertex_scan(), "seed {seed}, sample {k}");
            for (c, _) in out_fast.iter().zip(flags).filter(|(_, &f)| f) {
                let v = colliders[c.vertex_collider as usize].world_vertices()[c.vertex as usize];
                let b = &colliders[c.edge_collider as usize];
                let d_e = b.edge_distance(c.edge as usize, v);
                assert!(
                    d_e >= nearest_line(b, v).1 - DEFAULT_DELTA_C,
                    "seed {seed}, sample {k}"
                );
                flagged_total += 1;
            }
            reused_total += fast.reused();
            scanned_total += pairs.len() - fast.reused() - fast.skipped();
        }
    }
    // The suite exercises both paths: scans reused, and scans redone once the motion used up the
    // slack (or on the samples a pair was not reusable).
    assert!(reused_total > 20_000, "reused {reused_total}");
    assert!(flagged_total > 20_000, "flagged {flagged_total}");
    assert!(scanned_total > 20_000, "scanned {scanned_total}");
}

/// A change of `δ_c` between samples drops every reused scan: the candidates are those of the
/// new tolerance at once.
#[test]
fn a_changed_contact_tolerance_drops_the_reused_scans() {
    let square = ConvexPolygon::rectangle(0.05, 0.05).unwrap();
    // B's bottom corner 1 mm into A's top face, off-centre; the pair is penetrating.
    let poses = [Pose::new(0.0, 0.0, 0.0), Pose::new(0.011, 0.049, 0.3)];
    let colliders: Vec<Collider> = (0..2)
        .map(|i| Collider::new(i, i == 1, square.clone(), &poses[i]))
        .collect();
    let pairs = [(0u32, 1u32)];
    let (mut fast, mut every) = (LocalStage::new(), LocalStage::new());
    let (mut out_fast, mut out_every) = (Vec::new(), Vec::new());
    for (k, delta_c) in [2e-3, 2e-3, 2e-3, 2e-3, 0.04, 0.04, 2e-3]
        .into_iter()
        .enumerate()
    {
        fast.update_with_motion(&colliders, &pairs, delta_c, &poses, &mut out_fast);
        every.update(&colliders, &pairs, delta_c, &mut out_every);
        assert_eq!(out_fast, out_every, "sample {k}");
        if k == 3 {
            assert_eq!(fast.reused(), 1, "a still pair is reused");
        }
        if k == 4 {
            assert_eq!(fast.reused(), 0, "δ_c changed: scanned again");
        }
    }
}
