//! Physics conformance, dry friction (issue 16): textbook Coulomb results through the full world
//! (scene file → proximity → contacts → laws → integration), each citing the result it checks and
//! where its tolerance comes from.
//!
//! The contact is the paper's penalty law (`kc = 1e5 N/m`, `bc = 40 N·s/m` per corner) with the
//! reset-integrator friction model (stick up to `μ_s·F_n`, slip at `μ_k·F_n`: Coulomb with a
//! presliding spring `kr`), at 1 kHz. An incline of angle φ is the flat floor with gravity tilted by
//! φ (the same equations of motion in the incline's frame).

use haptic2d::scene::Scene;
use haptic2d::world::World;

const G: f64 = 9.81;
const MU_S: f64 = 0.5;
const MU_K: f64 = 0.4;
/// Karnopp's velocity-threshold Coulomb model with a narrow band.
const CLASSICAL: &str = "model = \"classical\"\nv_th = 0.001\nmu_s = 0.5\nmu_k = 0.4";
/// A flat slab (m) for the incline: the friction at its base shifts normal load from the rear to
/// the front corner by `f·(h/2)/b` = 2 % of `m·g`, which keeps each corner's share of the load
/// within `μ_s` of its share of the demand (the classical model splits the demand equally over the
/// contacts; see the finding below).
const SLAB: [f64; 2] = [0.2, 0.02];
/// The stick band of [`CLASSICAL`] (m/s).
const V_TH: f64 = 0.001;
/// The paper's reset integrator (presliding spring kr, stick damping β).
const RESET: &str = "model = \"reset-integrator\"\nkr = 1.0e5\nmu_s = 0.5\nmu_k = 0.4\nbeta = 20.0";

/// A 0.1 m × 0.05 m, 1 kg box resting on a long floor (top at y = 0), gravity `g` (m/s²).
fn block_world(g: [f64; 2], extra_load: &str) -> World {
    sized_block_world([0.1, 0.05], g, extra_load)
}

/// A `size` (m), 1 kg box resting on a long floor (top at y = 0), gravity `g` (m/s²).
fn sized_block_world(size: [f64; 2], g: [f64; 2], extra_load: &str) -> World {
    world_with(CLASSICAL, size, g, extra_load)
}

/// The block world with the `[friction]` table body `friction`.
fn world_with(friction: &str, size: [f64; 2], g: [f64; 2], extra_load: &str) -> World {
    let text = format!(
        r#"
name = "conformance-block"
[world]
rate = 1000
proximity_every = 10
integration = "semi-implicit"
[contact]
impacts = true
restitution = 0.0
v_c = 0.05
[normal]
model = "paper"
kc = 1.0e5
bc = 40.0
[friction]
{friction}
[[body]]
name = "floor"
kind = "fixed"
polygon = [[-20.0, -0.1], [20.0, -0.1], [20.0, 0.0], [-20.0, 0.0]]
[[body]]
name = "block"
mass = 1.0
box = [{}, {}]
position = [0.0, {}]
[[load]]
body = "block"
force = [{}, {}]
per_mass = true
{extra_load}
"#,
        size[0],
        size[1],
        size[1] / 2.0,
        g[0],
        g[1]
    );
    Scene::from_toml(&text, "conformance-block", None)
        .expect("valid scene")
        .world
}

/// The block placed on an incline of angle `phi` (rad): it first settles for 0.3 s under the
/// normal component `g·cos φ` alone (a block set down on the slope is loaded before it is let go;
/// starting with the full tilted gravity on a contact whose normal force is still zero would let it
/// slip in the first samples), then the tangential component `g·sin φ` is switched on.
fn incline(friction: &str, phi: f64, size: [f64; 2]) -> World {
    let mut w = world_with(friction, size, [0.0, -G * phi.cos()], "");
    run(&mut w, 0.3);
    w.loads[0].force.x = G * phi.sin();
    w
}

/// Steps `w` for `seconds`.
fn run(w: &mut World, seconds: f64) {
    for _ in 0..(seconds / w.params.dt).round() as usize {
        w.step();
    }
}

/// Block on an incline (Coulomb; e.g. Meriam & Kraige, Engineering Mechanics: Dynamics, §3/4):
/// at rest it stays at rest while `tan φ < μ_s`; above, it slides with
/// `a = g·(sin φ − μ_k·cos φ)`.
///
/// Tolerances: Karnopp's model sticks inside the band `|v| ≤ v_th` and lets the block creep there
/// (its documented behaviour, Fig. 7), so "at rest" is `|v| ≤ v_th` after 2 s and a travel of at
/// most `v_th·2 s = 2 mm`, against `½·a·t² ≥ 0.6 m` had it slid. Sliding: the acceleration is measured from the velocity
/// change between 0.5 s and 1.5 s, after the normal-force transient of the penalty contact (time
/// constant `m/(2·bc) ≈ 12 ms`) has died out; what is left is the sampling of the slip force, so the
/// tolerance is 1 % of the expected value.
#[test]
fn incline_sticks_below_tan_phi_mu_s_and_slides_above_with_g_sin_minus_mu_cos() {
    for ratio in [0.6, 0.9] {
        let phi = (ratio * MU_S).atan();
        let mut w = incline(CLASSICAL, phi, SLAB);
        let x0 = w.bodies[1].pose.pos.x;
        run(&mut w, 2.0);
        let dx = w.bodies[1].pose.pos.x - x0;
        let v = w.bodies[1].vel.x;
        eprintln!("stick tan φ = {ratio}·μ_s: moved {dx:e} m in 2 s, v = {v:e} m/s");
        assert!(
            v.abs() <= V_TH,
            "tan φ = {ratio} μ_s: v = {v} m/s left the stick band"
        );
        assert!(
            dx.abs() <= V_TH * 2.0,
            "tan φ = {ratio} μ_s: block moved {dx} m"
        );
    }
    for ratio in [1.2, 1.6] {
        let phi = (ratio * MU_S).atan();
        let mut w = incline(CLASSICAL, phi, SLAB);
        run(&mut w, 0.5);
        let v1 = w.bodies[1].vel.x;
        run(&mut w, 1.0);
        let v2 = w.bodies[1].vel.x;
        let a = v2 - v1;
        let want = G * (phi.sin() - MU_K * phi.cos());
        eprintln!("slide tan φ = {ratio}·μ_s: a = {a:.5} m/s², expected {want:.5}");
        assert!(
            (a - want).abs() <= 0.01 * want,
            "tan φ = {ratio} μ_s: a = {a}, expected {want}"
        );
    }
}

/// A block sliding at `v₀` on a level floor stops after `d = v₀²/(2·μ_k·g)` (work–energy).
///
/// The block first settles for 0.2 s, then gets `v₀ = 1 m/s`. Tolerance two samples of travel,
/// `2·v₀·T = 2 mm` (1.6 %): semi-implicit Euler under-counts the distance by `v₀·T/2`, the sample in
/// which the velocity is set is not integrated at `v₀`, and the stop is resolved to one sample.
#[test]
fn sliding_block_stops_after_v2_over_2_mu_k_g() {
    let mut w = block_world([0.0, -G], "");
    run(&mut w, 0.2);
    let v0 = 1.0;
    w.bodies[1].vel.x = v0;
    let x0 = w.bodies[1].pose.pos.x;
    let (mut fy, mut fx, mut k) = (0.0, 0.0, 0);
    for _ in 0..600 {
        w.step();
        if w.bodies[1].vel.x > 0.05 {
            let c = w.contact_wrench(1);
            fy += c.force.y;
            fx += c.force.x;
            k += 1;
        }
    }
    eprintln!(
        "mean contact force while sliding: ({:.4}, {:.4}) N, ratio {:.4}",
        fx / k as f64,
        fy / k as f64,
        -fx / fy
    );
    let d = w.bodies[1].pose.pos.x - x0;
    let want = v0 * v0 / (2.0 * MU_K * G);
    eprintln!("stopping distance {d:.5} m, expected {want:.5} m");
    assert!(
        w.bodies[1].vel.x.abs() < 1e-3,
        "still moving: {}",
        w.bodies[1].vel.x
    );
    assert!(
        (d - want).abs() <= 2.0 * v0 * w.params.dt,
        "d = {d}, expected {want}"
    );
}

/// A box of width `b` and height `h` pushed horizontally at height `y` above the floor by `F`:
/// it tips about its front corner when `F·y > m·g·b/2` while friction holds (`F < μ_s·m·g`), and
/// slides without tipping when `F > μ_s·m·g` but `F·y < m·g·b/2` (statics; e.g. Beer & Johnston,
/// Vector Mechanics for Engineers: Statics, §8.2, "tipping or sliding").
///
/// The push is a force at the centre of mass plus the torque `−F·(y − h/2)` it has about it.
/// Thresholds here: `b = 0.1 m`, `h = 0.05 m`, `m g = 9.81 N`; tipping needs `F·y > 0.49 N·m`,
/// sliding `F > 4.9 N`. Criterion after 0.3 s: tipping rotates the box past 0.05 rad with the front
/// corner moving < 2 mm; sliding moves it > 5 cm with `|θ| < 0.01 rad`. Both margins are ≥ 20 % of
/// the thresholds, so the result does not depend on the penalty compliance.
#[test]
fn pushed_box_tips_or_slides_as_statics_says() {
    let (b, h, mg) = (0.05, 0.1, G);
    // Tips: push at the top (y = h) with F·y = 1.3 × m g b/2, F = 0.6 μ_s m g ... checked below.
    let y_tip = h;
    let f_tip = 1.3 * mg * b / 2.0 / y_tip;
    assert!(f_tip < MU_S * mg, "case must be below sliding");
    let tip = format!(
        "[[load]]\nbody = \"block\"\nforce = [{f_tip}, 0.0]\ntorque = {}\n",
        -f_tip * (y_tip - h / 2.0)
    );
    let mut w = sized_block_world([b, h], [0.0, -G], &tip);
    for _ in 0..300 {
        w.step();
        if w.bodies[1].pose.angle < -0.1 {
            break;
        }
    }
    let th = w.bodies[1].pose.angle;
    let corner_x = w.bodies[1].pose.pos.x + (b / 2.0) * th.cos() - (-h / 2.0) * th.sin() - b / 2.0;
    eprintln!("tip case: θ = {th:.4} rad, front corner moved {corner_x:e} m");
    assert!(
        th < -0.05,
        "did not tip (clockwise, about the front corner): θ = {th}"
    );
    assert!(corner_x.abs() < 2e-3, "front corner slid {corner_x} m");

    // Slides: push low (y = h/10) with F = 1.3 μ_s m g; F·y = 0.064 N·m < 0.245 N·m.
    let y_sl = h / 10.0;
    let f_sl = 1.3 * MU_S * mg;
    assert!(
        f_sl * y_sl < 0.8 * mg * b / 2.0,
        "case must be below tipping"
    );
    let slide = format!(
        "[[load]]\nbody = \"block\"\nforce = [{f_sl}, 0.0]\ntorque = {}\n",
        -f_sl * (y_sl - h / 2.0)
    );
    let mut w = sized_block_world([b, h], [0.0, -G], &slide);
    run(&mut w, 0.3);
    let th = w.bodies[1].pose.angle;
    let x = w.bodies[1].pose.pos.x;
    eprintln!("slide case: x = {x:.4} m, θ = {th:e} rad");
    assert!(x > 0.05, "did not slide: x = {x}");
    assert!(th.abs() < 0.01, "tipped while sliding: θ = {th}");
}

/// **Finding (issue 16, not fixed here: laws/friction is not this change's).** With the paper's
/// reset integrator (`kr = 1e5 N/m`, `β = 20 N·s/m`) the same textbook cases deviate:
/// - a block on an incline with `tan φ = 0.9·μ_s` (above `μ_k`) released from rest slides 0.89 m in
///   2 s: the suddenly loaded presliding spring overshoots its strain limit `p0 = μ_k·F_n/kr` and
///   the contact slips, after which `μ_k` cannot hold it;
/// - a block sliding at 1 m/s stops after 0.1179 m instead of `v²/(2 μ_k g)` = 0.1274 m (−7.5 %):
///   the mean friction ratio while sliding is 0.416, not 0.400. When a corner's `F_n` rises,
///   `p0` grows past `p + ds`, the law takes its stick branch for a sample and adds
///   `(1 + a)·Kr·p + β·S0` with `S0 ≈ 1 m/s`.
///
/// The classical model (above) meets both; this test pins the reset integrator's deviation.
#[test]
#[ignore = "finding: reset-integrator friction releases at 0.9 μ_s and over-brakes a sliding block by 7.5 % (laws/friction/reset_integrator.rs)"]
fn reset_integrator_meets_the_textbook_incline_and_stopping_distance() {
    let phi = (0.9 * MU_S).atan();
    let mut w = incline(RESET, phi, SLAB);
    let x0 = w.bodies[1].pose.pos.x;
    run(&mut w, 2.0);
    let dx = w.bodies[1].pose.pos.x - x0;
    let mut w2 = world_with(RESET, [0.1, 0.05], [0.0, -G], "");
    run(&mut w2, 0.2);
    w2.bodies[1].vel.x = 1.0;
    let s0 = w2.bodies[1].pose.pos.x;
    run(&mut w2, 0.6);
    let d = w2.bodies[1].pose.pos.x - s0;
    let want = 1.0 / (2.0 * MU_K * G);
    assert!(
        dx.abs() < 1e-3 && (d - want).abs() <= 2e-3,
        "incline 0.9 μ_s moved {dx} m; stopping distance {d} m vs {want} m"
    );
}

/// **Finding (not fixed here: laws/friction).** Karnopp's classical model gives each contact an
/// equal share `(t·F_nonfric)/n_t` of the tangential demand, but the friction at the base of a tall
/// block shifts normal load to its front corner (`Δ F_n = f·(h/2)/b`). A 0.1 m × 0.05 m block on an
/// incline with `tan φ = 0.9·μ_s` (rigid Coulomb: it sticks, the total demand is below `μ_s·N`)
/// slips at the unloaded rear corner and slides away (0.91 m in 2 s, v = 0.90 m/s).
#[test]
#[ignore = "finding: the classical model's equal per-contact share lets a tall block slip on an incline below tan φ = μ_s (laws/friction/karnopp.rs)"]
fn classical_tall_block_sticks_below_tan_phi_mu_s() {
    let phi = (0.9 * MU_S).atan();
    let mut w = incline(CLASSICAL, phi, [0.1, 0.05]);
    run(&mut w, 2.0);
    let v = w.bodies[1].vel.x;
    assert!(v.abs() <= V_TH, "v = {v} m/s: the block slid");
}
