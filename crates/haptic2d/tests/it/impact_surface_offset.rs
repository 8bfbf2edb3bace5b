//! `[contact] impact_surface_offset = true` (issue 16, docs/MODELS.md §E.7) keeps the worlds
//! passive: the offset only lowers a record's normal force, so the ledger excess stays within the
//! issue's 1 mJ bound on the polygon drop of issue 10 (r8, impacts and friction on) and on a
//! 100-box pile, and the pile still settles without deep interpenetration (the offset adds at most
//! the detection depth `|C0|·T` to a resting record).

use haptic2d::scene::{builtin, Scene};
use haptic2d::world::World;

const R8: &str = include_str!("../repro/r8-polygon-drop-energy.toml");

/// Passivity bound on the ledger excess (J), as the acceptance: 1 mJ.
const EXCESS_TOL: f64 = 1e-3;

/// Steps `w` for `seconds`; the largest ledger excess (J).
fn max_excess(w: &mut World, seconds: f64) -> f64 {
    let mut m = f64::NEG_INFINITY;
    for _ in 0..(seconds / w.params.dt).round() as usize {
        w.step();
        m = m.max(w.ledger().excess());
    }
    m
}

#[test]
fn polygon_drop_with_the_surface_offset_creates_no_energy() {
    for on in [false, true] {
        let mut w = Scene::from_toml(R8, "r8", None).expect("valid scene").world;
        w.params.contact.impact_surface_offset = on;
        w.prime();
        let e = max_excess(&mut w, 3.0);
        eprintln!("r8, impact_surface_offset = {on}: max excess {e:.3e} J");
        assert!(e <= EXCESS_TOL, "offset {on}: gained {e} J");
    }
}

#[test]
fn pile_with_the_surface_offset_is_passive_and_settles() {
    let mut w = builtin("pile:100", None).unwrap().unwrap().world;
    w.params.contact.impact_surface_offset = true;
    w.prime();
    let e = max_excess(&mut w, 3.0);
    let deepest = w.contact_records().map(|c| -c.d[0]).fold(0.0, f64::max);
    let ke = w.ledger().kinetic;
    eprintln!(
        "pile:100 with the offset: max excess {e:.3e} J, deepest {deepest:.3e} m, KE {ke:.3e} J"
    );
    assert!(e <= EXCESS_TOL, "pile gained {e} J");
    assert!(w
        .bodies
        .iter()
        .all(|b| b.pose.pos.is_finite() && b.vel.is_finite()));
    // The resting depth `δ_eq = N·m·g/(n_c·Kc)` (well below 1 mm here, as in `world_pile.rs`) plus
    // at most one detection depth `|C0|·T` per landing (a few mm at the fall speeds of the pile):
    // 1 cm is above both, and far below a box sunk into another.
    assert!(deepest < 0.01, "deepest penetration {deepest} m");
    assert!(ke < 1.0, "kinetic energy after 3 s: {ke} J");
}
