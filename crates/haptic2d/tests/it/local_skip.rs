//! The local stage may skip separated pairs whose certified gap the bodies' relative motion
//! cannot have closed (`LocalStage::update_with_motion`, issue 17): the candidates must be
//! exactly those of tracking every pair every sample, and the skipping must actually happen.
//!
//! Both stages see the same colliders and proximate pairs of a world that is stepped normally:
//! random convex polygons thrown around a closed box under gravity (seeded), and the landing
//! pile:100.

use haptic2d::collide::{LocalStage, VeCandidate, DEFAULT_DELTA_C};
use haptic2d::geom::Pose;
use haptic2d::scene::{builtin, Scene};
use haptic2d::world::World;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;

/// A random strictly convex polygon of circumradius `r` (m), counter-clockwise.
fn polygon(rng: &mut ChaCha8Rng, r: f64) -> String {
    let n = rng.random_range(3..=10usize);
    let aspect = rng.random_range(0.4..1.0);
    let mut s = String::from("[");
    for i in 0..n {
        let a = std::f64::consts::TAU * (i as f64 + rng.random_range(-0.3..0.3)) / n as f64;
        let _ = write!(s, "[{:.6}, {:.6}], ", r * a.cos(), aspect * r * a.sin());
    }
    s.push(']');
    s
}

/// A 0.5 m closed box with 6 random polygons in a 3 × 2 grid of cells, thrown at up to 1.5 m/s.
fn random_world(seed: u64) -> World {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut s = String::from(
        "name = \"skip\"\n[world]\nrate = 1000\n[contact]\nimpacts = true\nrestitution = 0.3\n\
         v_c = 0.05\n[normal]\nmodel = \"paper\"\nkc = 5000.0\nbc = 10.0\n[friction]\n\
         model = \"reset-integrator\"\n[[body]]\nname = \"walls\"\nkind = \"fixed\"\npieces = [\
         [[-0.1, -0.1], [0.6, -0.1], [0.6, 0], [-0.1, 0]], [[-0.1, 0], [0, 0], [0, 0.5], [-0.1, 0.5]], \
         [[0.5, 0], [0.6, 0], [0.6, 0.5], [0.5, 0.5]], [[-0.1, 0.5], [0.6, 0.5], [0.6, 0.6], [-0.1, 0.6]]]\n",
    );
    for i in 0..6 {
        let (cx, cy) = (
            0.5 / 3.0 * ((i % 3) as f64 + 0.5),
            0.25 * ((i / 3) as f64 + 0.5),
        );
        let r = rng.random_range(0.02..0.06);
        let speed = rng.random_range(0.0..1.5);
        let dir = rng.random_range(0.0..std::f64::consts::TAU);
        let _ = write!(
            s,
            "[[body]]\nname = \"p{i}\"\ndensity = 1000.0\npolygon = {}\nposition = [{cx:.4}, {cy:.4}]\n\
             angle = {:.3}\nvelocity = [{:.4}, {:.4}]\nomega = {:.3}\n",
            polygon(&mut rng, r),
            rng.random_range(0.0..std::f64::consts::TAU),
            speed * dir.cos(),
            speed * dir.sin(),
            rng.random_range(-5.0..5.0),
        );
    }
    s.push_str("[[load]]\nbody = \"*\"\nforce = [0.0, -9.81]\nper_mass = true\n");
    Scene::from_toml(&s, "skip", None)
        .expect("random scene")
        .world
}

/// Steps `w` for `steps` samples; at every sample feeds its colliders (at the new poses) and
/// proximate pairs to a skipping and a full local stage and compares their candidates. Returns
/// the pairs tracked and skipped by the skipping stage over the run.
fn compare(w: &mut World, steps: usize, label: &str) -> (usize, usize) {
    let mut skipping = LocalStage::new();
    let mut full = LocalStage::new();
    let (mut a, mut b) = (Vec::<VeCandidate>::new(), Vec::<VeCandidate>::new());
    let mut colliders = w.colliders.clone();
    let (mut tracked, mut skipped) = (0, 0);
    for k in 0..steps {
        w.step();
        for c in colliders.iter_mut() {
            let pose = w.bodies[c.body].pose;
            c.update_with(&pose, pose.rot());
        }
        let pairs = w.proximate_pairs().to_vec();
        let poses: Vec<Pose> = w.bodies.iter().map(|b| b.pose).collect();
        skipping.update_with_motion(&colliders, &pairs, DEFAULT_DELTA_C, &poses, &mut a);
        full.update(&colliders, &pairs, DEFAULT_DELTA_C, &mut b);
        assert_eq!(a, b, "{label}: candidates differ at sample {k}");
        skipped += skipping.skipped();
        tracked += pairs.len() - skipping.skipped();
    }
    (tracked, skipped)
}

#[test]
fn skipping_far_pairs_gives_the_candidates_of_tracking_every_pair() {
    let (mut tracked, mut skipped) = (0, 0);
    for seed in 1..=12 {
        let mut w = random_world(seed);
        let (t, s) = compare(&mut w, 1500, &format!("random scene {seed}"));
        tracked += t;
        skipped += s;
    }
    eprintln!("random scenes: {tracked} pair updates tracked, {skipped} skipped");
    assert!(
        skipped > 0 && tracked > 0,
        "{tracked} tracked, {skipped} skipped"
    );
}

#[test]
fn skipping_in_a_landing_pile_gives_the_same_candidates() {
    let mut w = builtin("pile:100", None).unwrap().unwrap().world;
    let (tracked, skipped) = compare(&mut w, 1000, "pile:100");
    eprintln!("pile:100: {tracked} pair updates tracked, {skipped} skipped");
    // Most separated pairs of a settling pile wait (the share is printed above).
    assert!(
        skipped * 5 > tracked,
        "{tracked} tracked, {skipped} skipped"
    );
}

/// A skipped pair is checked against the contact tolerance of the sample that checks it: a box
/// 5 mm above a floor, tracked with `δ_c` = 2 mm (no candidate, then skipped while nothing moves),
/// gets its candidates at once when `δ_c` is raised to 10 mm (the parameters are re-read every
/// sample), as a stage that tracks every pair does.
#[test]
fn a_raised_contact_tolerance_reaches_skipped_pairs_at_once() {
    let text = "name = \"gap\"\n[[body]]\nname = \"floor\"\nkind = \"fixed\"\n\
                pieces = [[[-0.5, -0.1], [0.5, -0.1], [0.5, 0.0], [-0.5, 0.0]]]\n\
                [[body]]\nname = \"box\"\nmass = 1.0\nbox = [0.1, 0.1]\nposition = [0.0, 0.055]\n";
    let w = Scene::from_toml(text, "gap", None).expect("scene").world;
    let colliders = w.colliders.clone();
    let mut pairs = Vec::new();
    haptic2d::collide::BroadPhase::new(haptic2d::collide::DEFAULT_DELTA_PROX)
        .unwrap()
        .update(&colliders, &mut pairs);
    assert_eq!(pairs.len(), 1, "{pairs:?}");
    let poses: Vec<Pose> = w.bodies.iter().map(|b| b.pose).collect();
    let mut skipping = LocalStage::new();
    let mut out = Vec::new();
    for _ in 0..3 {
        skipping.update_with_motion(&colliders, &pairs, 0.002, &poses, &mut out);
        assert!(out.is_empty(), "5 mm apart, δ_c = 2 mm: {out:?}");
    }
    assert_eq!(skipping.skipped(), 1, "the pair waits while nothing moves");
    skipping.update_with_motion(&colliders, &pairs, 0.010, &poses, &mut out);
    let mut expected = Vec::new();
    LocalStage::new().update(&colliders, &pairs, 0.010, &mut expected);
    assert_eq!(expected.len(), 2, "the face's two corners: {expected:?}");
    assert_eq!(out, expected);
}
