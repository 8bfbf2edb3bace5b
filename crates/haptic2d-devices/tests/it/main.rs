//! The device drivers' integration tests, one binary (issue 37: one link instead of one per file).
//! Each module is one former test file, named after what it checks; run one with
//! `cargo test -p haptic2d-devices --test it MODULE::` (e.g. `driver_safety::`). The Inverse3
//! modules build with the driver's feature only: `cargo test -p haptic2d-devices --features
//! inverse3 --test it inverse3_`.
//!
//! `udp_interrupted.rs` stays its own binary: its SIGUSR1 handler is process-wide and it counts
//! three signals sent 10 ms apart to its waiting thread. Beside the other modules (two test
//! threads on a 2-core machine) its signal count was wrong in 1 suite run of 13, likely two sends
//! merged while the thread waited for a core (standard signals do not queue); alone it passes.

// The no-allocation modules count this thread's allocations (haptic2d-test-support).
haptic2d_test_support::install_counting_allocator!();

// Shared set-ups: the emulated board on a pseudo-terminal, the no-allocation check of an
// exchange, the UDP echo device, the UDP driver against a reference device, the Inverse3 emulator.
mod exchange_alloc;
#[cfg(feature = "inverse3")]
mod inverse3_support;
mod support;
mod udp_echo;
mod udp_reference;

mod closed_loop_pty;
mod codec_vectors;
mod device_files;
mod driver_safety;
mod firmware_native;
mod haply_buttons;
mod haply_no_alloc;
mod identify_emulator;
#[cfg(feature = "inverse3")]
mod inverse3_closed_loop;
#[cfg(feature = "inverse3")]
mod inverse3_no_alloc;
#[cfg(feature = "inverse3")]
mod inverse3_safety;
#[cfg(feature = "inverse3")]
mod inverse3_session;
#[cfg(feature = "inverse3")]
mod inverse3_wire;
mod udp_auth;
mod udp_auth_devices;
mod udp_exchange;
mod udp_no_alloc;
mod world_link_no_alloc;
