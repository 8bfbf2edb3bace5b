//! Criterion benchmark `pieces`: the hot pieces of one world step, each on its own.
//!
//! - `tracker/*`: closest-feature tracking of one box pair ([`FeatureTracker::update`]), separated
//!   under coherent motion and penetrating;
//! - `local_stage/pile:N`: the whole local stage ([`LocalStage::update`]: trackers + VE candidates) on
//!   the proximate pairs of a settled `pile:N` (throughput = pairs);
//! - `broad_phase/pile:N`: the global proximity stage ([`BroadPhase::update`]: AABB sort-and-sweep +
//!   GJK) on a settled `pile:N` (throughput = colliders);
//! - `impact/n`: the simultaneous-impact solve ([`ImpactSolver::solve`], §7.2) of 2, 4 and 8 corner
//!   contacts (1, 2 and 4 boxes stacked on a floor, approaching at 0.5 m/s);
//! - `lcp/n`: the compression LCP alone ([`LcpSolver::solve`]) on those Delassus matrices
//!   (enumeration for n ≤ 6, PGS above);
//! - `normal/NAME`: one sample of every normal law of [`NORMAL_MODEL_NAMES`] (per-contact defaults)
//!   on a contact pressed in and out;
//! - `friction/NAME`: one sample of every friction model of [`FrictionModel::NAMES`] (per-contact
//!   defaults) on a contact alternating stick and slip.
//!
//! Run with `cargo bench -p haptic2d --bench pieces` (about a minute: 1 s per measurement).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use haptic2d::body::Body;
use haptic2d::collide::{BroadPhase, Collider, FeatureTracker, LocalStage, DEFAULT_DELTA_PROX};
use haptic2d::contact::impact::{ImpactRow, ImpactSolver};
use haptic2d::contact::lcp::LcpSolver;
use haptic2d::geom::{ConvexPolygon, Pose, Vec2};
use haptic2d::laws::friction::{FrictionInput, FrictionLaw, FrictionModel};
use haptic2d::laws::normal::{NormalInput, NormalLaw, NormalModel, NORMAL_MODEL_NAMES};
use haptic2d::scene::builtin;
use haptic2d::world::World;
use std::hint::black_box;
use std::time::Duration;

/// Pile sizes of the scaling benchmarks.
const PILE_SIZES: [usize; 3] = [10, 100, 1000];
/// Steps a pile is run before its proximity state is benchmarked (0.5 s at 1 kHz: landed, settling).
const SETTLE_STEPS: usize = 500;

/// A settled `pile:n` world at 1 kHz.
fn settled_pile(n: usize) -> World {
    let mut w = builtin(&format!("pile:{n}"), Some(1000.0))
        .expect("pile:N is a built-in scene")
        .expect("the built-in pile is valid")
        .world;
    for _ in 0..SETTLE_STEPS {
        w.step();
    }
    w
}

fn box_collider(body: usize, dynamic: bool, w: f64, h: f64, pose: Pose) -> Collider {
    let shape = ConvexPolygon::rectangle(w, h).expect("positive sizes");
    Collider::new(body, dynamic, shape, &pose)
}

fn bench_tracker(c: &mut Criterion) {
    let mut g = c.benchmark_group("tracker");
    let b = box_collider(1, false, 0.3, 0.1, Pose::new(0.0, -0.05, 0.0));
    // Separated: a box hovering 1 mm above the floor, swaying by ±1 mrad and ±0.1 mm between samples
    // (coherent motion: the cached features stay valid or move by one step).
    let poses: Vec<Collider> = (0..16)
        .map(|k| {
            let ph = k as f64 / 16.0 * std::f64::consts::TAU;
            let pose = Pose::new(1e-4 * ph.sin(), 0.026 + 1e-4 * ph.cos(), 1e-3 * ph.sin());
            box_collider(0, true, 0.05, 0.05, pose)
        })
        .collect();
    let mut t = FeatureTracker::new();
    let mut k = 0usize;
    g.bench_function("separated_coherent", |bench| {
        bench.iter(|| {
            k = (k + 1) & 15;
            black_box(t.update(black_box(&poses[k]), &b))
        })
    });
    // Penetrating by 0.5 mm: every update runs the warm-started GJK.
    let sunk: Vec<Collider> = (0..16)
        .map(|k| {
            let ph = k as f64 / 16.0 * std::f64::consts::TAU;
            let pose = Pose::new(1e-4 * ph.sin(), 0.0245 + 1e-5 * ph.cos(), 1e-3 * ph.sin());
            box_collider(0, true, 0.05, 0.05, pose)
        })
        .collect();
    let mut t = FeatureTracker::new();
    g.bench_function("penetrating", |bench| {
        bench.iter(|| {
            k = (k + 1) & 15;
            black_box(t.update(black_box(&sunk[k]), &b))
        })
    });
    g.finish();
}

fn bench_stages(c: &mut Criterion, piles: &[(usize, World)]) {
    let mut g = c.benchmark_group("local_stage");
    for (n, w) in piles {
        let pairs = w.proximate_pairs().to_vec();
        let mut local = LocalStage::new();
        let mut out = Vec::new();
        local.update(&w.colliders, &pairs, w.params.delta_c, &mut out);
        g.throughput(Throughput::Elements(pairs.len().max(1) as u64));
        g.bench_with_input(BenchmarkId::new("pile", n), &pairs, |bench, pairs| {
            bench.iter(|| {
                local.update(&w.colliders, pairs, w.params.delta_c, &mut out);
                black_box(out.len())
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("broad_phase");
    for (n, w) in piles {
        let mut broad = BroadPhase::new(DEFAULT_DELTA_PROX).expect("the default margin is valid");
        let mut pairs = Vec::new();
        broad.update(&w.colliders, &mut pairs);
        g.throughput(Throughput::Elements(w.colliders.len() as u64));
        g.bench_with_input(BenchmarkId::new("pile", n), &w.colliders, |bench, cs| {
            bench.iter(|| {
                broad.update(cs, &mut pairs);
                black_box(pairs.len())
            })
        });
    }
    g.finish();
}

/// `boxes` 0.05 m, 2 kg boxes stacked on a fixed floor, each approaching the one below at 0.5 m/s, with
/// two corner contacts per box: `2·boxes` impact rows.
fn stack_impact(boxes: usize) -> (Vec<Body>, Vec<ImpactRow>, Vec<(Vec2, f64)>) {
    let inertia = 2.0 * (0.05f64 * 0.05 + 0.05 * 0.05) / 12.0;
    let mut bodies = vec![Body::fixed("floor", Pose::new(0.0, -0.05, 0.0))];
    let mut twists = vec![(Vec2::ZERO, 0.0)];
    let mut rows = Vec::new();
    for k in 0..boxes {
        let y = 0.025 + 0.05 * k as f64;
        let mut b = Body::dynamic(format!("box{k}"), 2.0, inertia, Pose::new(0.0, y, 0.0));
        // Faster boxes higher up: every contact closes.
        b.vel = Vec2::new(0.0, -0.5 * (k + 1) as f64);
        twists.push((b.vel, b.omega));
        bodies.push(b);
        let (ia, ib) = (k + 1, k);
        let c_b = bodies[ib].pose.pos;
        for sx in [-0.025, 0.025] {
            let v = Vec2::new(sx, y - 0.025);
            rows.push(ImpactRow {
                body_a: ia,
                body_b: ib,
                n: Vec2::Y,
                r_a: v - bodies[ia].pose.pos,
                r_b: v - c_b,
                restitution: 0.2,
            });
        }
    }
    (bodies, rows, twists)
}

fn bench_impact(c: &mut Criterion) {
    let mut gi = c.benchmark_group("impact");
    let mut lcp_inputs = Vec::new();
    for boxes in [1usize, 2, 4] {
        let (mut bodies, rows, twists) = stack_impact(boxes);
        let n = rows.len();
        let mut solver = ImpactSolver::with_capacity(n);
        solver.solve(&rows, &mut bodies);
        lcp_inputs.push((
            n,
            solver.delassus().to_vec(),
            solver.pre_velocities().to_vec(),
        ));
        gi.bench_function(BenchmarkId::from_parameter(n), |bench| {
            bench.iter(|| {
                for (b, &(v, w)) in bodies.iter_mut().zip(&twists) {
                    b.vel = v;
                    b.omega = w;
                }
                black_box(solver.solve(&rows, &mut bodies))
            })
        });
    }
    gi.finish();
    let mut gl = c.benchmark_group("lcp");
    for (n, a, b) in &lcp_inputs {
        let mut lcp = LcpSolver::with_capacity(*n);
        // Which method answers matters for the cost (PGS that fails to converge falls back to the
        // 2ⁿ enumeration for n ≤ 10): say it once.
        match lcp.solve(a, b) {
            Ok(r) => eprintln!(
                "lcp/{n}: {:?}, {} iterations, converged {}, pgs_failed {}",
                r.method, r.iterations, r.converged, r.pgs_failed
            ),
            Err(e) => eprintln!("lcp/{n}: {e}"),
        }
        gl.bench_function(BenchmarkId::from_parameter(n), |bench| {
            bench.iter(|| black_box(lcp.solve(black_box(a), black_box(b))))
        });
    }
    gl.finish();
}

fn bench_normal(c: &mut Criterion) {
    let mut g = c.benchmark_group("normal");
    // A contact pressed to 1 mm and released over 32 samples at 1 kHz (the law sees d, its history and C0).
    let inputs: Vec<NormalInput> = (0..32)
        .map(|k| {
            let ph = |j: f64| ((k as f64 - j) / 32.0 * std::f64::consts::TAU).sin();
            let d = |j: f64| -0.5e-3 * (1.0 + ph(j)) - 1e-5;
            NormalInput {
                d: [d(0.0), d(1.0), d(2.0)],
                hist: 3,
                c0: (d(0.0) - d(1.0)) / 1e-3,
                dt: 1e-3,
                m_eff: 1.0,
            }
        })
        .collect();
    for name in NORMAL_MODEL_NAMES {
        let mut law = NormalModel::from_name(name, true).expect("a listed name");
        let mut k = 0usize;
        g.bench_function(name, |bench| {
            bench.iter(|| {
                k = (k + 1) & 31;
                black_box(law.force(black_box(&inputs[k])))
            })
        });
    }
    g.finish();
}

fn bench_friction(c: &mut Criterion) {
    let mut g = c.benchmark_group("friction");
    // 32 samples: 16 at rest under a growing tangential push (stick), 16 sliding at 0.1 m/s (slip).
    let inputs: Vec<FrictionInput> = (0..32)
        .map(|k| {
            let slip = k >= 16;
            let s0 = if slip { 0.1 } else { 0.0 };
            FrictionInput {
                ds: s0 * 1e-3,
                s: if slip { (k - 16) as f64 * 1e-4 } else { 0.0 },
                s0,
                fn_: 10.0,
                dt: 1e-3,
                f_ext_t: if slip { 6.0 } else { k as f64 * 0.25 },
            }
        })
        .collect();
    for name in FrictionModel::NAMES {
        let mut law = FrictionModel::from_name(name, true).expect("a listed name");
        law.begin(0.0);
        let mut k = 0usize;
        g.bench_function(*name, |bench| {
            bench.iter(|| {
                k = (k + 1) & 31;
                black_box(law.update(black_box(&inputs[k])))
            })
        });
    }
    g.finish();
}

fn pieces(c: &mut Criterion) {
    bench_tracker(c);
    bench_normal(c);
    bench_friction(c);
    bench_impact(c);
    let piles: Vec<(usize, World)> = PILE_SIZES.iter().map(|&n| (n, settled_pile(n))).collect();
    bench_stages(c, &piles);
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .measurement_time(Duration::from_secs(1))
        .warm_up_time(Duration::from_millis(300))
        .sample_size(20);
    targets = pieces
}
criterion_main!(benches);
