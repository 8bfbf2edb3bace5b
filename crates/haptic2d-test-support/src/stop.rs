//! A stop flag raised from another thread after a delay: the Ctrl-C of a loop test (the delay is
//! what the test is about, a stop mid-run; a test that waits for a condition polls with
//! [`crate::wait`] instead).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// Sets `flag` after `delay`, on a thread of its own; joining the handle waits until it is set.
pub fn raise_after(flag: &Arc<AtomicBool>, delay: Duration) -> JoinHandle<()> {
    let flag = flag.clone();
    std::thread::spawn(move || {
        std::thread::sleep(delay);
        flag.store(true, Ordering::Relaxed);
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    #[test]
    fn raise_after_sets_the_flag_no_sooner_than_the_delay() {
        let flag = Arc::new(AtomicBool::new(false));
        let t0 = Instant::now();
        let setter = raise_after(&flag, Duration::from_millis(30));
        while !flag.load(Ordering::Relaxed) {
            std::thread::yield_now();
        }
        assert!(t0.elapsed() >= Duration::from_millis(30));
        setter.join().unwrap();
    }
}
