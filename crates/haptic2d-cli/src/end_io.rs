//! The I/O of the device at one end of a link — the simulated twin (its plant advanced one period
//! per tick, optionally gripped by a scripted hand) or a real device of the registry — and its
//! sensing through the device's [`DeviceEnd`]: the device side of `run --world`, the slave of
//! `serve-world --device`, either end of `teleop --live`. Neither method allocates, locks or
//! prints.

use std::sync::Arc;

use haptic2d::device::linalg::{V3, V4};
use haptic2d::device::DeviceEstimate;
use haptic2d::haptic::safety_stage::TickClock;
use haptic2d::haptic::DeviceEnd;
use haptic2d_rt::clock::now_ns;
use haptic2d_rt::{DeviceError, DeviceIo, SharedTarget, SimIo};

use crate::push_arg::Push;

/// A simulated grip's scripted push: the push, the target the grip follows, the start pose.
pub type SimPush = (Push, Arc<SharedTarget>, V3);

/// The I/O of an end.
// One per end, built once and never moved in the loop: the size difference costs nothing.
#[allow(clippy::large_enum_variant)]
pub enum EndIo {
    /// The simulated twin, and the scripted push of its grip if any.
    Sim {
        /// The plant and its hand.
        io: SimIo,
        /// `--push`, moving the grip's target every tick.
        push: Option<SimPush>,
    },
    /// A real device, opened.
    Real(Box<dyn DeviceIo + Send>),
}

impl EndIo {
    /// The device.
    pub fn io(&mut self) -> &mut dyn DeviceIo {
        match self {
            EndIo::Sim { io, .. } => io,
            EndIo::Real(io) => io.as_mut(),
        }
    }

    /// The simulated twin (its plant's true state, its hand); `None` for a real device.
    pub fn sim(&self) -> Option<&SimIo> {
        match self {
            EndIo::Sim { io, .. } => Some(io),
            EndIo::Real(_) => None,
        }
    }

    /// Reads the device at loop time `t` (s), first moving a simulated grip's target; the reading
    /// and how long a real device's read waited (ns: the driver's wait, bounded by its own
    /// timeout, which the stall check leaves out as `run` does; 0 for the simulated twin).
    pub fn read(&mut self, t: f64) -> (Result<V4, DeviceError>, u64) {
        match self {
            EndIo::Sim { io, push } => {
                if let Some((p, target, start)) = push {
                    target.set(p.target(start, t));
                }
                (io.read_encoders(), 0)
            }
            EndIo::Real(io) => {
                let t0 = now_ns();
                let q = io.read_encoders();
                (q, now_ns().saturating_sub(t0))
            }
        }
    }

    /// Steps 0–2 of `end` on the reading `q` taken `elapsed` s after the previous tick's, `wait`
    /// s of which waiting for devices ([`DeviceEnd::sense`]). The simulated plant advances one
    /// period per tick: its signals use one period `dt` (the run stays deterministic when
    /// nothing stalls) while the stall check sees the real interval; a real device's signals use
    /// the measured interval.
    pub fn sense(
        &self,
        end: &mut DeviceEnd,
        at: TickClock,
        q: &V4,
        (elapsed, wait, dt): (f64, f64, f64),
    ) -> Option<DeviceEstimate> {
        match self {
            EndIo::Sim { .. } => {
                end.check_stall(at, elapsed, wait);
                end.sense(at, q, dt, wait)
            }
            EndIo::Real(_) => end.sense(at, q, elapsed, wait),
        }
    }
}
