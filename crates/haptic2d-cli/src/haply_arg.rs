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

/// How a Haply command (`device check`, `device identify`, `emulate`) ended: its exit code, or
/// an exit code and the message to print as `error: …`.
pub type Outcome = Result<u8, (u8, String)>;

/// The process exit of an [`Outcome`]: its code, or `error: msg` printed ([`fail`]) and its code.
pub fn exit_code(r: Outcome) -> ExitCode {
    match r {
        Ok(code) => ExitCode::from(code),
        Err((code, msg)) => fail(code, &msg),
    }
}

/// The control period of the bench-top commands `device check` and `device identify` (1 ms).
pub const BENCH_PERIOD: std::time::Duration = std::time::Duration::from_millis(1);
