//! Helpers shared by the CLI end-to-end tests.

use std::process::{Command, Output};

/// Runs the `haptic2d` binary built for these tests with `args` and waits for it.
pub fn haptic2d(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_haptic2d"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Standard output and standard error of a finished run, concatenated.
pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}
