//! Deadline polls: a test waits for the condition it needs, never a fixed time and then an
//! assertion (a loaded machine only makes a poll take longer; it makes a sleep too short).

use std::time::{Duration, Instant};

/// How often the polls look (s): short against every deadline the tests use.
const POLL: Duration = Duration::from_millis(2);

/// Polls `cond` until it holds (true) or `deadline` passes (false; `cond` is checked once more at
/// the deadline).
pub fn wait_until(deadline: Instant, mut cond: impl FnMut() -> bool) -> bool {
    loop {
        if cond() {
            return true;
        }
        if Instant::now() >= deadline {
            return cond();
        }
        std::thread::sleep(POLL);
    }
}

/// [`wait_until`] `limit` from now, panicking with `what` if `cond` never held.
pub fn wait_for(what: &str, limit: Duration, cond: impl FnMut() -> bool) {
    assert!(
        wait_until(Instant::now() + limit, cond),
        "timed out after {limit:?} waiting for {what}"
    );
}

/// Whether `cond` holds at every poll for the whole `window` (false at the first poll where it
/// does not): "stays zero" checked throughout, not sampled once after a sleep.
pub fn holds_for(window: Duration, mut cond: impl FnMut() -> bool) -> bool {
    let end = Instant::now() + window;
    loop {
        if !cond() {
            return false;
        }
        if Instant::now() >= end {
            return true;
        }
        std::thread::sleep(POLL);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn wait_until_returns_as_soon_as_the_condition_holds() {
        let n = Cell::new(0);
        let t0 = Instant::now();
        assert!(wait_until(t0 + Duration::from_secs(10), || {
            n.set(n.get() + 1);
            n.get() >= 3
        }));
        assert_eq!(n.get(), 3);
        assert!(t0.elapsed() < Duration::from_secs(5));
    }

    #[test]
    fn wait_until_gives_up_at_the_deadline() {
        let t0 = Instant::now();
        assert!(!wait_until(t0 + Duration::from_millis(20), || false));
        assert!(t0.elapsed() >= Duration::from_millis(20));
    }

    #[test]
    #[should_panic(expected = "waiting for the impossible")]
    fn wait_for_names_what_it_waited_for() {
        wait_for("the impossible", Duration::from_millis(5), || false);
    }

    #[test]
    fn holds_for_fails_at_the_first_poll_that_breaks_the_condition() {
        let n = Cell::new(0);
        assert!(!holds_for(Duration::from_secs(10), || {
            n.set(n.get() + 1);
            n.get() < 3
        }));
        assert_eq!(n.get(), 3);
        assert!(holds_for(Duration::from_millis(10), || true));
    }
}
