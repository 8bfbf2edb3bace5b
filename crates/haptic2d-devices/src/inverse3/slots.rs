//! The wait-free exchange between the haptic loop and the service client's thread: two triple
//! buffers (the `triple_buffer` crate the telemetry and the display already use), one for the
//! newest device state (client → loop), one for the newest force command (loop → client), and a
//! few atomics for the client's status. Reading or writing a slot is a copy and a few atomic
//! operations: it never blocks, allocates or locks.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

/// The newest state of the Inverse3 as the client saw it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inverse3Sample {
    /// 1, 2, … per new state from the service; 0 = none yet.
    pub seq: u64,
    /// When the client received it (ns, `haptic2d_rt::clock::now_ns`).
    pub rx_ns: u64,
    /// Cursor position (m, device frame).
    pub position: [f64; 3],
    /// Cursor velocity (m/s, device frame): the service's, else differenced by the client.
    pub velocity: [f64; 3],
    /// The handle's (VerseGrip's) orientation quaternion `(w, x, y, z)`, if the service reports one.
    pub orientation: Option<[f64; 4]>,
    /// The service reports the device ready (`status.ready`).
    pub ready: bool,
}

/// The newest command of the loop.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ForceCommand {
    /// The plane force (N, world x and y axes), already clamped by the driver.
    pub planar: [f64; 2],
    /// Forces on: false before the first valid state and after a zero command.
    pub enable: bool,
    /// The loop latched (a zero command): zero force from now on, whatever follows.
    pub latched: bool,
}

/// The client's status, shared with the driver.
#[derive(Debug, Default)]
pub struct ClientStatus {
    /// Set by the driver: send a zero force and close.
    pub stop: AtomicBool,
    /// Set by the client when it stopped on its own (the connection failed); `reason` says why.
    pub closed: AtomicBool,
    /// Why the client closed (set once, before `closed`).
    pub reason: OnceLock<String>,
}

impl ClientStatus {
    /// Records why the client closed, then raises `closed`.
    pub fn close(&self, reason: String) {
        let _ = self.reason.set(reason);
        self.closed.store(true, Ordering::Release);
    }

    /// Why the client closed, if it did.
    #[inline]
    pub fn closed_reason(&self) -> Option<&str> {
        if self.closed.load(Ordering::Acquire) {
            Some(self.reason.get().map_or("closed", |s| s.as_str()))
        } else {
            None
        }
    }
}
