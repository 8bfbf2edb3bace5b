//! The Inverse3 driver's exchange on the tick — the loop's `DeviceIo` calls, the plane point read
//! and the plane force written — allocates nothing once open (issue 15): the shared
//! counting allocator counts per thread, so the client thread and the emulator allocate freely, off
//! the tick.

use crate::inverse3_support::*;

use std::time::Instant;

use haptic2d_devices::inverse3::{Emulator3Config, Hand3};
use haptic2d_rt::DeviceIo;

use haptic2d_test_support::alloc::allocations;

#[test]
fn the_exchange_allocates_nothing_once_open() {
    let emu = emulator(Emulator3Config {
        hand: Some(Hand3::hold([0.0; 3], 300.0, 5.0)),
        ..Emulator3Config::default()
    });
    let file = file_for(&emu, 200.0);
    let mut dev = open(&file);
    let t0 = Instant::now();
    for k in 0..50 {
        dev.read_encoders().unwrap();
        dev.write_torques(&[0.01, -0.01, 0.0, 0.0]).unwrap();
        wait_tick(t0, k + 1);
    }
    let mut reads = 0;
    let mut allocs = 0;
    for k in 50..550 {
        let before = allocations();
        let q = dev.read_encoders();
        let w = dev.write_torques(&[0.01, -0.01, 0.0, 0.0]);
        allocs += allocations() - before;
        q.unwrap();
        w.unwrap();
        reads += 1;
        wait_tick(t0, k + 1);
    }
    assert_eq!(reads, 500);
    assert_eq!(allocs, 0, "allocations on the tick's exchange");
    assert!(
        dev.sample().seq > 100,
        "states kept arriving: {}",
        dev.sample().seq
    );
}
