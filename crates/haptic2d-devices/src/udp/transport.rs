//! The host side of the UDP protocol: one `std::net::UdpSocket` connected to the device, the
//! sequence numbers and timestamps, and the accounting of what the network did to the datagrams.
//!
//! One exchange: the host [`send`](UdpTransport::send)s command `k`, the device answers with one
//! state whose `echo_seq = k`; [`wait_answer`](UdpTransport::wait_answer) reads datagrams until that
//! answer arrives or a deadline passes (a blocking `recv` with a read timeout of the time left, so
//! the thread sleeps in the kernel, never longer than the deadline). Every datagram is classified:
//!
//! - *malformed*: the codec rejects it (size, magic, version, kind, bits, non-finite numbers), or it
//!   echoes a command never sent → counted, ignored;
//! - *duplicate* / *reordered*: its device `seq` is equal to / below the highest seen → counted,
//!   ignored (its data is older than what the host has);
//! - *late*: newer than anything seen but answering an older command than the one pending (it
//!   arrived after the host stopped waiting for it) → counted, and its data is used;
//! - *fresh*: the answer to the pending command → used; its round trip is measured from the echoed
//!   host timestamp.
//!
//! Loss: a jump in the device's `seq` counts the missing states as gaps; a reordered datagram fills
//! one, so `lost = gaps − reordered`. Nothing here allocates after [`connect`](UdpTransport::connect).

use std::io::ErrorKind;
use std::net::{SocketAddr, UdpSocket};
use std::time::{Duration, Instant};

use super::codec::{Command, State, COMMAND_LEN};

/// What the network did, counted since the transport was opened.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UdpCounters {
    /// Commands sent.
    pub sent: u64,
    /// Datagrams received (all kinds).
    pub received: u64,
    /// Fresh answers (the answer to the pending command).
    pub fresh: u64,
    /// Late answers (newer than any seen, but to an older command); used.
    pub late: u64,
    /// States older than one already received (ignored).
    pub reordered: u64,
    /// States repeated (ignored).
    pub duplicates: u64,
    /// Datagrams the codec rejected, or echoing a command never sent (ignored).
    pub malformed: u64,
    /// States missing from the device's sequence (gaps in `seq`), before reordered ones fill them.
    pub gaps: u64,
    /// Waits that ended at their deadline without the answer.
    pub timeouts: u64,
    /// "Connection refused" reports (ICMP port unreachable: nothing listens at the address).
    pub refused: u64,
}

impl UdpCounters {
    /// States lost on the way (gaps not filled by a reordered datagram).
    pub fn lost(&self) -> u64 {
        self.gaps.saturating_sub(self.reordered)
    }
}

impl std::fmt::Display for UdpCounters {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} sent, {} received: {} fresh, {} late, {} lost, {} reordered, {} duplicate, {} malformed; {} replies timed out",
            self.sent,
            self.received,
            self.fresh,
            self.late,
            self.lost(),
            self.reordered,
            self.duplicates,
            self.malformed,
            self.timeouts
        )
    }
}

/// The host's UDP endpoint for one device.
#[derive(Debug)]
pub struct UdpTransport {
    socket: UdpSocket,
    origin: Instant,
    seq: u32,
    pending: Option<u32>,
    highest: Option<u32>,
    latest: Option<State>,
    latest_at: Option<Instant>,
    unanswered_since: Option<Instant>,
    last_send_at: Instant,
    rtt_ns: Option<u64>,
    rtt_new: bool,
    counters: UdpCounters,
    out: [u8; COMMAND_LEN],
    buf: [u8; 256],
}

impl UdpTransport {
    /// Binds an ephemeral port of `device`'s address family and connects the socket to `device`
    /// (so only its datagrams are received).
    pub fn connect(device: SocketAddr) -> std::io::Result<Self> {
        let local: SocketAddr = if device.is_ipv4() {
            "0.0.0.0:0".parse().expect("literal address")
        } else {
            "[::]:0".parse().expect("literal address")
        };
        let socket = UdpSocket::bind(local)?;
        socket.connect(device)?;
        Ok(Self {
            socket,
            origin: Instant::now(),
            seq: 0,
            pending: None,
            highest: None,
            latest: None,
            latest_at: None,
            unanswered_since: None,
            last_send_at: Instant::now(),
            rtt_ns: None,
            rtt_new: false,
            counters: UdpCounters::default(),
            out: [0; COMMAND_LEN],
            buf: [0; 256],
        })
    }

    /// Host clock (ns since the transport was opened), the timestamp put in commands.
    pub fn host_ns(&self) -> u64 {
        self.origin.elapsed().as_nanos() as u64
    }

    /// Sends the next command (`flags`, `command`); it becomes the pending one. Returns its `seq`.
    pub fn send(&mut self, flags: u16, command: [f32; 3]) -> std::io::Result<u32> {
        self.seq = self.seq.wrapping_add(1).max(1);
        let (echo_seq, echo_device_ns) = self.latest.map_or((0, 0), |s| (s.seq, s.device_time_ns));
        Command {
            seq: self.seq,
            host_time_ns: self.host_ns(),
            echo_device_ns,
            echo_seq,
            flags,
            command,
        }
        .encode(&mut self.out);
        self.counters.sent += 1;
        self.last_send_at = Instant::now();
        self.pending = Some(self.seq);
        if self.unanswered_since.is_none() {
            self.unanswered_since = Some(Instant::now());
        }
        match self.socket.send(&self.out) {
            Ok(_) => Ok(self.seq),
            // A previous datagram's ICMP "port unreachable" surfaces on the next call.
            Err(e) if e.kind() == ErrorKind::ConnectionRefused => {
                self.counters.refused += 1;
                Ok(self.seq)
            }
            Err(e) => Err(e),
        }
    }

    /// True while a command has not been answered.
    pub fn pending(&self) -> bool {
        self.pending.is_some()
    }

    /// Reads datagrams until the pending command is answered (returns true) or `deadline` passes
    /// (false; counted as a timeout). With nothing pending, only drains what has arrived.
    pub fn wait_answer(&mut self, deadline: Instant) -> std::io::Result<bool> {
        loop {
            if self.pending.is_none() {
                while self.drain_one()? {}
                return Ok(true);
            }
            let now = Instant::now();
            if now >= deadline {
                // One last look at what is queued, without waiting.
                while self.pending.is_some() && self.drain_one()? {}
                if self.pending.is_none() {
                    return Ok(true);
                }
                self.counters.timeouts += 1;
                return Ok(false);
            }
            self.socket
                .set_read_timeout(Some((deadline - now).max(Duration::from_micros(1))))?;
            self.socket.set_nonblocking(false)?;
            match self.socket.recv(&mut self.buf) {
                Ok(n) => self.classify(n),
                // Interrupted: a signal, or SIGSTOP/SIGCONT (job control, a suspended VM) on a
                // socket with a read timeout; the loop re-checks the deadline.
                Err(e)
                    if matches!(
                        e.kind(),
                        ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                    ) => {}
                Err(e) if e.kind() == ErrorKind::ConnectionRefused => {
                    self.counters.refused += 1;
                    // Nothing listens: do not spin on the error, wait out the deadline quietly.
                    std::thread::sleep(deadline.saturating_duration_since(Instant::now()));
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// Receives one datagram if one is queued (non-blocking). Returns whether one was read.
    fn drain_one(&mut self) -> std::io::Result<bool> {
        self.socket.set_nonblocking(true)?;
        let r = loop {
            match self.socket.recv(&mut self.buf) {
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                r => break r,
            }
        };
        self.socket.set_nonblocking(false)?;
        match r {
            Ok(n) => {
                self.classify(n);
                Ok(true)
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => Ok(false),
            Err(e) if e.kind() == ErrorKind::ConnectionRefused => {
                self.counters.refused += 1;
                Ok(false)
            }
            Err(e) => Err(e),
        }
    }

    fn classify(&mut self, n: usize) {
        self.counters.received += 1;
        let s = match State::decode(&self.buf[..n.min(self.buf.len())]) {
            Ok(s) if s.echo_seq <= self.seq => s,
            _ => {
                self.counters.malformed += 1;
                return;
            }
        };
        if let Some(h) = self.highest {
            if s.seq == h {
                self.counters.duplicates += 1;
                return;
            }
            // Sequence arithmetic modulo 2³²: "older" means less than half the range behind.
            let ahead = s.seq.wrapping_sub(h);
            if ahead > u32::MAX / 2 {
                self.counters.reordered += 1;
                return;
            }
            self.counters.gaps += u64::from(ahead - 1);
        }
        self.highest = Some(s.seq);
        let now = Instant::now();
        if Some(s.echo_seq) == self.pending {
            self.pending = None;
            self.unanswered_since = None;
            self.counters.fresh += 1;
            self.rtt_ns = Some(self.host_ns().saturating_sub(s.echo_host_ns));
            self.rtt_new = true;
        } else {
            self.counters.late += 1;
            // Commands after the one answered are still open; the oldest of them is at most as
            // old as the pending one (send times are not kept: this errs towards patience).
            self.unanswered_since = self.pending.map(|_| self.last_send_at);
        }
        self.latest = Some(s);
        self.latest_at = Some(now);
    }

    /// The newest state received (fresh or late).
    pub fn latest(&self) -> Option<&State> {
        self.latest.as_ref()
    }

    /// How long the device has been silent: since the oldest command sent after the newest state
    /// received (zero when every command is answered). Measured from the host's sends, so a host
    /// that stalled itself does not blame the device.
    pub fn silent_for(&self) -> Duration {
        self.unanswered_since
            .map_or(Duration::ZERO, |t| t.elapsed())
    }

    /// When the newest state arrived.
    pub fn latest_at(&self) -> Option<Instant> {
        self.latest_at
    }

    /// Round trip of the last fresh answer (ns): host send to host receive, from the echoed stamp.
    /// A true round trip only when the host was already waiting when the answer arrived (as the
    /// `udp_roundtrip` example does); an answer read from the queue a tick later shows its age.
    pub fn rtt_ns(&self) -> Option<u64> {
        self.rtt_ns
    }

    /// The round trip of a fresh answer received since the last call (ns), once.
    pub fn take_rtt(&mut self) -> Option<u64> {
        std::mem::take(&mut self.rtt_new)
            .then_some(self.rtt_ns)
            .flatten()
    }

    /// The counters.
    pub fn counters(&self) -> &UdpCounters {
        &self.counters
    }

    /// The device's address.
    pub fn peer(&self) -> std::io::Result<SocketAddr> {
        self.socket.peer_addr()
    }
}
