//! Why a haptic loop's tick stopped it, decided once for every loop that drives a device (`haptic2d
//! run`, `haptic2d study run --observer browser`): a lost reading, a world that diverged, a failed
//! write, the watchdog, the system's own safety latch. Each caller zeroes the torques before it
//! records the reason. Building a reason allocates its message: only on the tick that stops.

use haptic2d::world::World;
use haptic2d_rt::{DeviceError, Fault, FaultKind};

/// Why the loop stopped, when the tick stopped it (the loop also stops at the end of `--duration`
/// or on a signal, with no reason recorded here).
#[derive(Debug)]
pub enum LoopEnd {
    /// A replay's recorded data ended (a clean end).
    ReplayEnded,
    /// The device failed a read or a write, or the watchdog saw it lost.
    DeviceLost(String),
    /// The loop's watchdog tripped (other than a lost device).
    Watchdog(String),
    /// The haptic tick's own safety latch tripped (reported by `system.safety_trip()`).
    SafetyLatch,
    /// The world diverged (MODELS §0.5 step 12): its time (s) and why.
    WorldDiverged(String),
}

impl LoopEnd {
    /// A failed device read: the end of a replay's data, or a lost device.
    pub fn read_failed(e: DeviceError) -> LoopEnd {
        match e {
            DeviceError::EndOfData => LoopEnd::ReplayEnded,
            e => LoopEnd::DeviceLost(e.to_string()),
        }
    }

    /// A world that diverged in this tick stops the loop before its torques reach the device.
    pub fn diverged(world: &World) -> Option<LoopEnd> {
        world.divergence().map(|d| {
            LoopEnd::WorldDiverged(format!(
                "the world diverged at t = {:.4} s: {d}\n    torques were set to zero and latched; fix: lower the contact stiffness or raise the rate (docs/SCENES.md)",
                world.time()
            ))
        })
    }

    /// After the torques were written: the watchdog's verdict `guard`, then the system's latch
    /// (`tripped`).
    pub fn after_write(guard: Result<(), Fault>, tripped: bool) -> Option<LoopEnd> {
        match guard {
            Err(f) => Some(match f.kind {
                FaultKind::DeviceLost => LoopEnd::DeviceLost(f.to_string()),
                _ => LoopEnd::Watchdog(f.to_string()),
            }),
            Ok(()) => tripped.then_some(LoopEnd::SafetyLatch),
        }
    }
}
