//! Exit statuses of `haptic2d`: one documented code per way a command can end.
//!
//! The table is printed by `haptic2d --help` ([`EXIT_CODES_HELP`]) and documented in
//! docs/SCENES.md ("Exit codes"). A command returns `Ok(status)` when it ran to an end it reports
//! itself (summary printed: clean, a safety stop, a lost device, an interruption, an energy excess
//! under `--strict`, a divergence), and `Err(Failure)` when it could not run (the message is printed
//! as `error: …`).

use std::process::ExitCode;

/// How a command ended. The discriminant is the process exit code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Ran to the end (duration over, or the replay's data ended).
    Clean = 0,
    /// A runtime failure: an output file could not be written, a thread failed, a figure did not
    /// reproduce under `reproduce --strict`.
    Error = 1,
    /// Bad input: a scene file, device file or option was rejected (clap's own usage errors also
    /// exit 2). Nothing ran.
    BadInput = 2,
    /// A safety stop: the tick's safety latch or the loop's watchdog tripped and zeroed the torques.
    SafetyStop = 3,
    /// The device was lost (it stopped answering, or a read/write failed).
    DeviceLost = 4,
    /// `simulate --strict`: the energy excess exceeded the §13.1 bound.
    EnergyExcess = 5,
    /// `simulate`, `run`: the world diverged (a non-finite state or one beyond the documented
    /// magnitudes; MODELS §0.5 step 12).
    Diverged = 6,
    /// Interrupted by SIGINT (Ctrl-C) or SIGTERM: the run stopped early, logs complete.
    Interrupted = 130,
}

impl Status {
    /// The process exit code.
    pub fn code(self) -> u8 {
        self as u8
    }
}

impl From<Status> for ExitCode {
    fn from(s: Status) -> Self {
        ExitCode::from(s.code())
    }
}

/// The exit-code table for `haptic2d --help` (clap's `after_help`).
pub const EXIT_CODES_HELP: &str = "\
Exit codes:
  0    clean: ran to the end
  1    runtime failure (an output could not be written; reproduce --strict: a claim failed)
  2    bad input: a scene file, device file or option was rejected (nothing ran)
  3    safety stop: the safety latch or the watchdog zeroed the torques (run)
  4    the device was lost (run)
  5    energy excess above the §13.1 bound (simulate --strict; always a warning otherwise)
  6    the simulation diverged (simulate; run: after zeroing the torques)
  130  interrupted by SIGINT or SIGTERM (run, simulate: summary printed, logs end on a whole row;
       log convert: no output left behind)
  141  (shell status) ended by SIGPIPE: the reader of the output closed it, e.g. `| head -1`
       (run: after zeroing the torques and ending its log; simulate --out: after ending the file)";

/// A command that could not run: the status to exit with and the message to print.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// The exit status.
    pub status: Status,
    /// What went wrong and how to fix it.
    pub message: String,
}

impl Failure {
    /// A runtime failure (exit 1).
    pub fn error(message: impl Into<String>) -> Self {
        Self {
            status: Status::Error,
            message: message.into(),
        }
    }
}

/// A plain message is bad input (exit 2): option, scene and device-file validation all report
/// errors as strings; runtime failures use [`Failure::error`].
impl From<String> for Failure {
    fn from(message: String) -> Self {
        Self {
            status: Status::BadInput,
            message,
        }
    }
}

impl From<&str> for Failure {
    fn from(message: &str) -> Self {
        Self::from(message.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_status_has_a_distinct_code_listed_in_the_help_table() {
        let all = [
            Status::Clean,
            Status::Error,
            Status::BadInput,
            Status::SafetyStop,
            Status::DeviceLost,
            Status::EnergyExcess,
            Status::Diverged,
            Status::Interrupted,
        ];
        let mut codes: Vec<u8> = all.iter().map(|s| s.code()).collect();
        codes.sort_unstable();
        codes.dedup();
        assert_eq!(codes.len(), all.len());
        for c in codes {
            assert!(
                EXIT_CODES_HELP.contains(&format!("\n  {c} ")),
                "exit code {c} missing from the help table"
            );
        }
    }
}
