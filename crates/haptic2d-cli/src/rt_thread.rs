//! Runs a haptic loop on its own thread (`haptic2d-rt`, where the real-time priority and the CPU
//! pin are set), borrowing everything its tick touches for the run: `run`, the device side of
//! `run --world`, `teleop --live`.

use std::sync::atomic::AtomicBool;

use haptic2d_rt::{run_loop, LoopConfig, TickControl, TickInfo, TimingSummary};

use crate::exit::Failure;

/// Runs `tick` at `config`'s rate until the duration ends, `stop` is set or the tick stops it;
/// the timing summary. A bad loop setting is bad input (exit 2); a thread that cannot start or
/// panics is a runtime failure (exit 1).
pub fn run_on_rt_thread(
    config: &LoopConfig,
    stop: &AtomicBool,
    tick: impl FnMut(TickInfo) -> TickControl + Send,
) -> Result<TimingSummary, Failure> {
    std::thread::scope(|s| {
        let handle = std::thread::Builder::new()
            .name("haptic2d-rt".into())
            .spawn_scoped(s, || run_loop(config, stop, tick))
            .map_err(|e| Failure::error(format!("cannot start the real-time loop thread: {e}")))?;
        handle
            .join()
            .map_err(|_| Failure::error("the real-time loop thread panicked"))?
            .map_err(Failure::from)
    })
}
