//! The CLI's end-to-end tests, one binary (issue 37: one link instead of one per file). Each module is one
//! former test file, named after what it checks; run one with
//! `cargo test -p haptic2d-cli --test it MODULE::`.

#[path = "../common/mod.rs"]
mod common;

mod browser_e2e;
mod cli;
mod cli_exit;
mod cli_firmware;
mod cli_fuzz;
mod cli_haply;
mod cli_help;
mod cli_identify;
mod cli_inverse3;
mod cli_pipe;
mod cli_run;
mod cli_signals;
mod cli_stability;
mod cli_study;
mod cli_teleop;
mod cli_udp;
mod device_safety;
mod log_fuzz;
mod mcap_log;
