//! A minimal device on the UDP protocol for the driver's tests: answers every command with a fixed
//! joint state that echoes the command's sequence number and host time.

use std::net::{SocketAddr, UdpSocket};
use std::thread;
use std::time::Duration;

use haptic2d_devices::udp::codec::{Command, State, STATE_LEN};

/// The joint angles every answer carries (rad).
pub const ECHO_POSITION: [f32; 3] = [1.9, 1.2, 0.0];

/// The state answering command `c`: device sequence number `seq`, the command's sequence number
/// and host time echoed, joint angles `position` (rad), at rest, no force.
pub fn answer(c: &Command, seq: u32, position: [f32; 3]) -> State {
    State {
        seq,
        echo_seq: c.seq,
        status: 0,
        device_time_ns: 0,
        echo_host_ns: c.host_time_ns,
        position,
        velocity: [0.0; 3],
        force: [0.0; 3],
    }
}

/// A state as its datagram.
pub trait Encoded {
    /// The `STATE_LEN` bytes of the state.
    fn encoded(&self) -> [u8; STATE_LEN];
}

impl Encoded for State {
    fn encoded(&self) -> [u8; STATE_LEN] {
        let mut out = [0u8; STATE_LEN];
        self.encode(&mut out);
        out
    }
}

/// Starts the device on a free loopback port, answering each command `delay` after it arrives, on
/// its own thread (it ends with the test process). Returns its address.
pub fn spawn_echo_device(delay: Duration) -> SocketAddr {
    let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = sock.local_addr().unwrap();
    thread::spawn(move || {
        let mut buf = [0u8; 256];
        let mut seq = 0;
        while let Ok((n, peer)) = sock.recv_from(&mut buf) {
            let Ok(c) = Command::decode(&buf[..n]) else {
                continue;
            };
            if !delay.is_zero() {
                thread::sleep(delay);
            }
            seq += 1;
            let out = answer(&c, seq, ECHO_POSITION).encoded();
            let _ = sock.send_to(&out, peer);
        }
    });
    addr
}

/// The same device speaking protocol version 2 with `key`: answers a HELLO with a WELCOME, and
/// every authentic command of its session with an authentic state.
pub fn spawn_echo_device_v2(key: haptic2d_devices::udp::UdpKey) -> SocketAddr {
    use haptic2d_devices::udp::auth::{COMMAND2_LEN, HELLO_LEN, NONCE_LEN, STATE2_LEN};
    use haptic2d_devices::udp::codec::{COMMAND_LEN, KIND_COMMAND};
    let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = sock.local_addr().unwrap();
    thread::spawn(move || {
        let mut buf = [0u8; 256];
        let (mut seq, mut session) = (0, 0);
        while let Ok((n, peer)) = sock.recv_from(&mut buf) {
            if n == HELLO_LEN && key.verify(&buf[..n]) {
                let mut hn = [0u8; NONCE_LEN];
                hn.copy_from_slice(&buf[12..12 + NONCE_LEN]);
                session = key.session_id(&hn, &[7; NONCE_LEN]);
                let _ = sock.send_to(&key.welcome(&hn, &[7; NONCE_LEN]), peer);
                continue;
            }
            let mut v1 = [0u8; COMMAND_LEN];
            if key
                .open2(&buf[..n], KIND_COMMAND, COMMAND2_LEN, session, &mut v1)
                .is_err()
            {
                continue;
            }
            let Ok(c) = Command::decode(&v1) else {
                continue;
            };
            seq += 1;
            let out = answer(&c, seq, ECHO_POSITION).encoded();
            let mut out2 = [0u8; STATE2_LEN];
            key.state2(session, &out, &mut out2);
            let _ = sock.send_to(&out2, peer);
        }
    });
    addr
}
