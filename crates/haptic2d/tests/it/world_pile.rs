//! The pile scene (scaling): stays finite and bodies do not sink into each other.

use haptic2d::scene::builtin;

#[test]
fn pile_settles_without_deep_interpenetration() {
    // 250 boxes (10 staggered rows of 25), 2 kg each, under 9.81 m/s² into a container; Kc = 1e5 N/m.
    let mut w = builtin("pile:250", None).unwrap().unwrap().world;
    let steps = (3.0 / w.params.dt) as usize;
    for _ in 0..steps {
        w.step();
    }
    for b in &w.bodies {
        assert!(
            b.pose.pos.is_finite()
                && b.pose.angle.is_finite()
                && b.vel.is_finite()
                && b.omega.is_finite(),
            "{} is not finite",
            b.name
        );
    }
    // Equilibrium penetration: the whole weight rests on the 25 bottom boxes' 2 floor corners each:
    // δ_eq = N·m·g / (50·Kc) = 250·2·9.81 / (50·1e5) ≈ 0.98 mm.
    let kc = 1.0e5;
    let delta_eq = 250.0 * 2.0 * 9.81 / (50.0 * kc);
    let deepest = w.contact_records().map(|c| -c.d[0]).fold(0.0, f64::max);
    assert!(
        deepest <= 2.0 * delta_eq,
        "deepest penetration {deepest} m vs 2·δ_eq = {} m",
        2.0 * delta_eq
    );
    // And the pile has come (nearly) to rest.
    let ke = w.ledger().kinetic;
    assert!(ke < 1.0, "kinetic energy after 3 s: {ke} J");
}

/// pile:5000 (200 rows) started up to 11.2 m high inside 3 m walls, so its upper rows fell out of
/// the container (found by the bench in session 5): every box of every pile size starts between
/// the walls and below their top.
#[test]
fn every_pile_starts_inside_its_container() {
    for n in [1, 25, 1000, 1001, 5000, 19_999] {
        let w = builtin(&format!("pile:{n}"), None).unwrap().unwrap().world;
        let container = w
            .bodies
            .iter()
            .position(|b| b.name == "container")
            .expect("the container");
        // The container's highest point: the tops of its walls.
        let (mut top, mut left, mut right) = (f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for c in w.colliders.iter().filter(|c| c.body == container) {
            top = top.max(c.aabb.max.y);
            left = left.min(c.aabb.min.x);
            right = right.max(c.aabb.max.x);
        }
        let boxes: Vec<_> = w.bodies.iter().filter(|b| b.is_dynamic()).collect();
        assert_eq!(boxes.len(), n);
        for b in boxes {
            let p = b.pose.pos;
            assert!(
                p.y + 0.025 < top && p.x > left + 0.1 && p.x < right - 0.1,
                "pile:{n}: {} starts at ({:.3}, {:.3}) m, container top {top:.3} m",
                b.name,
                p.x,
                p.y
            );
        }
    }
}

/// pile:5000 as 200 rows of 25 dropped its top rows from 11.2 m, and two boxes ended up inside
/// each other on landing (issue 17): a pile of more than 1000 boxes keeps 40 rows and widens its
/// container instead, so no box starts higher than pile:1000's.
#[test]
fn large_piles_keep_forty_rows_and_widen_the_container() {
    let highest = |n: usize| {
        let w = builtin(&format!("pile:{n}"), None).unwrap().unwrap().world;
        w.bodies
            .iter()
            .filter(|b| b.is_dynamic())
            .map(|b| b.pose.pos.y)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let reference = highest(1000);
    for n in [1001, 5000, 19_999] {
        let h = highest(n);
        assert!(
            h <= reference + 1e-12,
            "pile:{n} starts up to {h} m, pile:1000 {reference} m"
        );
    }
}
