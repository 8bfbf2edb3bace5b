//! Crossing corners (issue 35 item 4, docs/MODELS.md §9.5b): two convex polygons whose corners
//! have passed through each other's edges are held, and pushed apart, along their separating
//! axis, passively.
//!
//! Before the clip contacts (`collide/clip.rs`, `contact/manager/clip.rs`) a pair with no vertex
//! inside the other polygon had no contact candidate at all, and a pair whose vertices sat on the
//! other polygon's side faces had records whose normals held none of the load: the bodies sank
//! into each other while every record stayed shallow.

use haptic2d::collide::{CLIP_MARGIN, DEFAULT_DELTA_C};

const STACK: &str = include_str!("../repro/stack-5-polygons-interpenetrate.toml");

use crate::shared::primed_world as world;

/// Contact stiffness (N/m) of the shelf scene (the paper's law, per corner).
const KC: f64 = 20_000.0;
/// The diamond: a square of side `SIDE` (m) turned 45°, of mass `MASS` (kg), pushed down by
/// `PUSH` (N) besides its weight.
const SIDE: f64 = 0.04;
const MASS: f64 = 2.0;
const PUSH: f64 = 20.0;
/// The shelf: fixed, 0.2 m wide and `SHELF` (m) thick, its top at y = 0.
const SHELF: f64 = 0.001;
/// How far below the shelf's bottom the diamond's lowest corner starts (m).
const BELOW: f64 = 0.0005;

/// A diamond whose lowest corner has gone right through a thin shelf: no vertex of either body is
/// inside the other (the shelf's corners are 0.1 m away, the diamond's corner is below the shelf),
/// the overlap `D_0 = SHELF + BELOW` = 3 mm is a trapezoid of crossed edges.
fn shelf_scene(impacts: bool) -> String {
    let h = SIDE / std::f64::consts::SQRT_2;
    let y = -SHELF - BELOW + h;
    format!(
        "name = \"crossed-shelf\"\n[world]\nrate = 1000\n[contact]\nimpacts = {impacts}\n\
         restitution = 0.0\n[normal]\nmodel = \"paper\"\nkc = {KC}\nbc = 20.0\n\
         [friction]\nmodel = \"none\"\n\
         [[body]]\nname = \"shelf\"\nkind = \"fixed\"\n\
         polygon = [[-0.1, -{SHELF}], [0.1, -{SHELF}], [0.1, 0.0], [-0.1, 0.0]]\n\
         [[body]]\nname = \"diamond\"\ndensity = {}\n\
         polygon = [[0.0, -{h}], [{h}, 0.0], [0.0, {h}], [-{h}, 0.0]]\n\
         position = [0.0, {y}]\n\
         [[load]]\nbody = \"diamond\"\nforce = [0.0, {}]\n",
        MASS / (SIDE * SIDE),
        -(PUSH + MASS * 9.81)
    )
}

/// The crossed shelf, pushed together by `F = PUSH + m·g` = 39.62 N.
///
/// Derived bound: the pair's separating axis is the shelf's top normal (the diamond rises by
/// `D_0` = 1.5 mm to clear it; every other axis needs ≥ 20 mm). Its clip pair is the diamond's
/// lowest corner against the shelf's top, depth `D_0`; as a record at `t = 0` it stores
/// `½·K·D_0²` (counted in the initial energy). Sinking a further `x` along the axis, the load does
/// `F·x` and the spring then stores `½·K·(D_0 + x)²`; passivity (damping only takes energy out)
/// gives `½·K·(D_0 + x)² ≤ ½·K·D_0² + F·x`, i.e. `x ≤ 2·(F/K − D_0)` = 0.96 mm. So the overlap
/// never exceeds `D_0 + max(0, 2·(F/K − D_0))` = 2.463 mm (plus 1e-6 m of round-off), and the
/// diamond ends at rest on its corner on top of the shelf, compressed by `F/K` = 1.981 mm, not
/// through it. Energy: the ledger's excess stays below the passivity suite's 1 mJ (the
/// semi-implicit step's energy measure swings by `O(K·T²/m)` of the stored 22.5 mJ). Before the
/// clip contacts the pair had no candidate (no vertex inside) and the diamond fell through the
/// shelf: overlap 28.8 mm, corner 29 mm below the shelf's top.
#[test]
fn crossed_corner_through_a_shelf_is_pushed_out_along_the_separating_axis() {
    let force = PUSH + MASS * 9.81;
    let d0 = SHELF + BELOW;
    let bound = d0 + (2.0 * (force / KC - d0)).max(0.0) + 1e-6;
    for impacts in [false, true] {
        let mut w = world(&shelf_scene(impacts), "crossed-shelf");
        let start = w.max_overlap().depth;
        assert!(
            (start - d0).abs() < 1e-9,
            "the scene starts crossed by D_0 = {d0} m, got {start}"
        );
        let mut worst = start;
        let mut excess = w.ledger().excess();
        for _ in 0..2000 {
            w.step();
            worst = worst.max(w.max_overlap().depth);
            excess = excess.max(w.ledger().excess());
        }
        let d = w.body_index("diamond").unwrap();
        let lowest = w.bodies[d].pose.pos.y - SIDE / std::f64::consts::SQRT_2;
        println!(
            "crossed shelf (impacts {impacts}): largest overlap {:.4} mm (bound {:.4} mm), lowest corner at {:.4} mm, excess {excess:.3e} J",
            worst * 1e3,
            bound * 1e3,
            lowest * 1e3
        );
        assert!(
            worst <= bound,
            "impacts {impacts}: overlap {worst} m beyond the derived bound {bound} m"
        );
        assert!(excess <= 1e-3, "impacts {impacts}: {excess} J created");
        // At rest on the shelf's top, compressed by F/K (1.981 mm), within 0.1 mm.
        assert!(
            (lowest + force / KC).abs() < 1e-4,
            "impacts {impacts}: the corner rests at {lowest} m, expected −F/K = {} m",
            -force / KC
        );
    }
}

/// `stack-5-polygons-interpenetrate.toml` (issue 35: 272 mm² shared by two polygons while 1.7 mm
/// was reported): at every sample the largest overlap of two bodies is within the clip margin
/// (`CLIP_MARGIN·δ_c` = 1 mm) plus one sample's relative motion of the deepest contact record:
/// nothing sinks unseen. And its true overlap is bounded by the load: the stack's whole weight
/// `W = Σ m·g` = 119.8 N on one corner spring, suddenly applied (the bodies start at rest,
/// touching), compresses it at most `2·W/K` = 12.0 mm (the static figure on the floor's two
/// corners of `p0` is `W/(2K)` = 3.0 mm). Measured on branch `corners`: largest overlap 2.385 mm
/// ("walls" and "p3" at 0.532 s), equal to the deepest record; 1.203 mm at 2 s.
#[test]
fn stack_5_polygons_overlap_is_seen_by_its_records_and_bounded_by_its_weight() {
    let mut w = world(STACK, "stack-5");
    let k = 20_000.0;
    let weight: f64 = w
        .bodies
        .iter()
        .filter(|b| b.is_dynamic())
        .map(|b| 9.81 / b.inv_mass)
        .sum();
    assert!((weight - 119.82).abs() < 0.1, "Σ m·g = {weight} N");
    let dt = w.params.dt;
    let mut worst = 0.0f64;
    let mut worst_hidden = f64::NEG_INFINITY;
    for _ in 0..2000 {
        // One sample's relative motion bound: twice the fastest body's speed (any point).
        let fastest = w
            .bodies
            .iter()
            .filter(|b| b.is_dynamic())
            .map(|b| b.vel.length() + b.omega.abs() * 0.03)
            .fold(0.0, f64::max);
        w.step();
        let o = w.max_overlap().depth;
        let deepest = w.contact_records().map(|c| -c.d[0]).fold(0.0, f64::max);
        worst = worst.max(o);
        worst_hidden =
            worst_hidden.max(o - deepest - CLIP_MARGIN * DEFAULT_DELTA_C - 2.0 * fastest * dt);
    }
    println!(
        "stack-5: largest overlap {:.3} mm (bound 2W/K = {:.3} mm); worst hidden overlap beyond margin + motion {:.3e} m",
        worst * 1e3,
        2.0 * weight / k * 1e3,
        worst_hidden
    );
    assert!(
        worst_hidden <= 1e-9,
        "an overlap {worst_hidden} m deeper than the records saw"
    );
    assert!(worst <= 2.0 * weight / k, "overlap {worst} m beyond 2W/K");
}

/// Depth (m) of the plate's left end under the wall slab, and its top below the floor's top.
const UNDER: f64 = 0.003;
const PLATE_TOP: f64 = -0.0005;

/// An L-shaped fixed body of two pieces (a floor slab, its top at `y = 0`, and a wall slab on its
/// left end, its face at `x = 0`), and a thin plate (60 × 4 mm, 0.2 kg) sunk just under the
/// floor's top with its left end `UNDER` under the wall slab, i.e. inside the floor slab where
/// the floor's top edge is covered by the wall slab's bottom (a seam).
fn joint_scene() -> String {
    let (x0, x1) = (-UNDER, 0.06 - UNDER);
    let (y0, y1) = (PLATE_TOP - 0.004, PLATE_TOP);
    format!(
        "name = \"slab-joint\"\n[world]\nrate = 1000\n[contact]\nimpacts = false\n\
         [normal]\nmodel = \"paper\"\nkc = {KC}\nbc = 20.0\n[friction]\nmodel = \"none\"\n\
         [[body]]\nname = \"walls\"\nkind = \"fixed\"\npieces = [\
         [[-0.1, -0.1], [0.5, -0.1], [0.5, 0.0], [-0.1, 0.0]], \
         [[-0.1, 0.0], [0.0, 0.0], [0.0, 0.3], [-0.1, 0.3]]]\n\
         [[body]]\nname = \"plate\"\ndensity = {}\n\
         polygon = [[{x0}, {y0}], [{x1}, {y0}], [{x1}, {y1}], [{x0}, {y1}]]\n\
         [[load]]\nbody = \"*\"\nforce = [0.0, -9.81]\nper_mass = true\n",
        0.2 / (0.06 * 0.004),
    )
}

/// A corner inside the floor slab *under* the wall slab is at the body's concave corner: the
/// body's surfaces there are the floor's exposed top (above it) and the wall slab's face (beside
/// it, `UNDER` = 3 mm away), so it is held by both, and pushed out of the corner, not only up
/// into the wall slab. The floor's top edge is only partly covered (a surface), the wall slab's
/// bottom a whole seam that faces it (`Collider::across`, reach = the floor's 100 mm): the wall
/// slab's face holds vertices across that seam within the reach (docs/MODELS.md §9.5a).
///
/// Derived: both left corners of the plate are `UNDER` behind the wall face's line `x = 0`
/// (normal `+x`), inside the floor slab; so at `t = 0` each has a record on the wall slab's
/// face with `n = (1, 0)` and `d = −UNDER`, which pushes the plate out from under the wall: within
/// 0.2 s no part of it is left under the wall slab (`x ≥ 0`). Before, the wall slab gave the
/// corners no candidate (they are outside it, across its bottom seam): the floor's top pushed
/// them up, into the wall slab, where they arrived "found inside" (no stored depth) and stayed
/// (the long passivity suite's seeds 11574, 10010 and 11996 hid 31.0, 12.1 and 10.6 mm beyond
/// their allowance this way).
#[test]
fn corner_under_a_wall_slab_is_held_by_the_wall_face_and_pushed_out() {
    let mut w = world(&joint_scene(), "slab-joint");
    let wall = 1u32; // collider of the wall slab (second piece)
    let plate = 2u32;
    let face: Vec<_> = w
        .contact_records()
        .filter(|c| c.key.vertex_collider == plate && c.key.edge_collider == wall)
        .map(|c| (c.key.vertex, c.n, c.d[0]))
        .collect();
    assert_eq!(
        face.len(),
        2,
        "both left corners on the wall slab: {face:?}"
    );
    for &(v, n, d) in &face {
        assert!(v == 0 || v == 3, "a left corner: {v}");
        assert!(
            (n.x - 1.0).abs() < 1e-12 && n.y.abs() < 1e-12,
            "the face's normal: {n:?}"
        );
        assert!((d + UNDER).abs() < 1e-9, "depth UNDER: {d}");
    }
    for _ in 0..200 {
        w.step();
    }
    let min_x = w.colliders[plate as usize]
        .world_vertices()
        .iter()
        .map(|p| p.x)
        .fold(f64::INFINITY, f64::min);
    assert!(
        min_x >= 0.0,
        "the plate is out from under the wall: min x {min_x}"
    );
    assert!(
        w.ledger().excess() < 1e-3,
        "passive: {}",
        w.ledger().excess()
    );
}
