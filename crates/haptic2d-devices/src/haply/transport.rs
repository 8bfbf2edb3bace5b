//! The Haply transport: frames over any `Read + Write` stream (a serial port, a pseudo-terminal, an
//! in-memory mock), with read timeouts, detection of a stream out of step, **one**
//! resynchronisation (reset + setup) and then a clear stop.
//!
//! ```text
//! handshake:  reset → setup → write(0…) → reply          (before the first deadline)
//! per tick:   send_write(τ) … read_reply() → angles       (deadline: sent + timeout)
//! out of step (first byte ≠ id, short reply, garbage):
//!             drain input → reset → setup → write(0…) → reply   (once; torques zero until then)
//!             a second time → HaplyError::OutOfStep (stop)
//! nothing at all within the timeout → HaplyError::Lost
//! ```
//!
//! The stream's own read timeout should be short (the serial opener uses ≤ 1 ms): the transport
//! loops until its deadline. No allocation on the success path.

use std::fmt;
use std::io::{ErrorKind, Read, Write};
use std::time::{Duration, Instant};

use super::codec::{
    decode_reply, encode_reset, encode_setup, encode_write, BoardSetup, CodecError, Reply, PORTS,
    REPLY_MAX_LEN, SETUP_MAX_LEN, WRITE_MAX_LEN,
};

/// A transport failure; mapped to `DeviceError::Lost`/`Io` at the `DeviceIo` boundary.
#[derive(Clone, Debug, PartialEq)]
pub enum HaplyError {
    /// No reply (or not all of it) within the timeout, or the port closed.
    Lost(String),
    /// The stream stayed out of step after the one resynchronisation allowed.
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
                "the byte stream is out of step ({e}) and one resynchronisation (reset + setup) did not fix it"
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
    resyncs_left: u32,
    resyncs: u32,
}

impl<S: Read + Write> Transport<S> {
    /// A transport to the board configured by `setup` over `stream`, waiting at most `timeout` for
    /// each reply (from the moment its write was sent). Nothing is sent yet: call
    /// [`handshake`](Self::handshake).
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
            resyncs_left: 1,
            resyncs: 0,
        })
    }

    /// Changes the reply timeout (must be > 0; zero is ignored).
    pub fn set_timeout(&mut self, timeout: Duration) {
        if !timeout.is_zero() {
            self.timeout = timeout;
        }
    }

    /// The board set-up.
    pub fn setup(&self) -> &BoardSetup {
        &self.setup
    }

    /// Resynchronisations done so far (0 or 1).
    pub fn resyncs(&self) -> u32 {
        self.resyncs
    }

    /// The stream (e.g. to inspect a mock).
    pub fn stream(&self) -> &S {
        &self.stream
    }

    /// True while a write waits for its reply.
    pub fn pending(&self) -> bool {
        self.sent_at.is_some()
    }

    /// Reset + setup + a zero-torque write, and its reply: the board is configured and answering.
    pub fn handshake(&mut self) -> Result<Reply, HaplyError> {
        self.send_reset_setup()?;
        self.send_write(&[0.0; PORTS][..self.setup.n_motors()])?;
        self.wait_reply()
    }

    fn send_reset_setup(&mut self) -> Result<(), HaplyError> {
        let n = encode_reset(self.setup.id, &mut self.tx).map_err(cfg)?;
        write_all(&mut self.stream, &self.tx[..n])?;
        let n = encode_setup(&self.setup, &mut self.tx).map_err(cfg)?;
        write_all(&mut self.stream, &self.tx[..n])
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

    /// Reads the reply to the last write, waiting until `timeout` after it was sent. A stream out of
    /// step is resynchronised once (the reply then comes from the zero-torque write of the
    /// resynchronisation); the second time it is an error.
    pub fn read_reply(&mut self) -> Result<Reply, HaplyError> {
        match self.wait_reply() {
            Err(HaplyError::OutOfStep(e)) => {
                if self.resyncs_left == 0 {
                    return Err(HaplyError::OutOfStep(e));
                }
                self.resyncs_left -= 1;
                self.resyncs += 1;
                self.drain();
                self.send_reset_setup()?;
                self.send_write(&[0.0; PORTS][..self.setup.n_motors()])?;
                self.wait_reply()
            }
            other => other,
        }
    }

    /// Write then read: one exchange.
    pub fn exchange(&mut self, torques: &[f32]) -> Result<Reply, HaplyError> {
        self.send_write(torques)?;
        self.read_reply()
    }

    /// One attempt at reading a full reply before the deadline; no resynchronisation.
    fn wait_reply(&mut self) -> Result<Reply, HaplyError> {
        let Some(sent) = self.sent_at.take() else {
            return Err(HaplyError::Config("read_reply without a write".into()));
        };
        let len = self.setup.reply_len();
        let deadline = sent + self.timeout;
        let mut got = 0;
        while got < len {
            // The first byte tells at once whether the stream is in step.
            if got >= 1 && self.rx[0] != self.setup.id {
                break;
            }
            match self.stream.read(&mut self.rx[got..len]) {
                Ok(n) => got += n,
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(HaplyError::Lost(format!(
                        "the port failed while waiting for a reply ({e}): unplugged or closed"
                    )))
                }
            }
            if got < len && Instant::now() >= deadline {
                if got == 0 {
                    return Err(HaplyError::Lost(format!(
                        "no reply within {:.1} ms",
                        self.timeout.as_secs_f64() * 1e3
                    )));
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

    /// Discards whatever is waiting on the input (up to one timeout).
    fn drain(&mut self) {
        let until = Instant::now() + self.timeout.min(Duration::from_millis(5));
        let mut buf = [0u8; 64];
        while Instant::now() < until {
            match self.stream.read(&mut buf) {
                Ok(0) => break,
                Ok(_) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(_) => break,
            }
        }
    }
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
