//! The real-time crate's integration tests, one binary (issue 37: one link instead of one per
//! file). Each module is one former test file, named after what it checks; run one with
//! `cargo test -p haptic2d-rt --test it MODULE::` (e.g. `watchdog::`).

// `log_fuzz` bounds the largest single allocation of its thread (haptic2d-test-support).
haptic2d_test_support::install_counting_allocator!();

mod csv_logger;
mod log_fuzz;
mod loop_runner;
mod replay_device;
mod timing_stats;
mod watchdog;
