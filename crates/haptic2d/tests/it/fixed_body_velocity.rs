//! A fixed body never moves. A velocity given to one through the public fields used to make its
//! surfaces move in the contacts' eyes: 0.5 m/s on a settled pile's container fed 0.018 J into
//! the boxes within 20 ms (found in session 12). The world now keeps fixed bodies at rest.

use haptic2d::geom::Vec2;
use haptic2d::scene::builtin;

#[test]
fn a_fixed_body_given_a_velocity_feeds_no_energy_in() {
    let mut world = builtin("pile:20", None).unwrap().unwrap().world;
    for _ in 0..700 {
        world.step();
    }
    let kinetic = |w: &haptic2d::world::World| -> f64 {
        w.bodies
            .iter()
            .filter(|b| b.is_dynamic())
            .map(|b| b.kinetic_energy())
            .sum()
    };
    let settled = kinetic(&world);
    assert!(settled < 1e-12, "the pile is at rest: {settled} J");
    let container = world.bodies.iter().position(|b| !b.is_dynamic()).unwrap();
    let pose = world.bodies[container].pose;
    world.bodies[container].vel = Vec2::new(0.3, 0.5);
    world.bodies[container].omega = 2.0;
    for _ in 0..200 {
        world.step();
        let e = kinetic(&world);
        assert!(
            e <= settled + 1e-12,
            "{e} J after the container was given a velocity"
        );
    }
    let c = &world.bodies[container];
    assert_eq!((c.pose, c.vel, c.omega), (pose, Vec2::ZERO, 0.0));
}
