//! The loop side of the display does not allocate in steady state (DESIGN §1): capturing and
//! publishing a frame (bodies, contacts, device linkage, energies, timing), polling commands and
//! recording timing, on the loop's thread.

use haptic2d::device::{DeviceParams, TwinKinematics};
use haptic2d::geom::Vec2;
use haptic2d::scene::builtin;
use haptic2d_test_support::alloc::allocations;
use haptic2d_view::{Frame, FrameInputs, LiveTiming, ViewHub};

/// The box is pushed into the left wall (contacts appear), a frame is published every tick (60×
/// the real rate, the worst case), with the device linkage: after a first pass (the world's own
/// buffers grow), a second pass allocates nothing.
#[test]
fn publishing_frames_and_polling_commands_do_not_allocate() {
    let scene = builtin("box-in-walls", Some(1000.0)).unwrap().unwrap();
    let mut world = scene.world;
    let kin = TwinKinematics::new(&DeviceParams::default());
    let (mut hub, _server_end) = ViewHub::new(&Frame::for_world(&world), 1000.0).unwrap();
    let mut timing = LiveTiming::new(1000.0, 0.05).unwrap();
    let mut pass = |world: &mut haptic2d::world::World, k0: u64| {
        let before = allocations();
        let mut contacts = 0;
        for k in k0..k0 + 600 {
            while hub.poll_command().is_some() {}
            world.begin_step();
            world.set_drive(1, Vec2::new(-3.0, 0.0), 0.001);
            world.finish_step();
            let t = k as f64 * 1e-3;
            let inputs = FrameInputs {
                slave: Some(1),
                hand_target: [-0.01, 0.0, 0.0],
                device: Some((&kin, [0.0, 0.14, 0.1])),
                timing: timing.snapshot(),
                controller: "coupling",
                ..FrameInputs::default()
            };
            // Publish regardless of viewers (frame_due needs one): the capture path is what counts.
            hub.publish_frame(t, world, &inputs);
            timing.record(k * 1_000_000, 1_000, 5_000, 0);
            contacts += world.contacts().contact_count();
        }
        (allocations() - before, contacts)
    };
    let (_, warm_contacts) = pass(&mut world, 0);
    assert!(warm_contacts > 0, "the box reached the wall");
    let (allocs, contacts) = pass(&mut world, 600);
    assert!(contacts > 0);
    assert_eq!(allocs, 0, "allocations in steady state");
}
