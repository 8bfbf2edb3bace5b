//! The echo (world) side's handling of one received message, the same for every transport:
//! decode and verify it (size, MAC, session, finite numbers), record its arrival, and re-encode
//! the world's answer. Called from the UDP receive loop or from zenoh's subscriber callback; no
//! lock, no allocation.

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::time::Duration;

use haptic2d_devices::udp::auth::Drop2;
use haptic2d_devices::udp::UdpKey;
use haptic2d_devices::world_link::message::FLAG_BYE;
use haptic2d_devices::world_link::{PortMessage, KIND_TO_DEVICE, KIND_TO_WORLD, PORT_LEN};
use haptic2d_rt::clock::now_ns;

use crate::message::{key, to_device, SESSION_RUN, SESSION_WARM};
use crate::slots::{intervals, Slots};
use crate::summary::{row, summarize, HEADER};

/// The echo side's state, shared with the receiving thread or callback.
pub struct Echo {
    key: UdpKey,
    /// Arrival time (CLOCK_MONOTONIC ns) of each measured message, by sequence number.
    arrivals: Slots,
    /// The world's own message counter.
    seq: AtomicU32,
    /// Arrival of the newest message of either session (ns; 0: none yet).
    last_ns: AtomicU64,
    /// Refused datagrams (bad MAC, wrong session, malformed).
    refused: AtomicU64,
    /// The ping side said goodbye.
    bye: AtomicBool,
}

impl Echo {
    /// An echo for a run of `n` messages.
    pub fn new(n: usize) -> Self {
        Self {
            key: key(),
            arrivals: Slots::new(n),
            seq: AtomicU32::new(0),
            last_ns: AtomicU64::new(0),
            refused: AtomicU64::new(0),
            bye: AtomicBool::new(false),
        }
    }

    /// Handles `b`, which arrived at `arrived_ns`: on an authentic message, writes the answer
    /// into `out` and returns `true` (send it); `false` for a goodbye or a refused datagram.
    #[inline]
    pub fn answer(&self, b: &[u8], arrived_ns: u64, out: &mut [u8; PORT_LEN]) -> bool {
        let opened = match PortMessage::open(&self.key, b, KIND_TO_WORLD, SESSION_RUN) {
            Ok(m) => Ok((m, SESSION_RUN)),
            Err(Drop2::WrongSession) => {
                PortMessage::open(&self.key, b, KIND_TO_WORLD, SESSION_WARM)
                    .map(|m| (m, SESSION_WARM))
            }
            Err(e) => Err(e),
        };
        let Ok((m, session)) = opened else {
            self.refused.fetch_add(1, Ordering::Relaxed);
            return false;
        };
        self.last_ns.store(arrived_ns, Ordering::Relaxed);
        if session == SESSION_RUN {
            if m.flags & FLAG_BYE != 0 {
                self.bye.store(true, Ordering::Relaxed);
                return false;
            }
            self.arrivals.record(m.seq, arrived_ns);
        }
        let seq = self.seq.fetch_add(1, Ordering::Relaxed) + 1;
        let now = now_ns();
        to_device(&m, seq, now, now.saturating_sub(arrived_ns)).seal(
            &self.key,
            KIND_TO_DEVICE,
            session,
            out,
        );
        true
    }

    /// Waits until the ping side says goodbye, or nothing arrived for `idle` after a first
    /// message, or `limit` passed; returns whether the goodbye came.
    pub fn wait_done(&self, idle: Duration, limit: Duration) -> bool {
        let t0 = now_ns();
        loop {
            std::thread::sleep(Duration::from_millis(10));
            let now = now_ns();
            let last = self.last_ns.load(Ordering::Relaxed);
            if self.bye.load(Ordering::Relaxed)
                || (last > 0 && now.saturating_sub(last) > idle.as_nanos() as u64)
                || now - t0 > limit.as_nanos() as u64
            {
                return self.bye.load(Ordering::Relaxed);
            }
        }
    }

    /// The echo side's report: messages received, refused, and the one-way arrival intervals.
    pub fn report(&self) -> String {
        let t = self.arrivals.recorded();
        let iv = summarize(&mut intervals(&t));
        format!(
            "  echo side: {} measured messages received, {} datagrams refused, goodbye {}\n{HEADER}\n{}",
            t.len(),
            self.refused.load(Ordering::Relaxed),
            if self.bye.load(Ordering::Relaxed) { "received" } else { "missing" },
            row("echo arrival interval", iv)
        )
    }
}
