//! [`DrainThread`]: the handle of a logger thread that drains a telemetry ring until told to stop
//! (the CSV logger, the MCAP logger, the study's trial logger). Stopping it — by
//! [`finish`](DrainThread::finish) or by dropping it — sets the stop flag, wakes the thread and
//! joins it; the thread then drains what is left and writes its file out.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

/// A running drain thread: its stop flag and its join handle. The thread's body returns its report
/// `R` or an error message.
pub struct DrainThread<R> {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<R, String>>>,
}

impl<R> DrainThread<R> {
    /// Starts a thread named `name` running `body` with the stop flag it polls. `what` names the
    /// thread in the error message, e.g. `logger` → "cannot start the logger thread: …".
    pub fn spawn<F>(name: &str, what: &str, body: F) -> Result<Self, String>
    where
        F: FnOnce(Arc<AtomicBool>) -> Result<R, String> + Send + 'static,
        R: Send + 'static,
    {
        let stop = Arc::new(AtomicBool::new(false));
        let s = stop.clone();
        let thread = std::thread::Builder::new()
            .name(name.into())
            .spawn(move || body(s))
            .map_err(|e| format!("cannot start the {what} thread: {e}"))?;
        Ok(Self {
            stop,
            thread: Some(thread),
        })
    }

    /// Sets the stop flag, wakes the thread and waits for its report. `what` names it in the
    /// error of a thread that panicked ("the {what} thread panicked").
    pub fn finish(mut self, what: &str) -> Result<R, String> {
        self.stop.store(true, Ordering::Release);
        match self.thread.take() {
            Some(t) => {
                t.thread().unpark();
                t.join()
                    .map_err(|_| format!("the {what} thread panicked"))?
            }
            None => Err(format!("the {what} was already finished")),
        }
    }
}

impl<R> Drop for DrainThread<R> {
    /// A thread dropped without [`finish`](DrainThread::finish) is stopped and joined all the
    /// same (its report or error is then lost).
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            t.thread().unpark();
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU32;

    /// A body that counts its polls until the flag is set, parking in between.
    fn counting(polls: Arc<AtomicU32>) -> impl FnOnce(Arc<AtomicBool>) -> Result<u32, String> {
        move |stop| {
            while !stop.load(Ordering::Acquire) {
                polls.fetch_add(1, Ordering::Relaxed);
                std::thread::park_timeout(std::time::Duration::from_millis(50));
            }
            Ok(7)
        }
    }

    #[test]
    fn finish_stops_the_thread_and_returns_its_report() {
        let polls = Arc::new(AtomicU32::new(0));
        let t = DrainThread::spawn("test-drain", "test", counting(polls.clone())).unwrap();
        assert_eq!(t.finish("test"), Ok(7));
    }

    #[test]
    fn a_panicking_thread_is_reported_by_name() {
        let t: DrainThread<u32> =
            DrainThread::spawn("test-drain", "test", |_| panic!("boom")).unwrap();
        assert_eq!(
            t.finish("trial logger"),
            Err("the trial logger thread panicked".to_string())
        );
    }

    #[test]
    fn dropping_the_handle_stops_and_joins_the_thread() {
        let polls = Arc::new(AtomicU32::new(0));
        let stopped = Arc::new(AtomicBool::new(false));
        let (p, s) = (polls.clone(), stopped.clone());
        let t = DrainThread::spawn("test-drain", "test", move |stop| {
            let r = counting(p)(stop);
            s.store(true, Ordering::Release);
            r
        })
        .unwrap();
        drop(t);
        // Joined: the body has returned by the time drop does.
        assert!(stopped.load(Ordering::Acquire));
    }
}
