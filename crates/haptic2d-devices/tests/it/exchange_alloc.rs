//! The no-allocation check of a driver's exchange, shared by the Haply and UDP modules: warm up,
//! then count this thread's allocations over the measured exchanges (the counting allocator of
//! `main.rs` counts per thread, so an emulator's or a device's thread allocates freely).

use haptic2d_rt::DeviceIo;
use haptic2d_test_support::alloc::allocations;

/// The torques every exchange writes (N·m): small, opposite on the two motors.
pub const TAU: [f64; 4] = [0.01, -0.01, 0.0, 0.0];

/// Allocations made by `ticks` exchanges of `dev` (read the encoders, write [`TAU`], then
/// `after_each(dev)`), after 20 exchanges of warm-up that are not counted.
pub fn exchange_allocations<D: DeviceIo>(
    dev: &mut D,
    ticks: usize,
    mut after_each: impl FnMut(&mut D),
) -> u64 {
    for _ in 0..20 {
        dev.read_encoders().unwrap();
        dev.write_torques(&TAU).unwrap();
    }
    let before = allocations();
    for _ in 0..ticks {
        dev.read_encoders().unwrap();
        dev.write_torques(&TAU).unwrap();
        after_each(dev);
    }
    allocations() - before
}
