//! The Haply transport: frames over any `Read + Write` stream (a serial port, a pseudo-terminal, an
//! in-memory mock), with read timeouts and detection of a stream out of step. It **never
//! resynchronises**: the stock firmware sets its encoders at every setup (docs/DEVICES.md §1.3.3),
//! so a re-setup mid-run would re-zero them wherever the handle is and silently shift the
//! calibration. A stream out of step is an error; the driver zeroes the torques and ends the run.
//!
//! ```text
//! open:       drain → identify [0x03] (≤ 100 ms; silence = stock firmware)
//!             → [0x04][watchdog_ms] (haptic2d firmware only) → reset → setup → write(0…) → reply
//! per tick:   send_write(τ) … read_reply() → angles        (deadline: sent + timeout)
//! out of step (first byte ≠ id, short reply, garbage)  → HaplyError::OutOfStep
//! nothing at all within the timeout                   → HaplyError::Lost (who was late, if known)
//! ```
//!
//! The stream's own read timeout should be short (the serial opener uses ≤ 1 ms): the transport
//! loops until its deadline. No allocation on the success path.

use std::fmt;
use std::io::{ErrorKind, Read, Write};
use std::time::{Duration, Instant};

use super::codec::{
    decode_identity, decode_reply, encode_identify, encode_reset, encode_set_watchdog,
    encode_setup, encode_write, BoardSetup, CodecError, FirmwareIdentity, Reply, IDENTIFY_LEN,
    PORTS, REPLY_MAX_LEN, SETUP_MAX_LEN, WRITE_MAX_LEN,
};

/// A transport failure; mapped to `DeviceError::Lost`/`Io` at the `DeviceIo` boundary.
#[derive(Clone, Debug, PartialEq)]
pub enum HaplyError {
    /// No reply (or not all of it) within the timeout, or the port closed.
    Lost(String),
    /// The stream is out of step: a byte was lost or added on the line.
    OutOfStep(CodecError),
    /// A read or write failed.
    Io(String),
    /// A bad setup or argument (programming or configuration error).
    Config(String),
}

impl fmt::Display for HaplyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            HaplyError::Lost(s) => write!(f, "{s}"),
            HaplyError::OutOfStep(e) => write!(
                f,
                "the byte stream is out of step ({e}): a byte was lost or added on the line"
            ),
            HaplyError::Io(s) => write!(f, "{s}"),
            HaplyError::Config(s) => write!(f, "{s}"),
        }
    }
}

impl std::error::Error for HaplyError {}

/// Frames to and from one board over `S`.
#[derive(Debug)]
pub struct Transport<S> {
    stream: S,
    setup: BoardSetup,
    timeout: Duration,
    tx: [u8; SETUP_MAX_LEN],
    rx: [u8; REPLY_MAX_LEN],
    sent_at: Option<Instant>,
}

/// How the host spent a wait that timed out: to tell a late device from a late host.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaitTiming {
    /// From the write to the first read attempt (s): the host's own delay before it waited.
    pub start_delay: f64,
    /// The longest gap between two read attempts while waiting (s): the host not running.
    pub max_gap: f64,
    /// The whole wait, write to giving up (s).
    pub total: f64,
}

impl WaitTiming {
    /// True when the host itself was not running for at least half of the timeout `timeout` (s):
    /// then the late reply may be the host's fault (a loaded machine), not the device's.
    pub fn host_late(&self, timeout: f64) -> bool {
        self.start_delay.max(self.max_gap) >= 0.5 * timeout
    }
}

impl<S: Read + Write> Transport<S> {
    /// A transport to the board configured by `setup` over `stream`, waiting at most `timeout` for
    /// each reply (from the moment its write was sent). Nothing is sent yet.
    pub fn from_stream(
        stream: S,
        setup: BoardSetup,
        timeout: Duration,
    ) -> Result<Self, HaplyError> {
        setup
            .validate()
            .map_err(|e| HaplyError::Config(e.to_string()))?;
        if timeout.is_zero() {
            return Err(HaplyError::Config("the reply timeout must be > 0".into()));
        }
        Ok(Self {
            stream,
            setup,
            timeout,
            tx: [0; SETUP_MAX_LEN],
            rx: [0; REPLY_MAX_LEN],
            sent_at: None,
        })
    }

    /// Changes the reply timeout (must be > 0; zero is ignored).
    pub fn set_timeout(&mut self, timeout: Duration) {
        if !timeout.is_zero() {
            self.timeout = timeout;
        }
    }

    /// The reply timeout.
    pub fn timeout(&self) -> Duration {
        self.timeout
    }

    /// The board set-up.
    pub fn setup(&self) -> &BoardSetup {
        &self.setup
    }

    /// The stream (e.g. to inspect a mock).
    pub fn stream(&self) -> &S {
        &self.stream
    }

    /// True while a write waits for its reply.
    pub fn pending(&self) -> bool {
        self.sent_at.is_some()
    }

    /// Sends haptic2d firmware's identify query and waits up to `wait` for its 10-byte answer.
    /// `Ok(None)`: nothing came back, a stock firmware (which discards the byte). Bytes that are not
    /// an identify frame are an error.
    pub fn identify(&mut self, wait: Duration) -> Result<Option<FirmwareIdentity>, HaplyError> {
        let n = encode_identify(&mut self.tx).map_err(cfg)?;
        write_all(&mut self.stream, &self.tx[..n])?;
        self.read_identity(wait)
    }

    /// Sets haptic2d firmware's watchdog to `ms` (1–1000) and returns the identify frame the board
    /// answers with. Only for a board that answered [`identify`](Self::identify): a stock board
    /// would read the two argument bytes as commands.
    pub fn set_watchdog(
        &mut self,
        ms: u16,
        wait: Duration,
    ) -> Result<FirmwareIdentity, HaplyError> {
        let n = encode_set_watchdog(ms, &mut self.tx).map_err(cfg)?;
        write_all(&mut self.stream, &self.tx[..n])?;
        match self.read_identity(wait)? {
            Some(id) => Ok(id),
            None => Err(HaplyError::Lost(format!(
                "no answer to the watchdog setting within {:.0} ms",
                wait.as_secs_f64() * 1e3
            ))),
        }
    }

    fn read_identity(&mut self, wait: Duration) -> Result<Option<FirmwareIdentity>, HaplyError> {
        let deadline = Instant::now() + wait;
        let mut got = 0;
        while got < IDENTIFY_LEN && Instant::now() < deadline {
            match self.stream.read(&mut self.rx[got..IDENTIFY_LEN]) {
                Ok(n) => got += n,
                Err(e) if transient(&e) => {}
                Err(e) => {
                    return Err(HaplyError::Lost(format!(
                        "the port failed while waiting for the identify answer ({e})"
                    )))
                }
            }
        }
        if got == 0 {
            return Ok(None);
        }
        decode_identity(&self.rx[..got])
            .map(Some)
            .map_err(HaplyError::OutOfStep)
    }

    /// Reset + setup + a zero-torque write, and its reply: the board is configured and answering.
    /// Call it once, with the handle at the rest pose (docs/DEVICES.md §7).
    pub fn handshake(&mut self) -> Result<Reply, HaplyError> {
        let n = encode_reset(self.setup.id, &mut self.tx).map_err(cfg)?;
        write_all(&mut self.stream, &self.tx[..n])?;
        let n = encode_setup(&self.setup, &mut self.tx).map_err(cfg)?;
        write_all(&mut self.stream, &self.tx[..n])?;
        self.send_write(&[0.0; PORTS][..self.setup.n_motors()])?;
        self.read_reply()
    }

    /// Sends a write with `torques` (N·m, one per used motor port in ascending port order; clamp
    /// them before). A reply must be read before the next write.
    pub fn send_write(&mut self, torques: &[f32]) -> Result<(), HaplyError> {
        if torques.len() != self.setup.n_motors() {
            return Err(HaplyError::Config(format!(
                "{} torques for {} motors",
                torques.len(),
                self.setup.n_motors()
            )));
        }
        let pwm = [0u8; PORTS];
        let mut buf = [0u8; WRITE_MAX_LEN];
        let n = encode_write(
            self.setup.id,
            &pwm[..self.setup.n_pwm as usize],
            torques,
            &mut buf,
        )
        .map_err(cfg)?;
        write_all(&mut self.stream, &buf[..n])?;
        self.sent_at = Some(Instant::now());
        Ok(())
    }

    /// Write then read: one exchange.
    pub fn exchange(&mut self, torques: &[f32]) -> Result<Reply, HaplyError> {
        self.send_write(torques)?;
        self.read_reply()
    }

    /// Reads the reply to the last write, waiting until `timeout` after it was sent. A reply that
    /// is out of step is an error ([`HaplyError::OutOfStep`]); nothing is re-sent.
    pub fn read_reply(&mut self) -> Result<Reply, HaplyError> {
        let Some(sent) = self.sent_at.take() else {
            return Err(HaplyError::Config("read_reply without a write".into()));
        };
        let len = self.setup.reply_len();
        let deadline = sent + self.timeout;
        let mut got = 0;
        let mut last = Instant::now();
        let start_delay = last.duration_since(sent);
        let mut max_gap = Duration::ZERO;
        while got < len {
            // The first byte tells at once whether the stream is in step.
            if got >= 1 && self.rx[0] != self.setup.id {
                break;
            }
            match self.stream.read(&mut self.rx[got..len]) {
                Ok(n) => got += n,
                Err(e) if transient(&e) => {}
                Err(e) => {
                    return Err(HaplyError::Lost(format!(
                        "the port failed while waiting for a reply ({e}): unplugged or closed"
                    )))
                }
            }
            let now = Instant::now();
            max_gap = max_gap.max(now.duration_since(last));
            last = now;
            if got < len && now >= deadline {
                if got == 0 {
                    let timing = WaitTiming {
                        start_delay: start_delay.as_secs_f64(),
                        max_gap: max_gap.as_secs_f64(),
                        total: now.duration_since(sent).as_secs_f64(),
                    };
                    return Err(HaplyError::Lost(no_reply_message(self.timeout, &timing)));
                }
                break;
            }
        }
        decode_reply(
            self.setup.id,
            self.setup.n_sensors as usize,
            self.setup.n_encoders(),
            &self.rx[..got],
        )
        .map_err(HaplyError::OutOfStep)
    }

    /// Discards whatever is waiting on the input: until `quiet` passes without a byte, at most
    /// `max`. For the start, before identify (a previous host may have left a reply behind).
    pub fn drain(&mut self, quiet: Duration, max: Duration) {
        let start = Instant::now();
        let mut last_byte = start;
        let mut buf = [0u8; 64];
        while start.elapsed() < max && last_byte.elapsed() < quiet {
            match self.stream.read(&mut buf) {
                Ok(0) => {}
                Ok(_) => last_byte = Instant::now(),
                Err(e) if transient(&e) => {}
                Err(_) => break,
            }
        }
    }
}

/// The message of a reply that did not come: who was late, when the timing tells.
fn no_reply_message(timeout: Duration, t: &WaitTiming) -> String {
    let ms = |s: f64| s * 1e3;
    let to = timeout.as_secs_f64();
    if t.host_late(to) {
        format!(
            "no reply within {:.1} ms of the write, but the host itself was not running for {:.1} ms of that wait (it began waiting {:.1} ms after the write): the host was late, not necessarily the device — a loaded machine; run with real-time priority or raise board.timeout_periods",
            ms(to),
            ms(t.start_delay.max(t.max_gap)),
            ms(t.start_delay)
        )
    } else {
        format!(
            "no reply within {:.1} ms of the write (the host waited {:.1} ms and was running throughout): the device was late",
            ms(to),
            ms(t.total)
        )
    }
}

fn transient(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
    )
}

fn cfg(e: CodecError) -> HaplyError {
    HaplyError::Config(e.to_string())
}

fn write_all<S: Write>(s: &mut S, b: &[u8]) -> Result<(), HaplyError> {
    s.write_all(b).and_then(|_| s.flush()).map_err(|e| {
        HaplyError::Lost(format!(
            "cannot write to the port ({e}): unplugged or closed"
        ))
    })
}
