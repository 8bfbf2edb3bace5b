//! Haply arguments shared by `run --device haply:…`, `emulate haply` and `device check`: the device
//! file and the port come from the device registry ([`haptic2d_devices::registry::haply`]); the exit
//! codes of a hardware run are the CLI's.

pub use haptic2d_devices::registry::haply::{load_file, port_of, BUILTIN_FILES};
use std::process::ExitCode;

/// Exit codes, the same numbers as the CLI's exit-code table (clean 0, runtime 1, bad input 2,
/// device lost 4).
pub mod exit {
    /// Ran to the end.
    pub const CLEAN: u8 = 0;
    /// Runtime failure.
    pub const ERROR: u8 = 1;
    /// Bad input (nothing ran).
    pub const BAD_INPUT: u8 = 2;
    /// The device was lost.
    pub const DEVICE_LOST: u8 = 4;
}

/// Prints `error: msg` and returns exit code `code`.
pub fn fail(code: u8, msg: &str) -> ExitCode {
    eprintln!("error: {}", msg.trim_end());
    ExitCode::from(code)
}
