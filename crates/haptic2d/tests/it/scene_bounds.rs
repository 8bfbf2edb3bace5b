//! Issue 10, items 4 and 5: every number of a scene is finite and within its documented bound
//! (docs/SCENES.md, "Bounds"), every count that sizes an allocation is capped, and each violation is
//! a clear error naming the field — checked before anything is allocated from it. The repro scenes
//! r1, r4, r5 and r7 (copied into tests/repro/) are regression tests.

use haptic2d::scene::bounds::{
    MAX_BODIES, MAX_LENGTH_M, MAX_OMEGA_RAD_S, MAX_RATE_HZ, MAX_SPEED_M_S, MAX_VERTICES,
};
use haptic2d::scene::{builtin, Scene};

use crate::shared::WALL_TOML as WALL;

use crate::shared::assert_scene_error as assert_error;

/// A dynamic body `b` (a 4 cm box of 0.5 kg at x = 0.1 m) with extra keys.
fn body(extra: &str) -> String {
    format!("{WALL}\n[[body]]\nname = \"b\"\nmass = 0.5\nbox = [0.04, 0.04]\nposition = [0.1, 0.0]\n{extra}\n")
}

fn repro(name: &str) -> String {
    let path = format!("{}/tests/repro/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

#[test]
fn the_base_scene_is_valid() {
    Scene::from_toml(&body(""), "test.toml", None).expect("valid");
}

#[test]
fn r1_nan_velocity_is_rejected_naming_the_field() {
    let e = Scene::from_toml(&repro("r1-velocity-nan.toml"), "r1", None).unwrap_err();
    assert_eq!(e.errors.len(), 1, "one problem, no follow-up errors: {e}");
    let x = &e.errors[0];
    assert!(x.field.contains("\"box\".velocity[0]"), "{e}");
    assert!(x.message.contains("NaN"), "{e}");
}

#[test]
fn infinite_velocity_is_rejected() {
    assert_error(&body("velocity = [0.0, inf]"), "\"b\".velocity[1]", "inf");
}

#[test]
fn velocity_beyond_the_bound_is_rejected() {
    assert_error(
        &body(&format!("velocity = [{}, 0.0]", 2.0 * MAX_SPEED_M_S)),
        "\"b\".velocity[0]",
        "beyond the documented bound",
    );
}

#[test]
fn nan_and_huge_omega_are_rejected() {
    assert_error(&body("omega = nan"), "\"b\".omega", "NaN");
    assert_error(
        &body(&format!("omega = {}", 2.0 * MAX_OMEGA_RAD_S)),
        "\"b\".omega",
        "beyond",
    );
}

#[test]
fn position_beyond_the_bound_is_rejected() {
    let text = body("").replace("position = [0.1, 0.0]", "position = [1e308, 0.0]");
    assert_error(&text, "\"b\".position[0]", "beyond");
}

#[test]
fn huge_angle_is_rejected() {
    assert_error(&body("angle = 1e300"), "\"b\".angle", "beyond");
    assert_error(&body("angle_deg = 1e308"), "\"b\".angle_deg", "beyond");
}

#[test]
fn polygon_coordinates_beyond_the_bound_are_rejected() {
    let text = format!(
        "{WALL}\n[[body]]\nname = \"p\"\nmass = 1.0\nposition = [0.5, 0.0]\npolygon = [[0.0, 0.0], [1e110, 0.0], [0.0, 1e110]]\n"
    );
    assert_error(&text, "\"p\".polygon[1].x", "beyond");
}

#[test]
fn vertex_count_above_cap_is_a_clear_error() {
    // A regular 50 000-gon of radius 5 cm: today's dense impact matrix for it needed 6.6 GB.
    let n = 50_000;
    let pts: Vec<String> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            format!("[{}, {}]", 0.05 * a.cos(), 0.05 * a.sin())
        })
        .collect();
    let text = format!(
        "{WALL}\n[[body]]\nname = \"p\"\nmass = 1.0\nposition = [0.5, 0.0]\npolygon = [{}]\n",
        pts.join(", ")
    );
    assert_error(&text, "\"p\".polygon", &format!("cap of {MAX_VERTICES}"));
}

#[test]
fn piece_count_above_cap_is_a_clear_error() {
    let piece = "[[0.0, 0.0], [0.01, 0.0], [0.0, 0.01]]";
    let pieces = vec![piece; 1000].join(", ");
    let text = format!("{WALL}\n[[body]]\nname = \"p\"\nkind = \"fixed\"\npieces = [{pieces}]\n");
    assert_error(&text, "\"p\".pieces", "cap of");
}

#[test]
fn box_size_beyond_the_bound_is_rejected() {
    let text = body("").replace("box = [0.04, 0.04]", "box = [0.04, 1e9]");
    assert_error(&text, "\"b\".box[1]", "at most");
}

#[test]
fn mass_density_and_inertia_beyond_their_bounds_are_rejected() {
    assert_error(
        &body("").replace("mass = 0.5", "mass = 1e300"),
        "\"b\".mass",
        "at most",
    );
    assert_error(
        &body("").replace("mass = 0.5", "density = inf"),
        "\"b\".density",
        "at most",
    );
    // density × area beyond the mass bound.
    let big = format!(
        "{WALL}\n[[body]]\nname = \"b\"\ndensity = 1e6\nbox = [100.0, 100.0]\nposition = [200.0, 0.0]\n"
    );
    assert_error(&big, "\"b\".density", "the mass it gives");
    assert_error(&body("inertia = 1e300"), "\"b\".inertia", "at most");
}

#[test]
fn damping_at_or_above_the_explicit_bound_is_rejected() {
    // b·T/m = 2: m = 0.5 kg, T = 2 ms (500 Hz) → b = 500 N·s/m.
    assert_error(&body("damping = 500.0"), "\"b\".damping", "not below 2");
    // Just below is accepted.
    Scene::from_toml(&body("damping = 499.0"), "test.toml", None).expect("b·T/m < 2");
    assert_error(&body("damping = nan"), "\"b\".damping", "non-negative");
}

#[test]
fn r7_rate_above_cap_is_rejected() {
    let e = Scene::from_toml(&repro("r7-rate-1e12.toml"), "r7", None).unwrap_err();
    assert!(e.errors.iter().any(|x| x.field == "world.rate"), "{e}");
    // The override is checked the same way.
    assert_error(
        &body(&format!("[world]\nrate = {}", 2.0 * MAX_RATE_HZ)),
        "world.rate",
        "within",
    );
    assert!(Scene::from_toml(&body(""), "t", Some(f64::NAN)).is_err());
    assert!(Scene::from_toml(&body(""), "t", Some(0.5)).is_err());
}

#[test]
fn r4_grid_count_above_cap_is_a_clear_error() {
    let e = Scene::from_toml(&repro("r4-grid-count.toml"), "r4", None).unwrap_err();
    assert!(
        e.errors
            .iter()
            .any(|x| x.field == "grid[0].count" && x.message.contains(&MAX_BODIES.to_string())),
        "{e}"
    );
}

#[test]
fn pile_count_above_cap_is_a_clear_error() {
    let r = builtin("pile:100000000000", None).expect("pile:N is recognised");
    let e = r.unwrap_err();
    assert!(e.errors.iter().any(|x| x.field.contains("count")), "{e}");
}

fn grid(origin: &str, spacing: &str) -> String {
    format!(
        "{WALL}\n[[grid]]\ncount = 4\ncolumns = 2\norigin = {origin}\nspacing = {spacing}\nbox = [0.05, 0.05]\nmass = 2.0\n"
    )
}

#[test]
fn grid_origin_and_spacing_must_be_finite_and_bounded() {
    assert_error(
        &grid("[nan, 0.5]", "[0.06, 0.06]"),
        "grid[0].origin[0]",
        "NaN",
    );
    assert_error(
        &grid("[0.5, 0.5]", "[0.06, inf]"),
        "grid[0].spacing[1]",
        "inf",
    );
    // Each number in range but the far corner is not.
    assert_error(&grid("[900.0, 0.5]", "[600.0, 0.06]"), "grid[0]", "beyond");
    Scene::from_toml(&grid("[0.5, 0.5]", "[0.06, 0.06]"), "t", None).expect("valid grid");
}

#[test]
fn load_force_and_torque_beyond_their_bounds_are_rejected() {
    let load = |f: &str| format!("{}\n[[load]]\nbody = \"b\"\n{f}\n", body(""));
    assert_error(&load("force = [1e308, 0.0]"), "load[0].force[0]", "beyond");
    assert_error(&load("torque = nan"), "load[0].torque", "NaN");
    assert_error(
        &load("force = [1.0, 0.0]\nprofile = \"sine\"\nfrequency = 1e300"),
        "load[0].frequency",
        "at most",
    );
}

#[test]
fn law_parameters_must_be_finite_and_bounded() {
    assert_error(
        &format!("{}\n[normal]\nmodel = \"paper\"\nkc = 1e300\n", body("")),
        "normal.kc",
        "beyond",
    );
    assert_error(
        &format!("{}\n[normal]\nmodel = \"paper\"\nbc = nan\n", body("")),
        "normal.bc",
        "NaN",
    );
}

#[test]
fn world_margins_and_contact_speeds_are_bounded() {
    let w = |s: &str| format!("{}\n{s}\n", body(""));
    assert_error(
        &w("[world]\ndelta_prox = 1e300"),
        "world.delta_prox",
        "at most",
    );
    assert_error(&w("[world]\ndelta_c = 1e300"), "world.delta_c", "");
    assert_error(&w("[world]\nguard = inf"), "world.guard", "");
    assert_error(
        &w("[world]\nproximity_every = 4000000000"),
        "world.proximity_every",
        "",
    );
    assert_error(&w("[contact]\nv_c = 1e300"), "contact.v_c", "");
    assert_error(&w("[contact]\neps_s = inf"), "contact.eps_s", "");
    assert_error(
        &w("[contact]\nrecollision_speed = 1e300"),
        "contact.recollision_speed",
        "",
    );
}

#[test]
fn r5_overlapping_grid_is_reported_with_names_and_depth() {
    let s = Scene::from_toml(&repro("r5-overlapping-grid.toml"), "r5", None).expect("parses");
    let (found, capped) = s.initial_overlaps();
    // 1000 boxes in rows 0.5 mm apart: far more overlapping pairs than the report's cap.
    assert!(capped && found.len() == haptic2d::scene::overlap::MAX_REPORTED);
    // Staggered rows: boxes two rows apart share a column and are 1 mm apart vertically, so the
    // deepest overlap is 50 − 1 = 49 mm (adjacent rows are shifted by 27 mm: 23 mm).
    let deepest = &found[0];
    assert!(
        (deepest.depth - 0.049).abs() < 1e-9,
        "{deepest} ({} pairs)",
        found.len()
    );
    assert!(deepest.bodies.0.starts_with("box") && deepest.bodies.1.starts_with("box"));
    assert!(found.windows(2).all(|w| w[0].depth >= w[1].depth));
}

#[test]
fn bodies_overlapping_by_5_mm_are_reported_and_resting_contact_is_not() {
    // The wall's face is x = 0; a 4 cm box centred at x = 0.015 overlaps it by 5 mm.
    let overlapping = body("").replace("position = [0.1, 0.0]", "position = [0.015, 0.0]");
    let s = Scene::from_toml(&overlapping, "t", None).unwrap();
    let (found, capped) = s.initial_overlaps();
    assert!(!capped);
    assert_eq!(found.len(), 1);
    assert_eq!(found[0].bodies, ("wall".to_string(), "b".to_string()));
    assert!((found[0].depth - 0.005).abs() < 1e-12, "{}", found[0]);
    // 1 mm (within δ_c = 2 mm) is a resting contact, not an overlap error.
    let resting = body("").replace("position = [0.1, 0.0]", "position = [0.019, 0.0]");
    let s = Scene::from_toml(&resting, "t", None).unwrap();
    assert!(s.initial_overlaps().0.is_empty());
    // The built-in scenes start clean.
    for name in ["box-in-walls", "box-in-walls-tilt", "peg-in-hole", "pile"] {
        let s = builtin(name, None).unwrap().unwrap();
        assert!(s.initial_overlaps().0.is_empty(), "{name}");
    }
}

#[test]
fn allow_initial_overlap_key_is_read() {
    let text = body("").replace("position = [0.1, 0.0]", "position = [0.015, 0.0]");
    let text = format!("[world]\nallow_initial_overlap = true\n{text}");
    let s = Scene::from_toml(&text, "t", None).unwrap();
    assert!(s.allow_initial_overlap);
}

#[test]
fn coordinates_at_the_bound_are_accepted() {
    let text = format!(
        "{WALL}\n[[body]]\nname = \"far\"\nmass = 1.0\nbox = [0.04, 0.04]\nposition = [{MAX_LENGTH_M}, 0.0]\n"
    );
    Scene::from_toml(&text, "t", None).expect("at the bound");
}
