//! The partial global update (issue 42, `collide/broad/partial.rs`): a body that moved past the
//! margin gets its pairs decided again alone. Checked against brute force, sample by sample:
//! every collider pair closer than `δ_c` at the poses the local stage sees is in the proximity
//! set (parry's distance, not ours), and the local stage's VE candidates are those of a local
//! stage that tracks every collider pair.

use crate::polygon_support::random_polygon;
use haptic2d::body::Body;
use haptic2d::collide::{LocalStage, VeCandidate};
use haptic2d::geom::{ConvexPolygon, Pose, Vec2};
use haptic2d::scene::builtin;
use haptic2d::world::World;
use parry2d_f64::math::Pose as ParryPose;
use parry2d_f64::shape::ConvexPolygon as ParryPolygon;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// Each collider's polygon in parry's form, at its body's pose (parry is the distance oracle).
fn parry_colliders(w: &World) -> Vec<(ParryPose, ParryPolygon)> {
    w.colliders
        .iter()
        .map(|c| (w.bodies[c.body].pose.to_parry(), c.local.to_parry()))
        .collect()
}

/// Every collider pair of two bodies, not both fixed (what the global stage may report).
fn all_pairs(w: &World) -> Vec<(u32, u32)> {
    let c = &w.colliders;
    let mut out = Vec::new();
    for i in 0..c.len() {
        for j in i + 1..c.len() {
            if c[i].body != c[j].body && (c[i].dynamic || c[j].dynamic) {
                out.push((i as u32, j as u32));
            }
        }
    }
    out
}

/// Checks the margin rule at the poses of the sample just begun: every pair of `pairs` closer
/// than `δ_c` (parry) is in the proximity set. Returns how many such pairs there were.
fn assert_margin_rule(w: &World, pairs: &[(u32, u32)], what: &str) -> usize {
    let delta_c = w.params.delta_c;
    let set = w.proximate_pairs();
    let shapes = parry_colliders(w);
    let mut close = 0;
    for &(a, b) in pairs {
        let (ca, cb) = (&w.colliders[a as usize], &w.colliders[b as usize]);
        // The boxes' gap is a lower bound on the distance: most pairs need no parry.
        let (p, q) = (&ca.aabb, &cb.aabb);
        let gap = (q.min.x - p.max.x)
            .max(p.min.x - q.max.x)
            .max(q.min.y - p.max.y)
            .max(p.min.y - q.max.y);
        if gap >= delta_c {
            continue;
        }
        let ((pa, sa), (pb, sb)) = (&shapes[a as usize], &shapes[b as usize]);
        let d = parry2d_f64::query::distance(pa, sa, pb, sb).expect("polygons are supported");
        if d.distance >= delta_c {
            continue;
        }
        close += 1;
        assert!(
            set.binary_search(&(a, b)).is_ok(),
            "{what}, tick {}: pair {a}-{b} within δ_c is not in the proximity set",
            w.tick()
        );
    }
    close
}

/// The VE candidates of a local stage that tracks every pair of `pairs`, at the world's poses.
fn brute_candidates(w: &World, pairs: &[(u32, u32)]) -> Vec<VeCandidate> {
    let poses: Vec<Pose> = w.bodies.iter().map(|b| b.pose).collect();
    let mut every = LocalStage::new();
    every.update_known_pairs(&w.colliders, pairs, true, w.params.delta_c, &poses);
    every.candidates().to_vec()
}

/// A box of four fixed walls (inner side `side` m, centred at the origin) holding `n` random
/// polygons on a jittered grid, without gravity: `fast` of them thrown at 2–6 m/s and spun, the
/// rest drifting at up to 0.2 m/s. The laws and parameters are pile:100's at 1 kHz.
fn random_box(seed: u64, n: usize, fast: usize) -> World {
    let template = builtin("pile:100", Some(1000.0)).unwrap().unwrap().world;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let side = 0.8;
    let (h, t) = (0.5 * side, 0.05);
    let mut bodies = Vec::new();
    let mut shapes: Vec<Vec<ConvexPolygon>> = Vec::new();
    for (k, (x, y, hx, hy)) in [
        (0.0, -h - t, h + 2.0 * t, t),
        (0.0, h + t, h + 2.0 * t, t),
        (-h - t, 0.0, t, h),
        (h + t, 0.0, t, h),
    ]
    .into_iter()
    .enumerate()
    {
        bodies.push(Body::fixed(format!("wall{k}"), Pose::new(x, y, 0.0)));
        shapes.push(vec![ConvexPolygon::rectangle(2.0 * hx, 2.0 * hy).unwrap()]);
    }
    let per_row = (n as f64).sqrt().ceil() as usize;
    let cell = side / per_row as f64;
    for i in 0..n {
        let shape = random_polygon(&mut rng, 0.2 * cell, 0.35 * cell);
        let (row, col) = (i / per_row, i % per_row);
        let centre = Vec2::new(
            -h + (col as f64 + 0.5) * cell + rng.random_range(-0.05..0.05) * cell,
            -h + (row as f64 + 0.5) * cell + rng.random_range(-0.05..0.05) * cell,
        );
        let r = shape.radius();
        let mut b = Body::dynamic(
            format!("b{i}"),
            1.0,
            0.5 * r * r,
            Pose::new(centre.x, centre.y, rng.random_range(0.0..TAU)),
        );
        let (speed, spin) = if i < fast {
            (rng.random_range(2.0..6.0), rng.random_range(-20.0..20.0))
        } else {
            (rng.random_range(0.0..0.2), rng.random_range(-1.0..1.0))
        };
        let dir = rng.random_range(0.0..TAU);
        b.vel = Vec2::new(speed * dir.cos(), speed * dir.sin());
        b.omega = spin;
        bodies.push(b);
        shapes.push(vec![shape]);
    }
    World::new(
        bodies,
        shapes,
        Vec::new(),
        template.normal,
        template.friction,
        template.params,
    )
}

/// Random boxes of polygons with a few fast ones: after every sample's global and local stages,
/// every pair within `δ_c` is in the proximity set, and the VE candidates are those of tracking
/// every pair; partial updates ran, and none updated more than one body in 8.
#[test]
fn partial_updates_keep_every_pair_within_delta_c_and_the_brute_force_candidates() {
    let (mut close, mut samples) = (0usize, 0usize);
    for seed in 0..6u64 {
        let mut w = random_box(seed, 64, 4);
        assert!(
            w.speed_warnings().is_empty(),
            "seed {seed}: within the limit"
        );
        let pairs = all_pairs(&w);
        for _ in 0..800 {
            w.begin_step();
            let what = format!("seed {seed}");
            close += assert_margin_rule(&w, &pairs, &what);
            assert_eq!(
                w.local_stage().candidates(),
                &brute_candidates(&w, &pairs)[..],
                "{what}, tick {}: VE candidates",
                w.tick()
            );
            w.finish_step();
            samples += 1;
            assert!(w.divergence().is_none(), "{what}: diverged");
        }
        let (partial, bodies) = w.partial_global_updates();
        println!(
            "seed {seed}: {partial} partial updates of {bodies} bodies, {} whole early updates",
            w.continuous_stats().1
        );
        assert!(partial > 0, "seed {seed}: no partial update ran");
        // At most one body in 8 in a partial update: past that the whole stage runs.
        assert!(
            bodies <= partial * 64 / 8,
            "seed {seed}: {bodies} bodies in {partial} partial updates"
        );
    }
    // The check saw contacts: pairs within δ_c that the set had to hold.
    assert!(close > samples, "{close} close pairs in {samples} samples");
}

/// A body thrown sideways through pile:100 once it has landed is updated alone: partial updates
/// run (no whole early update: one body of 100 moved past), and every pair within `δ_c` stays in
/// the proximity set while it ploughs through.
#[test]
fn a_fast_body_in_a_pile_gets_partial_updates() {
    let mut w = builtin("pile:100", Some(1000.0)).unwrap().unwrap().world;
    for _ in 0..600 {
        w.step();
    }
    let before = w.partial_global_updates().0;
    let pairs = all_pairs(&w);
    let thrown = w.bodies.iter().rposition(|b| b.is_dynamic()).unwrap();
    w.bodies[thrown].vel = Vec2::new(3.0, -1.0);
    let early = w.continuous_stats().1;
    let mut close = 0;
    for _ in 0..150 {
        w.begin_step();
        close += assert_margin_rule(&w, &pairs, "pile:100");
        w.finish_step();
    }
    let (partial, bodies) = w.partial_global_updates();
    assert!(partial > before, "no partial update ran");
    assert!(bodies >= partial, "{bodies} bodies in {partial} updates");
    assert_eq!(w.continuous_stats().1, early, "no whole early update");
    assert!(close > 100, "{close} close pairs");
}
