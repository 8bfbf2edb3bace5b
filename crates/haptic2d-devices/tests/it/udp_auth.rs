//! Protocol version 2 (issue 38, finding 1): every attack of the finding fails against the host.
//! The in-test device holds the key and speaks version 2; from its own socket (what a forged source
//! address looks like to the host) and from another port it also sends what an attacker would:
//! states with a wrong MAC that move the handle, states of an earlier session, replays of genuine
//! states, and a genuine state whose sequence number is 2³¹ ahead. The host must read only the
//! genuine angles, finish the run, and count every drop by its reason.

use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread;
use std::time::{Duration, Instant};

use haptic2d_devices::udp::auth::{
    session_of, UdpKey, COMMAND2_LEN, HELLO_LEN, KIND_HELLO, NONCE_LEN, STATE2_LEN,
};
use haptic2d_devices::udp::codec::{Command, COMMAND_LEN, KIND_COMMAND, STATE_LEN};
use haptic2d_devices::udp::{UdpCounters, UdpDevice, UdpDeviceFile};
use haptic2d_rt::DeviceIo;

use crate::udp_echo::{answer, Encoded};

const PERIOD: Duration = Duration::from_millis(1);
/// The genuine joint angles (rad).
const Q: [f32; 2] = [1.9, 1.2];
/// What forged states claim (rad): a handle far from Q.
const FORGED_Q: [f32; 2] = [2.3, 0.9];

fn key() -> UdpKey {
    UdpKey::from_bytes(b"haptic2d test key, 32 bytes long").unwrap()
}

fn wrong_key() -> UdpKey {
    UdpKey::from_bytes(b"an attacker's guess at the key..").unwrap()
}

/// What the in-test device sends besides its genuine answers.
#[derive(Clone, Copy, PartialEq)]
enum Attack {
    None,
    /// Before every genuine answer, from the device's own socket: a state with FORGED_Q and a
    /// wrong MAC; one MAC'd with the right key but an earlier session's id; a replay of the
    /// previous genuine state. From another port: a copy of the genuine answer.
    Everything,
    /// One genuine (MAC'd) state whose device seq is 2³¹ ahead, at the 50th command.
    SeqJump,
}

struct Device2 {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    handle: Option<thread::JoinHandle<u64>>,
}

impl Device2 {
    fn start(key: UdpKey, attack: Attack) -> Self {
        let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
        sock.set_read_timeout(Some(Duration::from_millis(5)))
            .unwrap();
        let other = UdpSocket::bind("127.0.0.1:0").unwrap();
        let addr = sock.local_addr().unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let s2 = stop.clone();
        let handle = thread::spawn(move || {
            let mut buf = [0u8; 256];
            let (mut session, mut seq, mut commands) = (0u64, 0u32, 0u64);
            let mut previous: Option<[u8; STATE2_LEN]> = None;
            let old_session = key.session_id(&[1; NONCE_LEN], &[2; NONCE_LEN]);
            while !s2.load(Ordering::Relaxed) {
                let Ok((n, peer)) = sock.recv_from(&mut buf) else {
                    continue;
                };
                let b = &buf[..n];
                if n == HELLO_LEN && b[3] == KIND_HELLO && key.verify(b) {
                    let mut hn = [0u8; NONCE_LEN];
                    hn.copy_from_slice(&b[12..12 + NONCE_LEN]);
                    let dn = [0x5a; NONCE_LEN];
                    session = key.session_id(&hn, &dn);
                    let _ = sock.send_to(&key.welcome(&hn, &dn), peer);
                    continue;
                }
                let mut v1 = [0u8; COMMAND_LEN];
                if key
                    .open2(b, KIND_COMMAND, COMMAND2_LEN, session, &mut v1)
                    .is_err()
                {
                    continue;
                }
                let c = Command::decode(&v1).unwrap();
                commands += 1;
                seq += 1;
                let state = |seq: u32, q: [f32; 2]| answer(&c, seq, [q[0], q[1], 0.0]).encoded();
                let mut out = [0u8; STATE2_LEN];
                let dev_seq = if attack == Attack::SeqJump && commands == 50 {
                    seq.wrapping_add(1 << 31)
                } else {
                    seq
                };
                key.state2(session, &state(dev_seq, Q), &mut out);
                if attack == Attack::Everything {
                    // A forged state: right layout and session, FORGED_Q, a MAC made without the key.
                    let mut forged = [0u8; STATE2_LEN];
                    wrong_key().state2(session, &state(seq + 1, FORGED_Q), &mut forged);
                    let _ = sock.send_to(&forged, peer);
                    // Authentic, but of another session (recorded in an earlier run).
                    let mut old = [0u8; STATE2_LEN];
                    key.state2(old_session, &state(seq + 1, FORGED_Q), &mut old);
                    let _ = sock.send_to(&old, peer);
                    // A replay of the previous genuine state.
                    if let Some(p) = previous {
                        let _ = sock.send_to(&p, peer);
                    }
                    // The genuine answer's bytes, from another port.
                    let _ = other.send_to(&out, peer);
                }
                let _ = sock.send_to(&out, peer);
                previous = Some(out);
            }
            commands
        });
        Self {
            addr,
            stop,
            handle: Some(handle),
        }
    }

    fn finish(mut self) -> u64 {
        self.stop.store(true, Ordering::Relaxed);
        self.handle.take().unwrap().join().unwrap()
    }
}

fn file_with(key: UdpKey) -> UdpDeviceFile {
    let mut f = UdpDeviceFile::reference();
    f.key = Some(key);
    // Patient: the tests count what arrives, on machines shared with compilers.
    f.timeout_periods = 50.0;
    f
}

/// `ticks` ticks at 1 kHz; every angle read is checked against the genuine ones.
fn run_checked(dev: &mut UdpDevice, ticks: usize) {
    let start = Instant::now();
    for k in 0..ticks {
        let q = dev.read_encoders().expect("the run goes on");
        assert_eq!(
            [q[0] as f32, q[1] as f32],
            Q,
            "tick {k}: a state that is not the device's was used"
        );
        dev.write_torques(&[0.01, -0.01, 0.0, 0.0]).unwrap();
        let next = start + PERIOD * (k as u32 + 1);
        thread::sleep(next.saturating_duration_since(Instant::now()));
    }
}

/// The host over version 2 (checked: a session) against a device with the genuine key doing
/// `attack`, `ticks` checked ticks; the host's counters and the commands the device received.
fn attacked_run(attack: Attack, ticks: usize, name: &str) -> (UdpCounters, u64) {
    let dev = Device2::start(key(), attack);
    let mut host = UdpDevice::open(dev.addr, &file_with(key()), PERIOD, name).unwrap();
    assert_eq!(host.transport().version(), 2);
    assert_ne!(host.transport().session(), 0);
    run_checked(&mut host, ticks);
    let c = *host.counters();
    drop(host);
    (c, dev.finish())
}

#[test]
fn version_2_exchanges_with_a_session_and_counts_nothing_dropped() {
    let (c, _) = attacked_run(Attack::None, 300, "udp:v2");
    assert!(c.fresh >= 290, "{c}");
    assert_eq!(c.dropped(), 0, "{c}");
}

#[test]
fn forged_replayed_and_misdirected_states_are_dropped_and_counted_by_reason() {
    let (c, commands) = attacked_run(Attack::Everything, 400, "udp:attacked");
    assert!(commands >= 400, "{commands}");
    // One of each per answer (the host may stop reading before the last few).
    let per_answer = c.fresh + c.late;
    assert!(per_answer >= 390, "{c}");
    assert!(c.bad_mac + 5 >= per_answer, "{c}");
    assert!(c.wrong_session + 5 >= per_answer, "{c}");
    assert!(c.wrong_source + 5 >= per_answer, "{c}");
    assert!(c.duplicates + c.reordered + 5 >= per_answer, "{c}");
    assert_eq!(c.lost(), 0, "{c}");
    let shown = c.to_string();
    assert!(
        shown.contains(" bad MAC")
            && shown.contains(" wrong session")
            && shown.contains(" wrong source"),
        "{shown}"
    );
}

/// Regression (issue 38): one state whose sequence number was 2³¹ ahead made every genuine state
/// look out of order, and the run ended as a lost device (exit 4).
#[test]
fn a_state_2_pow_31_ahead_does_not_lock_out_the_device() {
    let (c, _) = attacked_run(Attack::SeqJump, 300, "udp:jump");
    assert!(c.fresh >= 290, "{c}");
    assert_eq!(c.duplicates + c.reordered, 0, "{c}");
    // The jump there and the jump back re-anchor the loss count; no state is called lost.
    assert_eq!(c.seq_jumps, 2, "{c}");
    assert_eq!(c.lost(), 0, "{c}");
}

/// The same attack in version 1 on loopback (no MAC to stop it): the forged state from the
/// device's address is used once (version 1 cannot tell), but the real device is not locked out.
#[test]
fn version_1_is_not_locked_out_by_a_forged_state_2_pow_31_ahead() {
    let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = sock.local_addr().unwrap();
    thread::spawn(move || {
        let mut buf = [0u8; 256];
        let mut seq = 0u32;
        while let Ok((n, peer)) = sock.recv_from(&mut buf) {
            let Ok(c) = Command::decode(&buf[..n]) else {
                continue;
            };
            seq += 1;
            let mut out = [0u8; STATE_LEN];
            let s = answer(&c, seq, [Q[0], Q[1], 0.0]);
            if seq == 50 {
                // The forged one, ahead of the genuine answer to the same command.
                let mut f = s;
                f.seq = seq.wrapping_add(1 << 31);
                f.encode(&mut out);
                let _ = sock.send_to(&out, peer);
            }
            s.encode(&mut out);
            let _ = sock.send_to(&out, peer);
        }
    });
    let mut file = UdpDeviceFile::reference();
    file.timeout_periods = 50.0;
    let mut host = UdpDevice::open(addr, &file, PERIOD, "udp:v1").unwrap();
    run_checked(&mut host, 300);
    let c = *host.counters();
    assert!(c.fresh >= 290, "{c}");
    assert!(c.duplicates <= 1, "{c}");
}

#[test]
fn a_device_with_another_key_is_refused_at_open_naming_the_key() {
    let dev = Device2::start(wrong_key(), Attack::None);
    let e = UdpDevice::open(dev.addr, &file_with(key()), PERIOD, "udp:other").unwrap_err();
    dev.finish();
    assert!(e.contains("no session") && e.contains("same key"), "{e}");
}

#[test]
fn version_1_is_refused_beyond_loopback() {
    // Refused before any socket is opened: nothing is sent to this (documentation) address.
    let addr: SocketAddr = "192.0.2.1:5005".parse().unwrap();
    let e = UdpDevice::open(addr, &UdpDeviceFile::reference(), PERIOD, "udp:remote").unwrap_err();
    assert!(e.contains("loopback") && e.contains("key_file"), "{e}");
}

/// A HELLO replayed from an earlier session makes the device answer with a WELCOME the replayer
/// cannot use; the host's handshake takes only the WELCOME for its own nonce.
#[test]
fn a_welcome_to_another_hello_is_not_taken() {
    let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = sock.local_addr().unwrap();
    thread::spawn(move || {
        let k = key();
        let mut buf = [0u8; 256];
        while let Ok((n, peer)) = sock.recv_from(&mut buf) {
            if n == HELLO_LEN && k.verify(&buf[..n]) {
                // An authentic WELCOME, but to an old host nonce.
                let w = k.welcome(&[9; NONCE_LEN], &[8; NONCE_LEN]);
                let _ = sock.send_to(&w, peer);
                assert_ne!(session_of(&w), 0);
            }
        }
    });
    let e = UdpDevice::open(addr, &file_with(key()), PERIOD, "udp:replayed").unwrap_err();
    assert!(
        e.contains("no session") && e.contains("wrong session"),
        "{e}"
    );
}
