//! Timing world steps in windows, shared by the world-step benches: criterion's `iter_custom` asks
//! for `iters` steps; they run in windows of at most `window` steps, each from a fresh copy of the
//! state `w0` (a world stepped for the whole measurement would drift far from the state measured).
//! Only the steps are timed, not the copies.

use haptic2d::world::World;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Wall time of `iters` steps of `w`, restarted from `w0` every `window` steps.
pub fn windowed_steps(w: &mut World, w0: &World, iters: u64, window: u64) -> Duration {
    let mut total = Duration::ZERO;
    let mut left = iters;
    while left > 0 {
        w.clone_from(w0);
        let n = left.min(window);
        let t0 = Instant::now();
        for _ in 0..n {
            black_box(&mut *w).step();
        }
        total += t0.elapsed();
        left -= n;
    }
    total
}
