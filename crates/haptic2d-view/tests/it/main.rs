//! The live display's integration tests, one binary (issue 37: one link instead of one per file).
//! Each module is one former test file, named after what it checks; run one with
//! `cargo test -p haptic2d-view --test it MODULE::` (e.g. `ws_security::`).

// `no_alloc` counts this thread's allocations (haptic2d-test-support).
haptic2d_test_support::install_counting_allocator!();

/// The machine's cores, for the modules that time them or load them: `scene_trial` reads (its
/// trials run beside each other, as they did in their own binary), `load_viewers` writes (the
/// demo's 1 kHz loop and five viewers load both cores for 8 s). In one binary they would otherwise
/// share the test threads, and a trial timed beside the load test failed its 1.5× margin.
pub static CORES: tokio::sync::RwLock<()> = tokio::sync::RwLock::const_new(());

// Shared set-ups: the demo binary in a child process, the in-process server with a stand-in loop.
mod common;
mod ws;

mod load_viewers;
mod no_alloc;
mod scene_trial;
mod ws_protocol;
mod ws_security;
