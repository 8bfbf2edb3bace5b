//! Ctrl-C handling: turn SIGINT (and SIGTERM) into a stop flag.
//!
//! The first Ctrl-C sets the flag; the loop finishes its tick and returns,
//! then the caller drains the logger, zeroes the torques and prints the
//! summary, so nothing is lost. A second Ctrl-C exits at once with status 130
//! (for a loop that is stuck), at the cost of unflushed logs.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Installs the process-wide Ctrl-C handler and returns the stop flag it
/// sets. Can be installed once per process; a second call returns an error.
pub fn install_ctrlc_stop() -> Result<Arc<AtomicBool>, String> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    })
    .map_err(|e| format!("cannot install the Ctrl-C handler: {e}"))?;
    Ok(stop)
}
