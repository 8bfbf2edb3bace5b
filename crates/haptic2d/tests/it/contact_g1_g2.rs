//! God-object checks G1 and G2 (§8.5) through the full world pipeline; I5 (invalid impact) too.

use haptic2d::contact::{ContactState, EventKind};
use haptic2d::scene::Scene;

fn scene(text: &str) -> haptic2d::world::World {
    Scene::from_toml(text, "test", None)
        .expect("valid scene")
        .world
}

#[test]
fn g1_entry_point_is_the_analytic_crossing() {
    // A triangle with its lowest vertex at (0.0123, 0.0031) moves at 1 m/s at 45° down-right into the
    // top edge y = 0 of a long floor. It crosses y = 0 at x_c = 0.0123 + 0.0031 = 0.0154.
    let v = std::f64::consts::FRAC_1_SQRT_2;
    let w_text = format!(
        r#"
[world]
rate = 500
[[body]]
name = "floor"
kind = "fixed"
polygon = [[-1.0, -0.1], [1.0, -0.1], [1.0, 0.0], [-1.0, 0.0]]
[[body]]
name = "tri"
mass = 0.5
polygon = [[0.0123, 0.0031], [0.0323, 0.0231], [-0.0077, 0.0231]]
velocity = [{v}, {neg}]
"#,
        neg = -v
    );
    let mut w = scene(&w_text);
    let floor_top_edge = 2u32; // CCW from the bottom-left corner: bottom, right, top, left
    for _ in 0..100 {
        w.step();
        if let Some(rec) = w.contact_records().next() {
            assert_eq!(rec.key.edge, floor_top_edge);
            // The top edge runs from (1, 0) to (−1, 0): s = 1 − x.
            let s_expected = 1.0 - (0.0123 + 0.0031);
            assert!(
                (rec.s_entry - s_expected).abs() < 1e-9,
                "entry {} vs {}",
                rec.s_entry,
                s_expected
            );
            return;
        }
    }
    panic!("no contact was created");
}

#[test]
fn g2_fast_vertex_near_a_corner_gets_the_crossed_edge() {
    // Square B = [−0.05, 0.05]²; a triangle's vertex at (0.049, 0.0515) falls 4 mm per sample
    // (2 m/s at 500 Hz). After one sample it is 2.5 mm below the top edge but only 1 mm from the side
    // edge x = 0.05: it is closer to the side edge, yet it crossed the top edge's line.
    let mut w = scene(
        r#"
[world]
rate = 500
[contact]
impacts = false
[[body]]
name = "square"
kind = "fixed"
box = [0.1, 0.1]
[[body]]
name = "tri"
mass = 0.5
polygon = [[0.049, 0.0515], [0.069, 0.0715], [0.029, 0.0715]]
velocity = [0.0, -2.0]
"#,
    );
    let top = 2u32;
    // Collider 1 is the triangle; its vertex 0 is the falling tip. (The square's corner may also end up
    // inside the triangle's lower edge: that is a separate, legitimate VE contact.)
    for _ in 0..5 {
        w.step();
        if let Some(rec) = w
            .contact_records()
            .find(|r| r.key.vertex_collider == 1 && r.key.vertex == 0)
        {
            assert_eq!(rec.key.edge_collider, 0);
            assert_eq!(
                rec.key.edge, top,
                "assigned edge {} instead of the top edge",
                rec.key.edge
            );
            return;
        }
    }
    panic!("no contact was created");
}

#[test]
fn i5_invalid_impact_goes_straight_to_continuous() {
    // The box moves slower than v_c into the wall: a new contact is Continuous and no impulse acts.
    let mut w = scene(&format!(
        "[world]\nrate = 500\n{}position = [0.0205, 0.0]\nvelocity = [-0.01, 0.0]\n",
        crate::shared::WALL_AND_BOX_TOML
    ));
    let mut created = 0;
    for _ in 0..200 {
        let before = w.bodies[1].vel;
        w.step();
        for e in w.contacts().events() {
            match e.kind {
                EventKind::Created(ContactState::Continuous) => created += 1,
                EventKind::Created(ContactState::Colliding)
                | EventKind::CreatedSimultaneous
                | EventKind::Resolved => {
                    panic!("an invalid impact produced an impulse: {e:?}")
                }
                _ => {}
            }
        }
        // No velocity jump beyond what the held contact force explains.
        assert!((w.bodies[1].vel - before).length() < 0.01);
    }
    assert!(created >= 1, "the slow contact was never created");
}
