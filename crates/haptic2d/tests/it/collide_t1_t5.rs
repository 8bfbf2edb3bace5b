//! Checkable behaviour of the collision detection, spec §9.6 (T1–T5).

use crate::polygon_support;
use crate::ve_support;
use haptic2d::collide::{
    gjk_distance, required_delta_prox, BroadPhase, Collider, Feature, FeatureTracker, GjkCache,
    LocalStage, TrackStatus, VeCandidate, DEFAULT_DELTA_C, DEFAULT_DELTA_PROX,
};
use haptic2d::geom::{ConvexPolygon, Pose, Vec2};
use polygon_support::random_polygon;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{PI, TAU};
use ve_support::ve;

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// Distance from point `p` to segment `[a, b]` (m).
fn point_segment(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let e = b - a;
    let t = ((p - a).dot(e) / e.length_squared()).clamp(0.0, 1.0);
    (p - (a + e * t)).length()
}

/// True if `p` is inside or on the CCW convex polygon `v` (within `tol` m).
fn inside(v: &[Vec2], p: Vec2, tol: f64) -> bool {
    let n = v.len();
    (0..n).all(|i| {
        let e = v[(i + 1) % n] - v[i];
        let nrm = Vec2::new(e.y, -e.x) / e.length();
        nrm.dot(p - v[i]) <= tol
    })
}

/// Distance from `p` to the convex polygon `v` (0 inside), by brute force.
fn point_polygon(v: &[Vec2], p: Vec2) -> f64 {
    if inside(v, p, 0.0) {
        return 0.0;
    }
    let n = v.len();
    (0..n)
        .map(|i| point_segment(p, v[i], v[(i + 1) % n]))
        .fold(f64::INFINITY, f64::min)
}

/// True if edge normals of `a` separate `b` (SAT half-test).
fn separated_by_edges_of(a: &[Vec2], b: &[Vec2]) -> bool {
    let n = a.len();
    (0..n).any(|i| {
        let e = a[(i + 1) % n] - a[i];
        let nrm = Vec2::new(e.y, -e.x);
        b.iter().all(|q| nrm.dot(*q - a[i]) > 0.0)
    })
}

/// Brute-force distance between two convex polygons: 0 if the separating-axis test finds no
/// separating edge normal, else the minimum over all vertex–edge pairs.
fn brute_distance(a: &[Vec2], b: &[Vec2]) -> f64 {
    if !separated_by_edges_of(a, b) && !separated_by_edges_of(b, a) {
        return 0.0;
    }
    let mut d = f64::INFINITY;
    for (p, q) in [(a, b), (b, a)] {
        let m = q.len();
        for v in p {
            for j in 0..m {
                d = d.min(point_segment(*v, q[j], q[(j + 1) % m]));
            }
        }
    }
    d
}

/// Parry's distance between two colliders (test oracle).
fn parry_distance(a: &Collider, pa: &Pose, b: &Collider, pb: &Pose) -> f64 {
    parry2d_f64::query::distance(
        &pa.to_parry(),
        &a.local.to_parry(),
        &pb.to_parry(),
        &b.local.to_parry(),
    )
    .expect("polygon–polygon distance is supported")
    .distance
}

/// True if world point `p` lies on feature `f` of collider `c` (within `tol` m).
fn on_feature(c: &Collider, f: Feature, p: Vec2, tol: f64) -> bool {
    match f {
        Feature::Vertex(i) => (c.world_vertices()[i as usize] - p).length() <= tol,
        Feature::Edge(i) => {
            let a = c.world_vertices()[i as usize];
            let b = c.world_vertices()[c.local.next(i as usize)];
            point_segment(p, a, b) <= tol
        }
    }
}

fn random_pose(rng: &mut ChaCha8Rng, extent: f64) -> Pose {
    Pose::new(
        rng.random_range(-extent..extent),
        rng.random_range(-extent..extent),
        rng.random_range(-PI..PI),
    )
}

fn unit(angle: f64) -> Vec2 {
    Vec2::new(angle.cos(), angle.sin())
}

// ---------------------------------------------------------------------------------------------
// T1
// ---------------------------------------------------------------------------------------------

/// T1: GJK distance between two random convex polygons matches brute force (and parry) to 1e-9 m
/// for 10⁴ random cases, separated and overlapping; overlap returns 0. Each case is run cold and
/// warm-started from the previous (unrelated) case's cache, which must not matter.
#[test]
fn t1_gjk_matches_brute_force() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x7131);
    let mut warm = GjkCache::new();
    let (mut n_sep, mut n_overlap) = (0, 0);
    let mut worst_brute: f64 = 0.0;
    let mut worst_parry: f64 = 0.0;
    for case in 0..10_000 {
        let pa = random_polygon(&mut rng, 0.01, 0.05);
        let pb = random_polygon(&mut rng, 0.01, 0.05);
        let pose_a = random_pose(&mut rng, 0.1);
        // B around A, from deep overlap to well apart.
        let reach = pa.radius() + pb.radius();
        let dir = unit(rng.random_range(0.0..TAU));
        let pos_b = pose_a.pos + dir * (reach * rng.random_range(0.2..1.4));
        let pose_b = Pose {
            pos: pos_b,
            angle: rng.random_range(-PI..PI),
        };
        let a = Collider::new(0, true, pa, &pose_a);
        let b = Collider::new(1, true, pb, &pose_b);

        let brute = brute_distance(a.world_vertices(), b.world_vertices());
        let cold = gjk_distance(a.world_vertices(), b.world_vertices(), &mut GjkCache::new());
        let hot = gjk_distance(a.world_vertices(), b.world_vertices(), &mut warm);
        let parry = parry_distance(&a, &pose_a, &b, &pose_b);

        for g in [&cold, &hot] {
            let err = (g.distance - brute).abs();
            worst_brute = worst_brute.max(err);
            assert!(
                err <= 1e-9,
                "case {case}: GJK {} vs brute force {brute}",
                g.distance
            );
            if brute == 0.0 {
                // Overlap returns 0 (or a touching distance within ε_abs, which the SAT calls overlap).
                assert!(
                    g.overlap || g.distance <= 1e-9,
                    "case {case}: overlap not found"
                );
            } else {
                // Witness points realise the distance and lie on the polygons.
                assert!(((g.point_a - g.point_b).length() - g.distance).abs() <= 1e-12);
                assert!(point_polygon(a.world_vertices(), g.point_a) <= 1e-12);
                assert!(point_polygon(b.world_vertices(), g.point_b) <= 1e-12);
            }
        }
        let err_parry = (cold.distance - parry).abs();
        worst_parry = worst_parry.max(err_parry);
        assert!(
            err_parry <= 1e-9,
            "case {case}: GJK {} vs parry {parry}",
            cold.distance
        );
        if brute == 0.0 {
            n_overlap += 1;
        } else {
            n_sep += 1;
        }
    }
    println!(
        "T1: {n_sep} separated, {n_overlap} overlapping; worst |GJK − brute| = {worst_brute:.2e} m, \
         worst |GJK − parry| = {worst_parry:.2e} m"
    );
    assert!(
        n_sep > 2_000 && n_overlap > 2_000,
        "both kinds of case must be well represented"
    );
}

// ---------------------------------------------------------------------------------------------
// T2
// ---------------------------------------------------------------------------------------------

/// T2: Lin–Canny returns the same distance as GJK to 1e-9 m, with a feature pair whose closest
/// points realise it, over 1000-step trajectories with rotations ≤ 0.05 rad/step (both bodies).
/// When GJK finds overlap the tracker must report penetration, and vice versa.
#[test]
fn t2_tracker_matches_gjk() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x7232);
    let (mut steps, mut penetrating, mut fallbacks) = (0u64, 0u64, 0u64);
    for traj in 0..10 {
        let pa = random_polygon(&mut rng, 0.01, 0.05);
        let pb = random_polygon(&mut rng, 0.01, 0.05);
        let reach = pa.radius() + pb.radius();
        let w_a = rng.random_range(-0.05..0.05);
        let w_b = rng.random_range(-0.05..0.05);
        let orbit = rng.random_range(-0.02..0.02);
        let (th_a0, th_b0, phi0) = (
            rng.random_range(0.0..TAU),
            rng.random_range(0.0..TAU),
            rng.random_range(0.0..TAU),
        );
        let pose = |k: f64| {
            // Centre distance sweeps from 0.75·reach (usually overlapping) to 1.35·reach (apart).
            let rho = reach * (1.05 + 0.3 * (0.011 * k).sin());
            let pos_b = unit(phi0 + orbit * k) * rho;
            (
                Pose::new(0.0, 0.0, th_a0 + w_a * k),
                Pose {
                    pos: pos_b,
                    angle: th_b0 + w_b * k,
                },
            )
        };
        let (p0a, p0b) = pose(0.0);
        let mut a = Collider::new(0, true, pa, &p0a);
        let mut b = Collider::new(1, true, pb, &p0b);
        let mut tracker = FeatureTracker::new();
        let mut cache = GjkCache::new();
        for k in 0..1000 {
            let (qa, qb) = pose(k as f64);
            a.update(&qa);
            b.update(&qb);
            let g = gjk_distance(a.world_vertices(), b.world_vertices(), &mut cache);
            let t = tracker.update(&a, &b);
            steps += 1;
            let ctx = format!("trajectory {traj}, step {k}: GJK {g:?}, tracker {t:?}");
            if g.overlap || g.distance <= 1e-9 {
                assert!(
                    t.status == TrackStatus::Penetrating || t.distance <= 1e-9,
                    "{ctx}"
                );
            }
            match t.status {
                TrackStatus::Penetrating => {
                    penetrating += 1;
                    assert!(g.overlap || g.distance <= 1e-9, "{ctx}");
                }
                TrackStatus::Separated => {
                    assert!((t.distance - g.distance).abs() <= 1e-9, "{ctx}");
                    assert!(((t.point_a - t.point_b).length() - t.distance).abs() <= 1e-15);
                    assert!(on_feature(&a, t.feature_a, t.point_a, 1e-12), "{ctx}");
                    assert!(on_feature(&b, t.feature_b, t.point_b, 1e-12), "{ctx}");
                }
            }
        }
        fallbacks += tracker.stats.gjk_fallbacks;
    }
    println!("T2: {steps} steps, {penetrating} penetrating, {fallbacks} GJK fallbacks");
    assert!(penetrating > 0 && penetrating < steps / 2);
}

// ---------------------------------------------------------------------------------------------
// T3
// ---------------------------------------------------------------------------------------------

/// T3: under coherent motion (translation ≤ 1 mm and rotation ≤ 0.01 rad per step) the mean number
/// of feature-walk iterations is ≤ 2, and the hill-climbing support uses ≤ 3 evaluations on
/// average (one evaluation = one dot product comparing two adjacent vertices along `d`).
#[test]
fn t3_coherent_motion_is_o1() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x7333);
    let (mut updates, mut iterations, mut fallbacks) = (0u64, 0u64, 0u64);
    let (mut support_calls, mut support_evals, mut gjk_iters, mut gjk_calls) = (0u64, 0, 0, 0);
    for _ in 0..20 {
        let pa = random_polygon(&mut rng, 0.01, 0.05);
        let pb = random_polygon(&mut rng, 0.01, 0.05);
        let reach = pa.radius() + pb.radius();
        // B orbits A at a centre distance between reach and reach + 2 cm (never overlapping), with a
        // tangential speed ≤ 0.7 mm/step, a radial speed ≤ 0.2 mm/step and a spin ≤ 0.01 rad/step.
        let rho_mid = reach + 0.01;
        let orbit = 0.0007 / (rho_mid + 0.01) * if rng.random::<bool>() { 1.0 } else { -1.0 };
        let spin = rng.random_range(-0.01..0.01);
        let (th0, phi0) = (rng.random_range(0.0..TAU), rng.random_range(0.0..TAU));
        let pose_b = |k: f64| Pose {
            pos: unit(phi0 + orbit * k) * (rho_mid + 0.01 * (0.02 * k).sin()),
            angle: th0 + spin * k,
        };
        let a = Collider::new(0, false, pa, &Pose::IDENTITY);
        let mut b = Collider::new(1, true, pb, &pose_b(0.0));
        let mut tracker = FeatureTracker::new();
        let mut cache = GjkCache::new();
        tracker.update(&a, &b); // initialisation (GJK), not counted
        gjk_distance(a.world_vertices(), b.world_vertices(), &mut cache);
        let t0 = tracker.stats;
        let mut prev = pose_b(0.0);
        for k in 1..1000 {
            let q = pose_b(k as f64);
            assert!((q.pos - prev.pos).length() <= 1e-3 && (q.angle - prev.angle).abs() <= 0.01);
            prev = q;
            b.update(&q);
            tracker.update(&a, &b);
            let g = gjk_distance(a.world_vertices(), b.world_vertices(), &mut cache);
            support_calls += 2 * g.iterations as u64;
            support_evals += g.support_evals as u64;
            gjk_iters += g.iterations as u64;
            gjk_calls += 1;
        }
        updates += tracker.stats.updates - t0.updates;
        iterations += tracker.stats.iterations - t0.iterations;
        fallbacks += tracker.stats.gjk_fallbacks - t0.gjk_fallbacks;
    }
    let mean_iter = iterations as f64 / updates as f64;
    let mean_evals = support_evals as f64 / support_calls as f64;
    println!(
        "T3: mean feature-walk iterations {mean_iter:.3} ({fallbacks} GJK fallbacks); \
         mean support evaluations {mean_evals:.3} per support call ({:.3} distinct vertices read); \
         warm GJK {:.3} iterations per call",
        mean_evals + 1.0,
        gjk_iters as f64 / gjk_calls as f64
    );
    assert!(mean_iter <= 2.0, "mean iterations {mean_iter}");
    assert!(mean_evals <= 3.0, "mean support evaluations {mean_evals}");
    assert_eq!(fallbacks, 0);
}

// ---------------------------------------------------------------------------------------------
// T4
// ---------------------------------------------------------------------------------------------

/// Runs the broad phase and a fresh local stage on `cols` and returns the VE candidates.
fn candidates(cols: &[Collider]) -> Vec<VeCandidate> {
    let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let mut pairs = Vec::new();
    bp.update(cols, &mut pairs);
    let mut local = LocalStage::new();
    let mut out = Vec::new();
    local.update(cols, &pairs, DEFAULT_DELTA_C, &mut out);
    out
}

/// T4: a rectangle resting flat on a wall face yields exactly 2 VE contacts (edge–edge case), and a
/// square touching another square corner-to-corner yields 2 (vertex–vertex case).
#[test]
fn t4_edge_edge_and_vertex_vertex_give_two_contacts() {
    // (a) Box 4 cm × 2 cm on the top face (edge 2) of a fixed wall slab; the box's bottom corners
    // are its vertices 0 and 1. Gaps from 1.5 mm (within δ_c) to 1 mm of penetration, exactly flat
    // and tilted by round-off-sized and small angles (both corners within δ_c), and through a
    // continuous approach with the same local stage.
    let wall = ConvexPolygon::rectangle(0.4, 0.02).unwrap();
    let boxp = ConvexPolygon::rectangle(0.04, 0.02).unwrap();
    let expected = vec![ve(1, 0, 0, 2), ve(1, 1, 0, 2)];
    for &x in &[0.0, 0.07, -0.13] {
        for &tilt in &[0.0, 1e-12, -1e-9, 1e-5, -3e-5] {
            for &gap in &[0.0015, 0.001, 1e-7, 0.0, -1e-7, -0.0005, -0.001] {
                let cols = [
                    Collider::new(0, false, wall.clone(), &Pose::new(0.0, -0.01, 0.0)),
                    Collider::new(1, true, boxp.clone(), &Pose::new(x, 0.01 + gap, tilt)),
                ];
                let got = candidates(&cols);
                assert_eq!(got, expected, "box at x={x}, tilt={tilt}, gap={gap}");
            }
        }
    }
    // Continuous approach from 3 mm to 1 mm penetration: 0 candidates beyond δ_c, then exactly 2.
    let mut cols = [
        Collider::new(0, false, wall.clone(), &Pose::new(0.0, -0.01, 0.0)),
        Collider::new(1, true, boxp.clone(), &Pose::new(0.02, 0.013, 2e-6)),
    ];
    let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let mut pairs = Vec::new();
    bp.update(&cols, &mut pairs);
    let mut local = LocalStage::new();
    let mut out = Vec::new();
    for k in 0..=400 {
        let gap = 0.003 - 1e-5 * k as f64;
        cols[1].update(&Pose::new(0.02, 0.01 + gap, 2e-6));
        local.update(&cols, &pairs, DEFAULT_DELTA_C, &mut out);
        // The corners are ±4e-8 m from `gap` (tilt 2e-6 rad): within 1e-7 m of δ_c one corner may be
        // inside δ_c and the other not, so those samples are not checked.
        if gap > DEFAULT_DELTA_C + 1e-7 {
            assert!(out.is_empty(), "gap {gap}: {out:?}");
        } else if gap < DEFAULT_DELTA_C - 1e-7 {
            assert_eq!(out, expected, "gap {gap}");
        }
    }

    // (b) Box on a smaller box, overhanging its corner: the overlap interval ends at a corner of the
    // upper box (on the lower box's top edge 2) and at a corner of the lower box (on the upper
    // box's bottom edge 0).
    let small = ConvexPolygon::rectangle(0.03, 0.03).unwrap();
    for &gap in &[0.001, 0.0, -0.0008] {
        let cols = [
            Collider::new(0, true, small.clone(), &Pose::new(0.0, 0.0, 0.0)),
            Collider::new(1, true, boxp.clone(), &Pose::new(0.025, 0.025 + gap, 0.0)),
        ];
        // Upper box's bottom-left corner (vertex 0, x = 0.005) on the lower box's top edge, and the
        // lower box's top-right corner (vertex 2, x = 0.015) on the upper box's bottom edge.
        assert_eq!(
            candidates(&cols),
            vec![ve(0, 2, 1, 0), ve(1, 0, 0, 2)],
            "gap {gap}"
        );
    }

    // (c) Squares corner-to-corner: B's vertex 0 near A's vertex 2 along the diagonal, touching
    // (gap 0 or below ε_s) or penetrating by 0.5 mm, B also turned about its corner.
    let sq = ConvexPolygon::rectangle(0.04, 0.04).unwrap();
    let diag = Vec2::new(1.0, 1.0).normalize();
    for &alpha in &[0.0, 0.2, -0.3] {
        for &gap in &[0.0, 1e-6, 5e-5, -0.0005] {
            let corner_b = Vec2::new(0.02, 0.02) + diag * gap;
            // Pose of B such that its vertex 0 (local (−0.02, −0.02)) lands on corner_b.
            let rot = haptic2d::geom::Rot::new(alpha);
            let pose_b = Pose {
                pos: corner_b - rot.apply(Vec2::new(-0.02, -0.02)),
                angle: alpha,
            };
            let cols = [
                Collider::new(0, true, sq.clone(), &Pose::IDENTITY),
                Collider::new(1, true, sq.clone(), &pose_b),
            ];
            let got = candidates(&cols);
            assert_eq!(got.len(), 2, "alpha {alpha}, gap {gap}: {got:?}");
            assert_eq!(
                (got[0].vertex_collider, got[0].vertex),
                (0, 2),
                "alpha {alpha}, gap {gap}: {got:?}"
            );
            assert_eq!(
                (got[1].vertex_collider, got[1].vertex),
                (1, 0),
                "alpha {alpha}, gap {gap}: {got:?}"
            );
            // Each candidate's edge is incident to the other square's touching corner.
            assert!([0, 3].contains(&got[0].edge), "{got:?}");
            assert!([1, 2].contains(&got[1].edge), "{got:?}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// T5
// ---------------------------------------------------------------------------------------------

/// Result of one T5 trial: proximate at the global update, and the smallest distance (m) over the
/// following `2·N_g` samples (the update's own period plus one period of consumption latency).
struct Trial {
    proximate: bool,
    min_gap_ng: f64,
    min_gap_2ng: f64,
    start_gap: f64,
}

fn t5_trial(rng: &mut ChaCha8Rng, bp: &mut BroadPhase, pairs: &mut Vec<(u32, u32)>) -> Trial {
    const T: f64 = 0.002;
    const N_G: usize = 10;
    const V_REL_MAX: f64 = 1.0;
    let pa = random_polygon(rng, 0.01, 0.05);
    let pb = random_polygon(rng, 0.01, 0.05);
    let pose_a = random_pose(rng, 0.1);
    let a = Collider::new(0, false, pa, &pose_a);
    let rb = pb.radius();
    let th_b = rng.random_range(-PI..PI);
    let dir = unit(rng.random_range(0.0..TAU));
    // Start gap uniform in [0, 0.08] m, placed by bisection along `dir` (the distance of two convex
    // sets is convex in a translation, hence increasing along the ray once they are apart).
    let start_gap = rng.random_range(0.0..0.08);
    let mut b = Collider::new(1, true, pb, &Pose::IDENTITY);
    let mut cache = GjkCache::new();
    let mut gap_at = |s: f64, b: &mut Collider| {
        b.update(&Pose {
            pos: pose_a.pos + dir * s,
            angle: th_b,
        });
        gjk_distance(a.world_vertices(), b.world_vertices(), &mut cache).distance
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if gap_at(mid, &mut b) < start_gap {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let c0 = pose_a.pos + dir * hi;
    // Motion at v_rel,max: every point of B moves at ≤ |v| + |ω|·r_B = 1 m/s, roughly towards A.
    let omega = rng.random_range(-0.5..0.5) * V_REL_MAX / rb;
    let speed = V_REL_MAX - omega.abs() * rb;
    let v = unit(dir.y.atan2(dir.x) + PI + rng.random_range(-0.5..0.5)) * speed;
    let pose_b = |k: usize| Pose {
        pos: c0 + v * (k as f64 * T),
        angle: th_b + omega * (k as f64 * T),
    };
    // Global update at sample 0.
    b.update(&pose_b(0));
    let cols = [a, b];
    bp.update(&cols, pairs);
    let proximate = pairs.contains(&(0, 1));
    let [a, mut b] = cols;
    let (mut min_ng, mut min_2ng) = (f64::INFINITY, f64::INFINITY);
    let mut cache = GjkCache::new();
    for k in 1..=2 * N_G {
        b.update(&pose_b(k));
        let d = gjk_distance(a.world_vertices(), b.world_vertices(), &mut cache).distance;
        if k <= N_G {
            min_ng = min_ng.min(d);
        }
        min_2ng = min_2ng.min(d);
    }
    Trial {
        proximate,
        min_gap_ng: min_ng,
        min_gap_2ng: min_2ng,
        start_gap,
    }
}

/// T5: with bodies at v_rel,max = 1 m/s and a global update every N_g = 10 samples (T = 2 ms), a
/// pair that is not proximate at a global update never penetrates before the next one (10⁴ random
/// trials). With the default margin it even stays farther than δ_c for two global periods. The
/// same trials with a too-small δ_prox do miss collisions, so the test has teeth.
#[test]
fn t5_no_missed_collision() {
    let delta_prox = required_delta_prox(1.0, 0.02, DEFAULT_DELTA_C);
    assert!((delta_prox - DEFAULT_DELTA_PROX).abs() < 1e-15);
    let mut pairs = Vec::new();

    let mut rng = ChaCha8Rng::seed_from_u64(0x7535);
    let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let (mut not_proximate, mut closest_not_proximate) = (0, f64::INFINITY);
    for trial in 0..10_000 {
        let t = t5_trial(&mut rng, &mut bp, &mut pairs);
        // The proximity decision agrees with the distance the pair was placed at.
        if t.start_gap < DEFAULT_DELTA_PROX - 1e-9 {
            assert!(
                t.proximate,
                "trial {trial}: gap {} not proximate",
                t.start_gap
            );
        } else if t.start_gap > DEFAULT_DELTA_PROX + 1e-9 {
            assert!(!t.proximate, "trial {trial}: gap {} proximate", t.start_gap);
        }
        if !t.proximate {
            not_proximate += 1;
            closest_not_proximate = closest_not_proximate.min(t.min_gap_2ng);
            assert!(
                t.min_gap_ng > 0.0,
                "trial {trial}: missed collision within N_g samples"
            );
            assert!(
                t.min_gap_2ng > DEFAULT_DELTA_C,
                "trial {trial}: non-proximate pair came within δ_c ({}) within 2·N_g samples",
                t.min_gap_2ng
            );
        }
    }
    println!(
        "T5: {not_proximate} non-proximate trials, closest approach among them {closest_not_proximate:.5} m"
    );
    assert!(not_proximate > 3_000);

    // Teeth: δ_prox = 1 cm misses penetrations within N_g samples.
    let mut rng = ChaCha8Rng::seed_from_u64(0x7535);
    let mut bp = BroadPhase::new(0.01).unwrap();
    let missed = (0..10_000)
        .filter(|_| {
            let t = t5_trial(&mut rng, &mut bp, &mut pairs);
            !t.proximate && t.min_gap_ng <= 0.0
        })
        .count();
    println!("T5 (δ_prox = 0.01 m): {missed} missed collisions");
    assert!(missed > 0);
}

// ---------------------------------------------------------------------------------------------
// Local-stage invariants (random scenes)
// ---------------------------------------------------------------------------------------------

/// On random pairs from overlap to apart, every VE candidate is valid (edge coordinate within
/// `[−ε_s, L+ε_s]`, `d ≤ δ_c`), each vertex appears at most once, and every vertex inside the other
/// polygon is proposed (so the contact manager never misses a penetrating vertex).
#[test]
fn local_stage_candidate_invariants() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x10ca1);
    let mut local = LocalStage::new();
    let mut out = Vec::new();
    let eps_s = local.edge_tolerance();
    let (mut with_candidates, mut inside_vertices) = (0, 0);
    for case in 0..3000 {
        let pa = random_polygon(&mut rng, 0.01, 0.05);
        let pb = random_polygon(&mut rng, 0.01, 0.05);
        let pose_a = random_pose(&mut rng, 0.1);
        let reach = pa.radius() + pb.radius();
        let dir = unit(rng.random_range(0.0..TAU));
        let pose_b = Pose {
            pos: pose_a.pos + dir * (reach * rng.random_range(0.5..1.1)),
            angle: rng.random_range(-PI..PI),
        };
        let cols = [
            Collider::new(0, false, pa, &pose_a),
            Collider::new(1, true, pb, &pose_b),
        ];
        local.update(&cols, &[(0, 1)], DEFAULT_DELTA_C, &mut out);
        with_candidates += !out.is_empty() as usize;
        for w in out.windows(2) {
            assert!(
                (w[0].vertex_collider, w[0].vertex) != (w[1].vertex_collider, w[1].vertex),
                "case {case}: vertex proposed twice: {out:?}"
            );
        }
        for c in &out {
            let (cv, ce) = (
                &cols[c.vertex_collider as usize],
                &cols[c.edge_collider as usize],
            );
            let p = cv.world_vertices()[c.vertex as usize];
            let e = c.edge as usize;
            let s = ce.edge_coordinate(e, p);
            assert!(
                s >= -eps_s && s <= ce.local.lengths()[e] + eps_s,
                "case {case}: {c:?}"
            );
            assert!(
                ce.edge_distance(e, p) <= DEFAULT_DELTA_C,
                "case {case}: {c:?}"
            );
        }
        for (iv, ie) in [(0usize, 1usize), (1, 0)] {
            for (v, p) in cols[iv].world_vertices().iter().enumerate() {
                if inside(cols[ie].world_vertices(), *p, -1e-12) {
                    inside_vertices += 1;
                    assert!(
                        out.iter()
                            .any(|c| c.vertex_collider == iv as u32 && c.vertex == v as u32),
                        "case {case}: vertex {v} of collider {iv} is inside but not proposed"
                    );
                }
            }
        }
    }
    println!("local invariants: {with_candidates} cases with candidates, {inside_vertices} inside vertices");
    assert!(with_candidates > 500 && inside_vertices > 500);
}
