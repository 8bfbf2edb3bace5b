//! Fig. 7 through the full world pipeline (§13.2, F7-2D) and P4's Fig. 7 part.
//!
//! The `peg-in-hole` scene (0.2 kg peg, 1 mm interference at its 4 corners with `Kc = 1000 N/m` per
//! corner, so `F_n = 1 N` per corner and 2 N per wall; VE mode, `T = 2 ms`) is run for 5.2 s with each
//! friction model at its per-contact parameters and the push peak set to 2.1 N or 1.8 N. The normal law
//! is the scene's paper law with `Bc = 0`: a pure SEH stiffness. With the peg symmetric in the channel
//! its penetration is constant, so the SEH estimate equals the penetration and any pure-stiffness
//! variant (ZOH, SEH, predictor–corrector) gives the same 1 N per corner.

use haptic2d::geom::{ConvexPolygon, Vec2};
use haptic2d::laws::friction::FrictionModel;
use haptic2d::scene::builtin;
use haptic2d::world::World;
use haptic2d_lab::harness::peg::{PegHarness, PegPush, PegResult};

const MODELS: [&str; 5] = [
    "classical",
    "salcudean-vlaar",
    "reset-integrator",
    "hayward-armstrong",
    "nahvi",
];

/// The peg-in-hole world with `model` (per-contact parameters), push peak `f_pk` (N) and an optional
/// passivity guard tolerance (J).
fn world(model: &str, f_pk: f64, guard: Option<f64>) -> (World, usize) {
    let w = builtin("peg-in-hole", None)
        .expect("built-in")
        .expect("valid")
        .world;
    let peg = w.body_index("peg").expect("peg");
    let mut params = w.params;
    params.guard = guard;
    let mut loads = w.loads.clone();
    for l in loads.iter_mut().filter(|l| l.body == peg) {
        l.force = Vec2::new(f_pk, 0.0);
    }
    let mut shapes: Vec<Vec<ConvexPolygon>> = vec![Vec::new(); w.bodies.len()];
    for c in &w.colliders {
        shapes[c.body].push(c.local.clone());
    }
    let friction = FrictionModel::from_name(model, true).expect("model");
    let w = World::new(w.bodies, shapes, loads, w.normal, friction, params);
    (w, peg)
}

struct Run2d {
    r: PegResult,
    max_theta: f64,
    max_y: f64,
    guard_triggers: u64,
}

/// Runs 5.2 s and returns the peg's x series with the Fig. 7 metrics (same definitions as the 1-D
/// harness), plus the symmetry bounds.
fn run_2d(model: &str, f_pk: f64, guard: Option<f64>) -> Run2d {
    let (mut w, peg) = world(model, f_pk, guard);
    let dt = w.params.dt;
    let n = (5.2 / dt).round() as usize;
    let mut r = PegResult {
        mass: w.bodies[peg].mass,
        dt,
        period: 1.0,
        ..PegResult::default()
    };
    let (mut max_theta, mut max_y) = (0.0f64, 0.0f64);
    for _ in 0..=n {
        let b = &w.bodies[peg];
        max_theta = max_theta.max(b.pose.angle.abs());
        max_y = max_y.max(b.pose.pos.y.abs());
        r.t.push(w.time());
        r.x.push(b.pose.pos.x);
        w.step();
    }
    r.creep = (1..=4).map_while(|k| r.creep_of(k)).collect();
    r.advance = (1..=3).map_while(|k| r.advance_of(k)).collect();
    r.max_abs_x = r.x.iter().fold(0.0, |a, x| a.max(x.abs()));
    Run2d {
        r,
        max_theta,
        max_y,
        guard_triggers: w.guard_triggers(),
    }
}

fn run_1d(model: &str, f_pk: f64) -> PegResult {
    PegHarness::fig7(FrictionModel::from_name(model, false).expect("model"))
        .run(&PegPush::fig7(f_pk))
        .expect("valid harness")
}

fn max(v: &[f64]) -> f64 {
    v.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
}
fn min(v: &[f64]) -> f64 {
    v.iter().cloned().fold(f64::INFINITY, f64::min)
}

/// F7-1 … F7-4 on a result (the thresholds of §13.2).
fn f7_checks(model: &str, f_pk: f64, r: &PegResult) {
    assert_eq!(r.creep.len(), 4, "{model}");
    assert_eq!(r.advance.len(), 3, "{model}");
    if f_pk > 2.0 {
        if model == "classical" {
            // F7-1.
            assert!(min(&r.creep) >= 5e-4, "{model}: creep {:?}", r.creep);
            assert!(
                max(&r.creep) - min(&r.creep) > 1e-4,
                "{model}: {:?}",
                r.creep
            );
        } else {
            // F7-2.
            assert!(max(&r.creep) <= 2e-4, "{model}: creep {:?}", r.creep);
            for w in r.creep.windows(2).chain(r.advance.windows(2)) {
                assert!((w[1] - w[0]).abs() < 1e-5, "{model}: not periodic {w:?}");
            }
        }
        // F7-3.
        assert!(min(&r.advance) > 5e-3, "{model}: advance {:?}", r.advance);
    } else {
        // F7-4.
        match model {
            "classical" => assert!(r.x.iter().all(|&x| x == 0.0), "classical: x ≢ 0"),
            "hayward-armstrong" => {
                for a in &r.advance {
                    assert!(0.2e-3 < *a && *a < 2e-3, "HA: advance {a:e}");
                }
            }
            _ => {
                for a in &r.advance {
                    assert!(a.abs() < 1e-6, "{model}: |advance| {a:e}");
                }
                assert!(r.max_abs_x < 4e-4, "{model}: max|x| {:e}", r.max_abs_x);
            }
        }
    }
}

/// The numbers F7-2D compares with the 1-D reference.
fn numbers(model: &str, f_pk: f64, r: &PegResult) -> Vec<f64> {
    if f_pk > 2.0 {
        r.creep.iter().chain(&r.advance).copied().collect()
    } else if model == "hayward-armstrong" {
        r.advance.clone()
    } else if model == "classical" {
        Vec::new() // x ≡ 0 in both
    } else {
        vec![r.max_abs_x]
    }
}

#[test]
fn f7_2d_pipeline_matches_1d() {
    for model in MODELS {
        for f_pk in [2.1, 1.8] {
            let two = run_2d(model, f_pk, None);
            f7_checks(model, f_pk, &two.r);
            let one = run_1d(model, f_pk);
            for (a, b) in numbers(model, f_pk, &two.r)
                .iter()
                .zip(numbers(model, f_pk, &one))
            {
                assert!(
                    ((a - b) / b).abs() <= 0.10,
                    "{model} @{f_pk} N: 2-D {a:e} vs 1-D {b:e}"
                );
            }
            assert!(
                two.max_theta < 1e-6,
                "{model} @{f_pk} N: |θ| {:e}",
                two.max_theta
            );
            assert!(two.max_y < 1e-6, "{model} @{f_pk} N: |y| {:e}", two.max_y);
        }
    }
}

#[test]
fn p4_guard_never_triggers_on_fig7() {
    for model in MODELS {
        for f_pk in [2.1, 1.8] {
            let run = run_2d(model, f_pk, Some(1e-9));
            assert_eq!(
                run.guard_triggers, 0,
                "{model} @{f_pk} N: the passivity guard triggered"
            );
        }
    }
}

#[test]
fn p4_guard_from_toml_world_section() {
    // The same guard set from the scene file (`[world] guard = 1e-9`), reset-integrator friction.
    let text = haptic2d::scene::BUILTIN
        .iter()
        .find(|b| b.0 == "peg-in-hole")
        .expect("built-in")
        .2
        .replace("[world]\n", "[world]\nguard = 1e-9\n");
    let mut w = haptic2d::scene::Scene::from_toml(&text, "peg-in-hole+guard", None)
        .expect("valid scene")
        .world;
    assert_eq!(w.params.guard, Some(1e-9));
    for _ in 0..2600 {
        w.step();
    }
    assert_eq!(w.guard_triggers(), 0);
}
