//! Starting the demo binary for integration tests.

use haptic2d_test_support::process::Served;
use std::process::{Command, Stdio};

/// A running `haptic2d-view-demo` (killed on drop): its page URL (with `?token=` when commands
/// need one), `host:port`, and the lines it prints after the banner (its timing summary at exit).
pub type Demo = Served;

/// Starts the demo on a free loopback port with extra arguments; waits for its banner.
pub fn start_demo(extra: &[&str]) -> Demo {
    Served::start(
        Command::new(env!("CARGO_BIN_EXE_haptic2d-view-demo"))
            .args(["--bind", "127.0.0.1:0", "--duration", "120"])
            .args(extra)
            .stderr(Stdio::inherit()),
        None,
    )
}
