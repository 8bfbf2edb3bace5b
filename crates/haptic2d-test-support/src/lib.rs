//! Dev-only helpers shared by the integration tests of the haptic2d crates (issue 37, item 6).
//! Only ever a `[dev-dependencies]` entry; std only, so that it adds nothing to a test build.
//!
//! - [`alloc`]: the counting global allocator of the no-allocation tests;
//! - [`wait`]: deadline polls (`wait_until`, `wait_for`, `holds_for`) instead of sleep-then-assert;
//! - [`process`]: children killed on drop, first-line and banner handshakes, bounded waits;
//! - [`stop`]: a stop flag raised from another thread after a delay (a loop stopped mid-run);
//! - [`files`]: temp copies of the shipped device files with edits;
//! - [`firmware`]: the native build of the board firmware, started on its pseudo-terminal;
//! - [`udp_device`]: the UDP reference devices (Python, C) in processes of their own;
//! - [`browser`]: the headless Chromium + playwright-core launcher of the browser tests.

pub mod alloc;
pub mod browser;
pub mod files;
pub mod firmware;
pub mod process;
pub mod stop;
pub mod udp_device;
pub mod wait;

pub use wait::{holds_for, wait_for, wait_until};
