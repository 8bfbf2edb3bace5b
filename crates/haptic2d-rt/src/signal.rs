//! SIGINT (Ctrl-C) and SIGTERM handling: both turn into one stop flag.
//!
//! The first signal sets the flag; the loop (or `simulate`'s step loop) finishes its tick and
//! returns, then the caller drains the logger, zeroes the torques and prints the summary, so every
//! log ends on a whole row and nothing that reached the ring is lost. A second signal exits at once
//! with status [`SECOND_SIGNAL_EXIT`] (for a loop that is stuck), at the cost of unflushed logs.
//!
//! SIGTERM needs the `termination` feature of `ctrlc` (enabled in this crate's Cargo.toml); without
//! it the default action would kill the process mid-row.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Exit status when a second SIGINT/SIGTERM arrives before the first one was honoured (the same
/// "interrupted" code the CLI uses for a clean interrupted run).
pub const SECOND_SIGNAL_EXIT: i32 = 130;

/// Installs the process-wide SIGINT/SIGTERM handler and returns the stop flag it sets. Can be
/// installed once per process; a second call returns an error.
pub fn install_stop_signals() -> Result<Arc<AtomicBool>, String> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(SECOND_SIGNAL_EXIT);
        }
    })
    .map_err(|e| format!("cannot install the SIGINT/SIGTERM handler: {e}"))?;
    Ok(stop)
}

/// The former name of [`install_stop_signals`] (it too handles SIGTERM).
pub fn install_ctrlc_stop() -> Result<Arc<AtomicBool>, String> {
    install_stop_signals()
}
