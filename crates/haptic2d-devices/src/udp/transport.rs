//! The host side of the UDP protocol: one `std::net::UdpSocket` that talks to the device, the
//! session (version 2: the handshake and the MAC of every datagram, [`super::auth`]), the sequence
//! numbers and timestamps, and the accounting of what the network did to the datagrams.
//!
//! One exchange: the host [`send`](UdpTransport::send)s command `k`, the device answers with one
//! state whose `echo_seq = k`; [`wait_answer`](UdpTransport::wait_answer) reads datagrams until that
//! answer arrives or a deadline passes (a blocking `recv` with a read timeout of the time left, so
//! the thread sleeps in the kernel, never longer than the deadline). Every datagram is classified,
//! in this order:
//!
//! - *wrong source*: not from the device's address and port → counted, ignored (the socket is not
//!   `connect`ed, so these are seen and counted rather than dropped silently by the kernel);
//! - *malformed*: wrong size, magic, version or kind, undefined bits, non-finite numbers, or it
//!   echoes a command never sent → counted, ignored;
//! - *bad MAC* (version 2): the MAC does not match the key → counted, ignored;
//! - *wrong session* (version 2): authentic but of another session (a replay from an earlier run)
//!   → counted, ignored;
//! - *duplicate* / *reordered* (stale or replayed): it answers a command no newer than the one the
//!   newest used state answered (equal / older) → counted, ignored;
//! - *late*: answering a newer command than any answer used, but older than the pending one (it
//!   arrived after the host stopped waiting for it) → counted, and its data is used;
//! - *fresh*: the answer to the pending command → used; its round trip is measured from the echoed
//!   host timestamp.
//!
//! Freshness is decided by `echo_seq`, the host's own command number, which the host bounds (an
//! answer to a command never sent is malformed): no datagram can move the window beyond what the
//! host itself sent, so a forged or corrupt device `seq` (even 2³¹ ahead) cannot make the real
//! device's states look old. The device's `seq` only counts loss: a jump of `1 ..= MAX_SEQ_JUMP`
//! counts the missing states as gaps (a reordered datagram fills one, so `lost = gaps − reordered`);
//! a larger jump is counted as a *seq jump* and re-anchors the count. Nothing here allocates after
//! [`handshake`](UdpTransport::handshake) (which reads its nonce from the system).

use std::io::ErrorKind;
use std::net::{SocketAddr, UdpSocket};
use std::time::{Duration, Instant};

use super::auth::{self, Drop2, UdpKey, COMMAND2_LEN, HELLO_LEN, STATE2_LEN};
use super::codec::{Command, State, COMMAND_LEN, KIND_STATE, STATE_LEN};

/// The largest forward jump of the device's `seq` counted as lost states; a larger one is a *seq
/// jump* (a device restart, or a corrupt number) and re-anchors the loss count.
pub const MAX_SEQ_JUMP: u32 = 1 << 16;

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
    /// Version 2: datagrams whose MAC did not match (forged or corrupt; ignored).
    pub bad_mac: u64,
    /// Version 2: authentic datagrams of another session (replayed from an earlier one; ignored).
    pub wrong_session: u64,
    /// Datagrams from another address or port than the device's (ignored).
    pub wrong_source: u64,
    /// Forward jumps of the device's `seq` beyond [`MAX_SEQ_JUMP`] (not counted as loss).
    pub seq_jumps: u64,
}

impl UdpCounters {
    /// States lost on the way (gaps not filled by a reordered datagram).
    pub fn lost(&self) -> u64 {
        self.gaps.saturating_sub(self.reordered)
    }

    /// Every datagram dropped, whatever the reason.
    pub fn dropped(&self) -> u64 {
        self.malformed
            + self.bad_mac
            + self.wrong_session
            + self.wrong_source
            + self.duplicates
            + self.reordered
    }
}

impl std::fmt::Display for UdpCounters {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} sent, {} received: {} fresh, {} late, {} lost, {} reordered, {} duplicate, {} malformed; {} replies timed out; dropped: {} bad MAC, {} wrong session, {} wrong source, {} seq jumps",
            self.sent,
            self.received,
            self.fresh,
            self.late,
            self.lost(),
            self.reordered,
            self.duplicates,
            self.malformed,
            self.timeouts,
            self.bad_mac,
            self.wrong_session,
            self.wrong_source,
            self.seq_jumps
        )
    }
}

/// The host's UDP endpoint for one device.
#[derive(Debug)]
pub struct UdpTransport {
    socket: UdpSocket,
    device: SocketAddr,
    key: Option<UdpKey>,
    session: u64,
    origin: Instant,
    seq: u32,
    pending: Option<u32>,
    highest: Option<u32>,
    newest_echo: u32,
    latest: Option<State>,
    latest_at: Option<Instant>,
    unanswered_since: Option<Instant>,
    last_send_at: Instant,
    rtt_ns: Option<u64>,
    rtt_new: bool,
    counters: UdpCounters,
    out: [u8; COMMAND_LEN],
    out2: [u8; COMMAND2_LEN],
    v1: [u8; STATE_LEN],
    buf: [u8; 256],
}

impl UdpTransport {
    /// Binds an ephemeral port of `device`'s address family for protocol version 1 (no
    /// authentication; [`UdpDevice::open`](super::UdpDevice::open) allows it on loopback only).
    /// Datagrams from any other address or port are counted as *wrong source* and ignored.
    pub fn connect(device: SocketAddr) -> std::io::Result<Self> {
        Self::connect_with(device, None)
    }

    /// Binds an ephemeral port for `device`: version 2 with `key` (then
    /// [`handshake`](Self::handshake) before the first command), version 1 without.
    pub fn connect_with(device: SocketAddr, key: Option<UdpKey>) -> std::io::Result<Self> {
        // A device on loopback is answered from loopback only: nothing from the network reaches
        // this socket at all.
        let local: SocketAddr = match (device.is_ipv4(), device.ip().is_loopback()) {
            (true, true) => "127.0.0.1:0",
            (true, false) => "0.0.0.0:0",
            (false, true) => "[::1]:0",
            (false, false) => "[::]:0",
        }
        .parse()
        .expect("literal address");
        let socket = UdpSocket::bind(local)?;
        Ok(Self {
            socket,
            device,
            key,
            session: 0,
            origin: Instant::now(),
            seq: 0,
            pending: None,
            highest: None,
            newest_echo: 0,
            latest: None,
            latest_at: None,
            unanswered_since: None,
            last_send_at: Instant::now(),
            rtt_ns: None,
            rtt_new: false,
            counters: UdpCounters::default(),
            out: [0; COMMAND_LEN],
            out2: [0; COMMAND2_LEN],
            v1: [0; STATE_LEN],
            buf: [0; 256],
        })
    }

    /// The protocol version spoken: 2 with a key, else 1.
    pub fn version(&self) -> u8 {
        if self.key.is_some() {
            2
        } else {
            1
        }
    }

    /// The session id (version 2, after the handshake; 0 before and in version 1).
    pub fn session(&self) -> u64 {
        self.session
    }

    /// Version 2: opens a session. Sends a `HELLO` with a fresh host nonce every `retry` until a
    /// `WELCOME` answering it arrives (authentic, echoing this nonce) or `deadline` passes. Returns
    /// whether the session is open; what else arrives meanwhile is counted. Version 1: `true`.
    pub fn handshake(&mut self, deadline: Instant, retry: Duration) -> std::io::Result<bool> {
        let Some(key) = self.key.clone() else {
            return Ok(true);
        };
        let hn = auth::nonce()?;
        let hello: [u8; HELLO_LEN] = key.hello(&hn);
        loop {
            let now = Instant::now();
            if now >= deadline {
                return Ok(false);
            }
            self.send_raw_hello(&hello)?;
            let until = (now + retry).min(deadline);
            while let Some(n) = self.recv_until(until)? {
                let b = &self.buf[..n];
                match key.check_welcome(b, &hn) {
                    Ok(sid) => {
                        self.session = sid;
                        return Ok(true);
                    }
                    Err(Drop2::BadMac) => self.counters.bad_mac += 1,
                    Err(Drop2::WrongSession) => self.counters.wrong_session += 1,
                    Err(Drop2::Malformed) => self.counters.malformed += 1,
                }
            }
        }
    }

    fn send_raw_hello(&mut self, hello: &[u8]) -> std::io::Result<()> {
        match self.socket.send_to(hello, self.device) {
            Ok(_) => Ok(()),
            Err(e) if e.kind() == ErrorKind::ConnectionRefused => {
                self.counters.refused += 1;
                Ok(())
            }
            Err(e) => Err(e),
        }
    }

    /// Receives one datagram from the device before `until` (its length in `buf`), counting and
    /// skipping those from elsewhere; `None` at the deadline.
    fn recv_until(&mut self, until: Instant) -> std::io::Result<Option<usize>> {
        loop {
            let now = Instant::now();
            if now >= until {
                return Ok(None);
            }
            self.socket
                .set_read_timeout(Some((until - now).max(Duration::from_micros(1))))?;
            match self.socket.recv_from(&mut self.buf) {
                Ok((n, from)) => {
                    self.counters.received += 1;
                    if from != self.device {
                        self.counters.wrong_source += 1;
                        continue;
                    }
                    return Ok(Some(n));
                }
                Err(e) => self.absorb_recv_error(e, until)?,
            }
        }
    }

    /// A failed blocking receive that was to end by `until`. A timeout or an interruption (a
    /// signal, or SIGSTOP/SIGCONT — job control, a suspended VM — on a socket with a read timeout)
    /// is nothing: the caller re-checks its deadline. "Connection refused" (nothing listens) is
    /// counted and the rest of the wait slept out quietly rather than spun on. Any other error is
    /// returned.
    fn absorb_recv_error(&mut self, e: std::io::Error, until: Instant) -> std::io::Result<()> {
        match e.kind() {
            ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted => Ok(()),
            ErrorKind::ConnectionRefused => {
                self.counters.refused += 1;
                std::thread::sleep(until.saturating_duration_since(Instant::now()));
                Ok(())
            }
            _ => Err(e),
        }
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
        let sent = match &self.key {
            Some(key) => {
                key.command2(self.session, &self.out, &mut self.out2);
                self.socket.send_to(&self.out2, self.device)
            }
            None => self.socket.send_to(&self.out, self.device),
        };
        match sent {
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
            match self.socket.recv_from(&mut self.buf) {
                Ok((n, from)) => self.classify(n, from),
                Err(e) => self.absorb_recv_error(e, deadline)?,
            }
        }
    }

    /// Receives one datagram if one is queued (non-blocking). Returns whether one was read.
    fn drain_one(&mut self) -> std::io::Result<bool> {
        self.socket.set_nonblocking(true)?;
        let r = loop {
            match self.socket.recv_from(&mut self.buf) {
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                r => break r,
            }
        };
        self.socket.set_nonblocking(false)?;
        match r {
            Ok((n, from)) => {
                self.classify(n, from);
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

    fn classify(&mut self, n: usize, from: SocketAddr) {
        self.counters.received += 1;
        if from != self.device {
            self.counters.wrong_source += 1;
            return;
        }
        let b = &self.buf[..n.min(self.buf.len())];
        let decoded = match &self.key {
            Some(key) => match key.open2(b, KIND_STATE, STATE2_LEN, self.session, &mut self.v1) {
                Ok(()) => State::decode(&self.v1),
                Err(Drop2::BadMac) => {
                    self.counters.bad_mac += 1;
                    return;
                }
                Err(Drop2::WrongSession) => {
                    self.counters.wrong_session += 1;
                    return;
                }
                Err(Drop2::Malformed) => {
                    self.counters.malformed += 1;
                    return;
                }
            },
            None => State::decode(b),
        };
        // An answer to a command this host never sent (seq 0, or ahead of its own counter).
        let s = match decoded {
            Ok(s) if s.echo_seq != 0 && s.echo_seq <= self.seq => s,
            _ => {
                self.counters.malformed += 1;
                return;
            }
        };
        // Stale or replayed: it answers a command no newer than the newest state used did.
        if s.echo_seq == self.newest_echo {
            self.counters.duplicates += 1;
            return;
        }
        if s.echo_seq < self.newest_echo {
            self.counters.reordered += 1;
            return;
        }
        if let Some(h) = self.highest {
            // Sequence arithmetic modulo 2³²: a gap of 1 ..= MAX_SEQ_JUMP is loss, anything else
            // (a restart, a corrupt or forged number) re-anchors.
            let ahead = s.seq.wrapping_sub(h);
            if (1..=MAX_SEQ_JUMP).contains(&ahead) {
                self.counters.gaps += u64::from(ahead - 1);
            } else {
                self.counters.seq_jumps += 1;
            }
        }
        self.highest = Some(s.seq);
        self.newest_echo = s.echo_seq;
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
        Ok(self.device)
    }

    /// This end's own address (the host's port; tests send to it).
    pub fn local_addr(&self) -> std::io::Result<SocketAddr> {
        self.socket.local_addr()
    }
}
