//! [`DeviceSystem::prime`]: the world's first contact stage run before the real-time loop (issue
//! 42: the loop's first tick was its slowest, building every contact from nothing) changes nothing
//! the ticks compute.

use haptic2d::device::HandModel;
use haptic2d::haptic::{DeviceInTheLoop, DeviceSystem, HapticConfig, HapticSystem};
use haptic2d::scene::builtin;

/// Box-in-walls with the box 0.5 mm into the left wall and moving into it at 0.3 m/s, so that
/// sample 0 creates contacts and resolves an impact.
fn striking_world() -> haptic2d::world::World {
    let mut world = builtin("box-in-walls", None).unwrap().unwrap().world;
    let b = world.body_index("box").unwrap();
    world.bodies[b].pose.pos.x = 0.02 - 0.0005;
    world.bodies[b].vel.x = -0.3;
    world
}

fn primed(system: HapticSystem) -> HapticSystem {
    let mut s = DeviceSystem::Twin(system);
    s.prime();
    match s {
        DeviceSystem::Twin(s) => s,
        _ => unreachable!("a twin stays a twin"),
    }
}

#[test]
fn a_primed_system_ticks_bit_for_bit_as_an_unprimed_one() {
    let config = HapticConfig::default();
    let system = HapticSystem::new(striking_world(), &config).expect("valid system");
    let hand = HandModel::Constant {
        wrench: [-1.0, 0.5, 0.0],
    };
    let mut plain = DeviceInTheLoop::new(system.clone(), hand, 4, true).unwrap();
    let mut early = DeviceInTheLoop::new(primed(system), hand, 4, true).unwrap();
    let w = early.system.world();
    assert!(
        w.contacts().contact_count() > 0,
        "sample 0 made contacts before the first tick"
    );
    assert_eq!(w.time(), 0.0, "priming does not advance the world");
    assert_eq!(plain.system.world().contacts().contact_count(), 0);
    let (a, fa) = plain.run(600);
    let (b, fb) = early.run(600);
    assert!(fa.is_none() && fb.is_none(), "{fa:?} {fb:?}");
    // Debug strings compare every number bit for bit that `{:?}` prints exactly (f64's Debug
    // round-trips), NaNs included.
    assert_eq!(format!("{a:?}"), format!("{b:?}"));
    let bodies = |d: &DeviceInTheLoop| format!("{:?}", d.system.world().bodies);
    assert_eq!(bodies(&plain), bodies(&early));
    assert_eq!(
        format!("{:?}", plain.system.world().ledger()),
        format!("{:?}", early.system.world().ledger())
    );
}
