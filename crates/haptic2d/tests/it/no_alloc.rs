//! DESIGN §1 / issue: once warmed up, `World::step` performs no heap allocation. A counting global
//! allocator proves it for the built-in scenes.

use crate::counting_alloc;
use counting_alloc::allocations;
use haptic2d::scene::builtin;

/// Allocations during `measure` samples of `scene` after `warm` samples of warm-up.
fn step_allocations(scene: &str, warm: usize, measure: usize) -> u64 {
    let mut w = builtin(scene, None).unwrap().unwrap().world;
    for _ in 0..warm {
        w.step();
    }
    let before = allocations();
    for _ in 0..measure {
        w.step();
    }
    allocations() - before
}

#[test]
fn world_step_does_not_allocate_once_warm() {
    // box-in-walls: the window covers the later bounces, releases and re-creations of contacts.
    assert_eq!(
        step_allocations("box-in-walls", 50, 2500),
        0,
        "box-in-walls"
    );
    assert_eq!(
        step_allocations("box-in-walls-tilt", 50, 2500),
        0,
        "box-in-walls-tilt"
    );
    assert_eq!(step_allocations("peg-in-hole", 50, 2500), 0, "peg-in-hole");
    assert_eq!(step_allocations("pile:25", 200, 500), 0, "pile:25");
}

/// The chain damper's patches (a few loaded contacts changed: rows become holes, new rows fill
/// holes or are appended) allocate nothing either: its builds leave room for what the patches may
/// append before the next build. pile:1000 after its fall (1 s), through 0.5 s of the contact
/// changes of a settling pile.
#[test]
fn chain_damper_patches_do_not_allocate() {
    let mut w = builtin("pile:1000", None).unwrap().unwrap().world;
    for _ in 0..1000 {
        w.step();
    }
    let before = allocations();
    let mut patches = 0;
    for _ in 0..500 {
        w.step();
        patches += w.chain_damper().last_patched as usize;
    }
    assert_eq!(allocations() - before, 0, "{patches} patches");
    assert!(
        patches >= 3,
        "only {patches} patches: the window tests too little"
    );
}

/// A landing pile's collapse grows the contact stage's and the chain damper's per-record buffers
/// sample after sample (pile:1000: about 250 allocations, up to 1.1 MB at once), which inside
/// `run`'s real-time loop are allocations in its ticks. Given room first, as `run` and
/// `serve-world` do before their loops (`reserve_contacts(contact_room())`), pile:1000's fall,
/// collapse and settling (1.2 s) allocate nothing, and every body ends bit for bit where it ends
/// without the room.
#[test]
fn a_landing_pile_allocates_nothing_once_given_room_for_its_contacts() {
    let run = |room: bool| {
        let mut w = builtin("pile:1000", None).unwrap().unwrap().world;
        if room {
            let records = w.contact_room();
            w.reserve_contacts(records);
        }
        w.prime();
        let before = allocations();
        for _ in 0..1200 {
            w.step();
        }
        (allocations() - before, w)
    };
    let (grown, plain) = run(false);
    let (with_room, roomy) = run(true);
    assert!(grown > 0, "the landing allocated nothing even without room");
    assert_eq!(with_room, 0, "allocations with room ({grown} without)");
    assert!(roomy.contacts().contact_count() > 3000);
    for (a, b) in plain.bodies.iter().zip(&roomy.bodies) {
        let bits = |b: &haptic2d::body::Body| b.state().map(f64::to_bits);
        assert_eq!(bits(a), bits(b), "{}", a.name);
    }
}
