//! Fast thin bodies do not tunnel (issue 10): `r9-rod-tunnel.toml` (a copy of
//! `../shared/repro/`), a 0.1 × 0.002 m rod thrown end-on at 5 m/s at 500 Hz against a 10 mm wall,
//! went 10 cm past the wall's face before any contact and came to rest embedded in it; against a
//! 100 mm wall the same throw created 2.9 J. The limit the world guarantees is a motion of
//! `(δ_prox − δ_c)/2` = 20 mm per sample (10 m/s at 500 Hz), `collide/toi.rs`.

use haptic2d::scene::Scene;
use haptic2d::world::World;

const R9: &str = include_str!("../repro/r9-rod-tunnel.toml");
/// The wall's face (m).
const FACE: f64 = 0.3;

fn rod_world(speed: f64, wall_thickness: f64, broadside: bool) -> World {
    let mut text = R9.replace(
        "velocity = [5.0, 0.0]",
        &format!("velocity = [{speed}, 0.0]"),
    );
    assert!(text.contains(&format!("velocity = [{speed}, 0.0]")));
    let back = FACE + wall_thickness;
    text = text.replace(
        "polygon = [[0.3, -0.3], [0.31, -0.3], [0.31, 0.3], [0.3, 0.3]]",
        &format!("polygon = [[0.3, -0.3], [{back}, -0.3], [{back}, 0.3], [0.3, 0.3]]"),
    );
    if broadside {
        text = text.replace(
            "position = [0.1, 0.0]",
            "position = [0.1, 0.0]\nangle_deg = 90.0",
        );
    }
    let mut w = Scene::from_toml(&text, "r9", None).expect("valid").world;
    w.prime();
    w
}

struct Throw {
    /// Deepest any rod vertex went past the wall's face (m).
    max_past_face: f64,
    /// Rod velocity at the end (m/s).
    final_vx: f64,
    max_excess: f64,
}

fn throw(w: &mut World, seconds: f64) -> Throw {
    let rod = w.body_index("rod").expect("rod");
    let rod_collider = w.colliders.iter().position(|c| c.body == rod).unwrap();
    let mut t = Throw {
        max_past_face: f64::NEG_INFINITY,
        final_vx: 0.0,
        max_excess: f64::NEG_INFINITY,
    };
    for _ in 0..(seconds / w.params.dt).round() as usize {
        w.step();
        let c = &mut w.colliders[rod_collider].clone();
        c.update(&w.bodies[rod].pose);
        let x = c
            .world_vertices()
            .iter()
            .map(|v| v.x)
            .fold(f64::MIN, f64::max);
        t.max_past_face = t.max_past_face.max(x - FACE);
        t.max_excess = t.max_excess.max(w.ledger().excess());
    }
    t.final_vx = w.bodies[rod].vel.x;
    t
}

#[test]
fn r9_thin_rod_end_on_bounces_off_the_wall() {
    for speed in [5.0, 7.5, 9.5] {
        let mut w = rod_world(speed, 0.01, false);
        assert!(
            w.speed_warnings().is_empty(),
            "{speed} m/s is within the limit"
        );
        let t = throw(&mut w, 0.3);
        let (hits, early) = w.continuous_stats();
        println!(
            "r9 end-on {speed} m/s: deepest {:.3} mm past the face, final vx {:.3} m/s, max excess {:.3e} J, swept put-backs {hits}, early global updates {early}",
            t.max_past_face * 1e3,
            t.final_vx,
            t.max_excess
        );
        assert!(
            t.max_past_face < 0.003,
            "{speed} m/s: {} m past the face",
            t.max_past_face
        );
        assert!(
            t.final_vx < 0.0,
            "{speed} m/s: the rod did not bounce (vx {})",
            t.final_vx
        );
        assert!(
            t.max_excess <= 1e-3,
            "{speed} m/s: gained {} J",
            t.max_excess
        );
    }
}

#[test]
fn r9_thin_rod_broadside_does_not_pass_the_wall() {
    let mut w = rod_world(5.0, 0.01, true);
    let t = throw(&mut w, 0.3);
    println!(
        "r9 broadside 5 m/s: deepest {:.3} mm past the face, final vx {:.3} m/s, max excess {:.3e} J",
        t.max_past_face * 1e3,
        t.final_vx,
        t.max_excess
    );
    assert!(
        t.max_past_face < 0.003,
        "{} m past the face",
        t.max_past_face
    );
    assert!(t.final_vx < 0.0, "no bounce (vx {})", t.final_vx);
    assert!(t.max_excess <= 1e-3, "gained {} J", t.max_excess);
}

#[test]
fn r9_thin_rod_against_a_thick_wall_gains_no_energy() {
    // Was +2.9 J: the rod entered 10 cm deep before the pair was proximate.
    for speed in [5.0, 9.5] {
        let mut w = rod_world(speed, 0.1, false);
        let t = throw(&mut w, 0.3);
        println!(
            "r9 thick wall {speed} m/s: deepest {:.3} mm past the face, final vx {:.3} m/s, max excess {:.3e} J",
            t.max_past_face * 1e3,
            t.final_vx,
            t.max_excess
        );
        assert!(
            t.max_excess <= 1e-3,
            "{speed} m/s: gained {} J",
            t.max_excess
        );
        assert!(
            t.max_past_face < 0.003,
            "{} m past the face",
            t.max_past_face
        );
    }
}

#[test]
fn r9_speed_beyond_the_guaranteed_limit_is_reported() {
    // 500 Hz, δ_prox = 0.042 m, δ_c = 0.002 m: 0.02 m per sample = 10 m/s.
    let w = rod_world(12.0, 0.01, false);
    let warnings = w.speed_warnings();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("\"rod\"") && warnings[0].contains("10.000 m/s"),
        "{}",
        warnings[0]
    );
    assert!(rod_world(9.9, 0.01, false).speed_warnings().is_empty());
}

#[test]
fn swept_test_stops_a_rod_at_9_5_m_s_before_a_2_mm_plate() {
    // 19 mm per sample against a 2 mm plate with a 2 mm rod: one sample can carry the rod past
    // the plate entirely; only the swept test (time of impact) catches it.
    let mut w = rod_world(9.5, 0.002, true);
    let t = throw(&mut w, 0.3);
    let (hits, _) = w.continuous_stats();
    println!(
        "2 mm plate, broadside 9.5 m/s: deepest {:.3} mm past the face, final vx {:.3} m/s, max excess {:.3e} J, swept put-backs {hits}",
        t.max_past_face * 1e3,
        t.final_vx,
        t.max_excess
    );
    assert!(hits > 0, "the swept test never fired");
    assert!(
        t.max_past_face < 0.001,
        "{} m past the face",
        t.max_past_face
    );
    assert!(t.final_vx < 0.0, "no bounce (vx {})", t.final_vx);
    assert!(t.max_excess <= 1e-3, "gained {} J", t.max_excess);
}
