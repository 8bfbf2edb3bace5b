//! One end of the world link: a UDP socket connected to the other end after the version-2
//! handshake of the device protocol (docs/DEVICE-PROTOCOL.md §3), non-blocking afterwards.
//!
//! The device side calls [`LinkEndpoint::connect`] (it sends `HELLO`s, as a host does to a UDP
//! device), the world side [`LinkEndpoint::accept`] (it answers with a `WELCOME`, as a device
//! does). Every period each side [`send`](LinkEndpoint::send)s one sealed port message and
//! [`poll`](LinkEndpoint::poll)s: all waiting datagrams are read, checked (size, MAC, session) and
//! the newest by sequence number is kept, so a late, reordered or duplicated datagram never
//! replaces a newer one. No allocation after the handshake.

use std::net::{SocketAddr, ToSocketAddrs, UdpSocket};
use std::time::{Duration, Instant};

use super::message::{PortMessage, Refused, PORT_LEN};
use crate::udp::auth::{
    nonce, Drop2, UdpKey, HEADER2_LEN, HELLO_LEN, KIND_HELLO, NONCE_LEN, VERSION2, WELCOME_LEN,
};
use crate::udp::codec::MAGIC;

/// What the endpoint has seen (datagrams).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkCounters {
    /// Port messages accepted as the newest.
    pub received: u64,
    /// Authentic port messages older than (or equal to) the newest: reordered or duplicated.
    pub stale: u64,
    /// Datagrams whose MAC did not match (another key, or forged).
    pub bad_mac: u64,
    /// Authentic datagrams of another session.
    pub wrong_session: u64,
    /// Datagrams of the wrong size, framing or kind, or with a non-finite number.
    pub malformed: u64,
    /// Authentic port messages of this session in the older message version 1 (the other end is
    /// an older build): refused.
    pub old_version: u64,
    /// Sends that failed (the other end gone: loopback answers with "connection refused").
    pub send_errors: u64,
}

/// A connected, authenticated end of the world link.
#[derive(Debug)]
pub struct LinkEndpoint {
    socket: UdpSocket,
    key: UdpKey,
    session: u64,
    peer: SocketAddr,
    /// The `WELCOME` this (world) end sent, answered again to a repeated `HELLO` whose `WELCOME`
    /// was lost.
    welcome: Option<([u8; NONCE_LEN], [u8; WELCOME_LEN])>,
    newest_seq: u32,
    /// What the endpoint has seen.
    pub counters: LinkCounters,
}

fn is_hello(b: &[u8]) -> bool {
    b.len() == HELLO_LEN && b[0..2] == MAGIC && b[2] == VERSION2 && b[3] == KIND_HELLO
}

impl LinkEndpoint {
    /// The device side: opens a session with the world at `addr` (`HOST:PORT`), sending a `HELLO`
    /// every 100 ms until a valid `WELCOME` answers it, for at most `timeout`.
    pub fn connect(addr: &str, key: &UdpKey, timeout: Duration) -> Result<Self, String> {
        let peer = addr
            .to_socket_addrs()
            .map_err(|e| format!("world address {addr}: {e}\n    fix: --world udp:HOST:PORT"))?
            .next()
            .ok_or_else(|| format!("world address {addr} resolves to nothing"))?;
        let local: SocketAddr = if peer.is_ipv4() {
            "0.0.0.0:0"
        } else {
            "[::]:0"
        }
        .parse()
        .map_err(|e| format!("{e}"))?;
        let socket =
            UdpSocket::bind(local).map_err(|e| format!("cannot open a UDP socket: {e}"))?;
        socket
            .connect(peer)
            .map_err(|e| format!("cannot reach {peer}: {e}"))?;
        socket
            .set_read_timeout(Some(Duration::from_millis(100)))
            .map_err(|e| e.to_string())?;
        let host_nonce = nonce().map_err(|e| format!("no random nonce: {e}"))?;
        let hello = key.hello(&host_nonce);
        let t0 = Instant::now();
        let mut counters = LinkCounters::default();
        let mut buf = [0u8; 512];
        while t0.elapsed() < timeout {
            // A refused send (nobody there yet) is retried with the next HELLO.
            let _ = socket.send(&hello);
            let until = Instant::now() + Duration::from_millis(100);
            while Instant::now() < until {
                let Ok(n) = socket.recv(&mut buf) else { break };
                match key.check_welcome(&buf[..n], &host_nonce) {
                    Ok(session) => {
                        socket.set_nonblocking(true).map_err(|e| e.to_string())?;
                        return Ok(Self {
                            socket,
                            key: key.clone(),
                            session,
                            peer,
                            welcome: None,
                            newest_seq: 0,
                            counters,
                        });
                    }
                    Err(Drop2::BadMac) => counters.bad_mac += 1,
                    Err(Drop2::WrongSession) => counters.wrong_session += 1,
                    Err(Drop2::Malformed) => counters.malformed += 1,
                }
            }
        }
        let why = bad_mac_note(&counters, "answers", "the two sides' keys differ");
        Err(format!(
            "no WELCOME from the world at {peer} in {:.1} s{why}\n    fix: start `haptic2d serve-world SCENE --bind {peer} --key KEY` there first, with the same key file",
            timeout.as_secs_f64()
        ))
    }

    /// The world side: waits on `socket` for an authentic `HELLO` (at most `timeout`, or until
    /// `stop` is set) and answers it with a `WELCOME`, opening the session with its sender.
    pub fn accept(
        socket: UdpSocket,
        key: &UdpKey,
        timeout: Duration,
        stop: &std::sync::atomic::AtomicBool,
    ) -> Result<Self, String> {
        socket
            .set_read_timeout(Some(Duration::from_millis(50)))
            .map_err(|e| e.to_string())?;
        let t0 = Instant::now();
        let mut counters = LinkCounters::default();
        let mut buf = [0u8; 512];
        while t0.elapsed() < timeout && !stop.load(std::sync::atomic::Ordering::Relaxed) {
            let Ok((n, from)) = socket.recv_from(&mut buf) else {
                continue;
            };
            let b = &buf[..n];
            if !is_hello(b) {
                counters.malformed += 1;
                continue;
            }
            if !key.verify(b) {
                counters.bad_mac += 1;
                continue;
            }
            let mut host_nonce = [0u8; NONCE_LEN];
            host_nonce.copy_from_slice(&b[HEADER2_LEN..HEADER2_LEN + NONCE_LEN]);
            let device_nonce = nonce().map_err(|e| format!("no random nonce: {e}"))?;
            let welcome = key.welcome(&host_nonce, &device_nonce);
            socket
                .connect(from)
                .map_err(|e| format!("cannot answer {from}: {e}"))?;
            let _ = socket.send(&welcome);
            socket.set_nonblocking(true).map_err(|e| e.to_string())?;
            return Ok(Self {
                socket,
                key: key.clone(),
                session: key.session_id(&host_nonce, &device_nonce),
                peer: from,
                welcome: Some((host_nonce, welcome)),
                newest_seq: 0,
                counters,
            });
        }
        let why = bad_mac_note(&counters, "HELLOs", "the device side's key differs");
        Err(format!(
            "no device opened a session in {:.1} s{why}",
            timeout.as_secs_f64()
        ))
    }

    /// The session id both ends derived.
    pub fn session(&self) -> u64 {
        self.session
    }

    /// The other end's address.
    pub fn peer(&self) -> SocketAddr {
        self.peer
    }

    /// The key the session is authenticated with.
    pub fn key(&self) -> &UdpKey {
        &self.key
    }

    /// Sends one sealed datagram; a failure is counted, never an error (the link's loss).
    #[inline]
    pub fn send(&mut self, datagram: &[u8]) {
        if self.socket.send(datagram).is_err() {
            self.counters.send_errors += 1;
        }
    }

    /// Reads every waiting datagram and returns the newest authentic port message of `kind` among
    /// them if it is newer than any before (`None`: nothing new this period). A repeated `HELLO`
    /// of this session is answered with its `WELCOME` again. Never blocks or allocates.
    pub fn poll(&mut self, kind: u8) -> Option<PortMessage> {
        let mut buf = [0u8; 512];
        let mut newest = None;
        while let Ok(n) = self.socket.recv(&mut buf) {
            let b = &buf[..n];
            if is_hello(b) {
                if let Some((hn, w)) = &self.welcome {
                    if self.key.verify(b) && b[HEADER2_LEN..HEADER2_LEN + NONCE_LEN] == hn[..] {
                        let _ = self.socket.send(w);
                        continue;
                    }
                }
            }
            match PortMessage::open_versioned(&self.key, b, kind, self.session) {
                Ok(m) if m.seq > self.newest_seq => {
                    self.newest_seq = m.seq;
                    self.counters.received += 1;
                    newest = Some(m);
                }
                Ok(_) => self.counters.stale += 1,
                Err(Refused::OldVersion) => self.counters.old_version += 1,
                Err(Refused::Drop(Drop2::BadMac)) => self.counters.bad_mac += 1,
                Err(Refused::Drop(Drop2::WrongSession)) => self.counters.wrong_session += 1,
                Err(Refused::Drop(Drop2::Malformed)) => self.counters.malformed += 1,
            }
        }
        newest
    }
}

/// The port message size, for callers sizing their buffers.
pub const DATAGRAM_LEN: usize = PORT_LEN;

/// The note a handshake that timed out adds when datagrams (`what`: "answers", "HELLOs") failed the
/// MAC: " (3 HELLOs with a bad MAC: {why})"; empty when none did.
fn bad_mac_note(counters: &LinkCounters, what: &str, why: &str) -> String {
    if counters.bad_mac > 0 {
        format!(" ({} {what} with a bad MAC: {why})", counters.bad_mac)
    } else {
        String::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world_link::message::{KIND_TO_DEVICE, KIND_TO_WORLD};
    use std::sync::atomic::AtomicBool;

    #[test]
    fn a_session_opens_on_loopback_and_carries_port_messages_both_ways() {
        let key = UdpKey::from_bytes(&[9; 32]).unwrap();
        let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
        let addr = sock.local_addr().unwrap().to_string();
        let k2 = key.clone();
        let world = std::thread::spawn(move || {
            LinkEndpoint::accept(sock, &k2, Duration::from_secs(5), &AtomicBool::new(false))
        });
        let mut dev = LinkEndpoint::connect(&addr, &key, Duration::from_secs(5)).unwrap();
        let mut w = world.join().unwrap().unwrap();
        assert_eq!(dev.session(), w.session());
        let mut b = [0u8; PORT_LEN];
        for seq in [1u32, 3, 2] {
            let m = PortMessage {
                seq,
                pose: [seq as f64, 0.0, 0.0],
                ..Default::default()
            };
            m.seal(&key, KIND_TO_WORLD, dev.session(), &mut b);
            dev.send(&b);
        }
        let mut got = None;
        for _ in 0..200 {
            if let Some(m) = w.poll(KIND_TO_WORLD) {
                got = Some(m);
            }
            if w.counters.received + w.counters.stale >= 3 {
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        assert_eq!(got.map(|m| m.seq), Some(3), "{:?}", w.counters);
        assert!(w.counters.stale >= 1, "{:?}", w.counters);
        PortMessage {
            seq: 1,
            ..Default::default()
        }
        .seal(&key, KIND_TO_DEVICE, w.session(), &mut b);
        w.send(&b);
        let mut back = None;
        for _ in 0..200 {
            back = back.or(dev.poll(KIND_TO_DEVICE));
            if back.is_some() {
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        assert_eq!(back.map(|m| m.seq), Some(1));
    }

    #[test]
    fn a_device_with_another_key_gets_no_session_and_is_told_why() {
        let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
        let addr = sock.local_addr().unwrap().to_string();
        let world = std::thread::spawn(move || {
            let k = UdpKey::from_bytes(&[1; 32]).unwrap();
            LinkEndpoint::accept(
                sock,
                &k,
                Duration::from_millis(600),
                &AtomicBool::new(false),
            )
        });
        let other = UdpKey::from_bytes(&[2; 32]).unwrap();
        let e = LinkEndpoint::connect(&addr, &other, Duration::from_millis(400)).unwrap_err();
        assert!(e.contains("no WELCOME"), "{e}");
        let e = world.join().unwrap().unwrap_err();
        assert!(e.contains("bad MAC"), "{e}");
    }
}
