//! The ping (device) side: one world-link message every 1 ms on absolute deadlines (the loop's
//! own clock, haptic2d-rt's `FixedRateClock`: sleep, then spin the last 100 µs), and the
//! bookkeeping of the answers, which arrive on another thread (a UDP receive thread or zenoh's
//! subscriber callback). Nothing in the send loop allocates: the tables are sized before it.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use haptic2d_devices::udp::UdpKey;
use haptic2d_devices::world_link::message::FLAG_BYE;
use haptic2d_devices::world_link::{PortMessage, KIND_TO_DEVICE, KIND_TO_WORLD, PORT_LEN};
use haptic2d_rt::clock::{now_ns, set_timer_slack_ns, FixedRateClock};

use crate::message::{key, to_world, SESSION_RUN, SESSION_WARM};
use crate::slots::Slots;

/// Warm-up messages sent at least (and until the first answer) before the measured run.
pub const WARMUP: u32 = 500;
/// Warm-up messages sent at most without an answer before the run gives up.
const WARMUP_LIMIT: u32 = 10_000;

/// One transport's sending half.
pub trait Wire {
    /// Sends one sealed message; `false` if the transport refused it.
    fn send(&mut self, b: &[u8; PORT_LEN]) -> bool;
}

/// What the ping side records from the answers (shared with the receiving thread).
pub struct Answers {
    key: UdpKey,
    /// Round trip of each measured message, by its sequence number (ns): the answer's arrival
    /// minus the send time it echoes.
    pub rtt: Slots,
    /// The echo side's turnaround for each message (ns): arrival there to its answer's send time.
    pub turnaround: Slots,
    warm: AtomicU64,
    refused: AtomicU64,
}

impl Answers {
    /// Tables for a run of `n` messages.
    pub fn new(n: usize) -> Self {
        Self {
            key: key(),
            rtt: Slots::new(n),
            turnaround: Slots::new(n),
            warm: AtomicU64::new(0),
            refused: AtomicU64::new(0),
        }
    }

    /// Takes one answer `b` that arrived at `now` (CLOCK_MONOTONIC ns): decoded and verified
    /// with the link's codec, its round trip is recorded under the sequence number it echoes.
    #[inline]
    pub fn take(&self, b: &[u8], now: u64) {
        if let Ok(m) = PortMessage::open(&self.key, b, KIND_TO_DEVICE, SESSION_RUN) {
            self.rtt
                .record(m.echo_seq, now.saturating_sub(m.echo_time_ns));
            self.turnaround.record(m.echo_seq, m.echo_age_ns as u64);
        } else if PortMessage::open(&self.key, b, KIND_TO_DEVICE, SESSION_WARM).is_ok() {
            self.warm.fetch_add(1, Ordering::Relaxed);
        } else {
            self.refused.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Answers that failed to decode or verify.
    pub fn refused(&self) -> u64 {
        self.refused.load(Ordering::Relaxed)
    }
}

/// The sending loop's own record.
pub struct PingRun {
    /// Each measured send's lateness behind its deadline (ns).
    pub lateness: Vec<u64>,
    /// Deadlines skipped because the loop was more than a period late.
    pub skipped: u64,
    /// Sends the transport refused.
    pub send_errors: u64,
    /// Warm-up messages sent.
    pub warmup_sent: u32,
}

/// Runs the warm-up, then `n` measured messages at 1 kHz, then waits 300 ms for late answers and
/// says goodbye.
pub fn run(wire: &mut impl Wire, answers: &Answers, n: u32) -> Result<PingRun, String> {
    set_timer_slack_ns(1);
    let key = key();
    let mut buf = [0u8; PORT_LEN];
    let mut clock = FixedRateClock::new(1000.0, Duration::from_micros(100))?;
    let mut out = PingRun {
        lateness: Vec::with_capacity(n as usize),
        skipped: 0,
        send_errors: 0,
        warmup_sent: 0,
    };
    clock.start();
    while out.warmup_sent < WARMUP || answers.warm.load(Ordering::Relaxed) == 0 {
        if out.warmup_sent >= WARMUP_LIMIT {
            return Err(format!("no answer to {WARMUP_LIMIT} warm-up messages"));
        }
        clock.wait();
        out.warmup_sent += 1;
        to_world(out.warmup_sent, 0, now_ns()).seal(&key, KIND_TO_WORLD, SESSION_WARM, &mut buf);
        wire.send(&buf);
        clock.advance(now_ns());
    }
    for seq in 1..=n {
        let wake = clock.wait();
        out.lateness.push(wake.lateness_ns());
        to_world(seq, 0, now_ns()).seal(&key, KIND_TO_WORLD, SESSION_RUN, &mut buf);
        if !wire.send(&buf) {
            out.send_errors += 1;
        }
        out.skipped += clock.advance(now_ns());
    }
    std::thread::sleep(Duration::from_millis(300));
    for _ in 0..3 {
        to_world(n + 1, FLAG_BYE, now_ns()).seal(&key, KIND_TO_WORLD, SESSION_RUN, &mut buf);
        wire.send(&buf);
        std::thread::sleep(Duration::from_millis(10));
    }
    Ok(out)
}
