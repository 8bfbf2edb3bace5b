//! Protocol version 2 against both reference devices (issue 38, finding 1: "a third process drove
//! the handle 15–16 mm at the full 0.123 N·m"): devices/udp/sim_device.py and sim_device.c, each
//! in its own process with a key file and a trace of every command it acts on. The test is the
//! genuine host (it holds the key) and, from another socket, the third process: version-1
//! commands, commands with a wrong MAC, replays of the host's own datagrams (commands and HELLO).
//! Only the genuine commands may act; after the host falls silent the device zeroes its output.
//! Skipped (with a note) where `python3` or `cc` is missing.

use std::net::{SocketAddr, UdpSocket};
use std::path::{Path, PathBuf};
use std::process::Command as Process;
use std::time::{Duration, Instant};

use haptic2d_devices::udp::auth::{
    UdpKey, COMMAND2_LEN, HELLO_LEN, NONCE_LEN, STATE2_LEN, WELCOME_LEN,
};
use haptic2d_devices::udp::codec::{
    Command, State, COMMAND_LEN, FLAG_ENABLE, KIND_STATE, STATE_LEN,
};
use haptic2d_test_support::process::Killed;
use haptic2d_test_support::udp_device::{device_command, start_device, Which};
use haptic2d_test_support::wait_until;

use crate::udp_reference::{answers_at_the_start_pose, patient_reference};

const KEY_HEX: &str = "8f1c2a9e4b7d6035f2e1c0b9a8d7e6f5041322f1e0d9c8b7a6958473625140ff";

fn key() -> UdpKey {
    UdpKey::from_bytes(&haptic2d_devices::udp::auth::key_bytes(KEY_HEX.as_bytes())).unwrap()
}

/// The key file (mode 600) in the test's temp dir.
fn key_file(tag: &str, mode: u32) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let p = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("udp-auth-{tag}.key"));
    std::fs::write(&p, format!("{KEY_HEX}\n")).unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(mode)).unwrap();
    p
}

/// The reference device's command line (`None` where its tool is missing).
fn device_cmd(which: Which) -> Option<Process> {
    // One C executable per call: tests build it concurrently.
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let exe = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("udp_sim_device_auth_{}_{n}", std::process::id()));
    device_command(which, &exe)
}

/// Starts the device on a loopback port with `args`; its address.
fn start(which: Which, args: &[&str]) -> Option<(Killed, SocketAddr)> {
    Some(start_device(device_cmd(which)?, args))
}

/// A version-2 command of `session`, seq `seq`, ENABLE, torques `tau`, sealed with `key`.
fn command2(key: &UdpKey, session: u64, seq: u32, tau: [f32; 2]) -> [u8; COMMAND2_LEN] {
    let mut v1 = [0u8; COMMAND_LEN];
    Command {
        seq,
        host_time_ns: u64::from(seq) * 1000,
        echo_device_ns: 0,
        echo_seq: 0,
        flags: FLAG_ENABLE,
        command: [tau[0], tau[1], 0.0],
    }
    .encode(&mut v1);
    let mut out = [0u8; COMMAND2_LEN];
    key.command2(session, &v1, &mut out);
    out
}

/// Every datagram `sock` receives within `wait`.
fn received(sock: &UdpSocket, wait: Duration) -> Vec<Vec<u8>> {
    let end = Instant::now() + wait;
    let mut got = Vec::new();
    let mut buf = [0u8; 256];
    while Instant::now() < end {
        sock.set_read_timeout(Some(Duration::from_millis(10)))
            .unwrap();
        if let Ok(n) = sock.recv(&mut buf) {
            got.push(buf[..n].to_vec());
        }
    }
    got
}

/// The genuine host's answer to `cmd`: a state of `session` with a valid MAC answering `seq`.
fn exchange(host: &UdpSocket, key: &UdpKey, session: u64, cmd: &[u8], seq: u32) {
    host.send(cmd).unwrap();
    let mut buf = [0u8; 256];
    host.set_read_timeout(Some(Duration::from_millis(500)))
        .unwrap();
    let n = host
        .recv(&mut buf)
        .expect("the device answers the genuine host");
    let mut v1 = [0u8; STATE_LEN];
    key.open2(&buf[..n], KIND_STATE, STATE2_LEN, session, &mut v1)
        .expect("an authentic state of the session");
    assert_eq!(State::decode(&v1).unwrap().echo_seq, seq);
}

fn attack(which: Which) {
    let trace = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("udp-auth-{which:?}.trace"));
    let kf = key_file(&format!("{which:?}"), 0o600);
    let Some((_dev, addr)) = start(
        which,
        &[
            "--key-file",
            kf.to_str().unwrap(),
            "--trace",
            trace.to_str().unwrap(),
        ],
    ) else {
        panic!("{which:?}: its tool (python3 or cc) is not installed: bash scripts/install-test-deps.sh installs it");
    };
    let k = key();
    let third = UdpSocket::bind("127.0.0.1:0").unwrap();
    third.connect(addr).unwrap();
    let host = UdpSocket::bind("127.0.0.1:0").unwrap();
    host.connect(addr).unwrap();

    // 1. The third process before any session: version-1 commands at 0.1 N·m, a HELLO and a
    //    command MAC'd with a guessed key. Nothing answers, nothing acts.
    let mut v1 = [0u8; COMMAND_LEN];
    for seq in 1..=5 {
        Command {
            seq,
            host_time_ns: 0,
            echo_device_ns: 0,
            echo_seq: 0,
            flags: FLAG_ENABLE,
            command: [0.1, 0.1, 0.0],
        }
        .encode(&mut v1);
        third.send(&v1).unwrap();
    }
    let guess = UdpKey::from_bytes(b"not the key, but 32 bytes of it.").unwrap();
    third.send(&guess.hello(&[3; NONCE_LEN])).unwrap();
    third.send(&command2(&guess, 7, 1, [0.1, 0.1])).unwrap();
    assert!(
        received(&third, Duration::from_millis(100)).is_empty(),
        "{which:?} answered a sender without the key"
    );

    // 2. The genuine host: a session and 20 commands at 0.01 N·m.
    let hn = [0x11; NONCE_LEN];
    let hello = k.hello(&hn);
    assert_eq!(hello.len(), HELLO_LEN);
    host.send(&hello).unwrap();
    let mut buf = [0u8; 256];
    host.set_read_timeout(Some(Duration::from_millis(1000)))
        .unwrap();
    let n = host.recv(&mut buf).expect("a WELCOME");
    assert_eq!(n, WELCOME_LEN);
    let session = k
        .check_welcome(&buf[..n], &hn)
        .expect("an authentic WELCOME");
    let mut sent = Vec::new();
    for seq in 1..=20 {
        let c = command2(&k, session, seq, [0.01, -0.01]);
        exchange(&host, &k, session, &c, seq);
        sent.push(c);
    }

    // 3. The third process during the session: replays of the host's commands, a forged command of
    //    the session at 0.1 N·m (bad MAC), one from a guessed key, and the host's HELLO replayed.
    third.send(&sent[19]).unwrap();
    third.send(&sent[9]).unwrap();
    let mut forged = command2(&k, session, 1000, [0.1, 0.1]);
    forged[COMMAND2_LEN - 1] ^= 1;
    third.send(&forged).unwrap();
    third
        .send(&command2(&guess, session, 1001, [0.1, 0.1]))
        .unwrap();
    third.send(&hello).unwrap();
    let got = received(&third, Duration::from_millis(100));
    assert!(
        got.iter().all(|d| d.len() == WELCOME_LEN),
        "{which:?} sent the third process a state: {got:?}"
    );

    // 4. The replayed HELLO did not end the host's session: it goes on.
    for seq in 21..=30 {
        let c = command2(&k, session, seq, [0.01, -0.01]);
        exchange(&host, &k, session, &c, seq);
    }

    // 5. Silence: the device's watchdog zeroes its output (its trace ends on the watchdog line).
    let mut t = String::new();
    wait_until(Instant::now() + Duration::from_secs(10), || {
        t = std::fs::read_to_string(&trace).unwrap_or_default();
        t.lines().last() == Some("watchdog 0 0")
    });
    let lines: Vec<&str> = t.lines().collect();
    let applied = lines.iter().filter(|l| l.starts_with("applied")).count();
    assert_eq!(
        applied, 30,
        "{which:?}: only the 30 genuine commands act\n{t}"
    );
    assert!(
        lines
            .iter()
            .filter(|l| l.starts_with("applied"))
            .all(|l| *l == "applied 0.010000 -0.010000"),
        "{which:?}: a command that was not the host's acted\n{t}"
    );
    assert_eq!(
        lines.last().copied(),
        Some("watchdog 0 0"),
        "{which:?}: output zeroed on silence\n{t}"
    );
}

#[test]
fn a_third_process_cannot_drive_the_python_reference_device() {
    attack(Which::Python);
}

#[test]
fn a_third_process_cannot_drive_the_c_reference_device() {
    attack(Which::C);
}

/// The host's driver with each reference device over version 2: a session, every answer fresh,
/// nothing dropped.
fn closed_loop(which: Which) {
    let kf = key_file(&format!("loop-{which:?}"), 0o600);
    let Some((_dev, addr)) = start(which, &["--key-file", kf.to_str().unwrap()]) else {
        panic!("{which:?}: its tool (python3 or cc) is not installed: bash scripts/install-test-deps.sh installs it");
    };
    let mut file = patient_reference();
    file.key = Some(UdpKey::from_file(&kf).unwrap());
    let c = answers_at_the_start_pose(addr, file, &format!("{which:?}"));
    assert_eq!(c.dropped(), 0, "{which:?}: {c}");
}

#[test]
fn the_python_reference_device_speaks_version_2_with_the_host() {
    closed_loop(Which::Python);
}

#[test]
fn the_c_reference_device_speaks_version_2_with_the_host() {
    closed_loop(Which::C);
}

#[test]
fn the_c_reference_device_passes_the_rfc_4231_vectors() {
    let Some(mut cmd) = device_cmd(Which::C) else {
        panic!("cc not found: this test builds the C reference device (bash scripts/install-test-deps.sh installs gcc)");
    };
    let o = cmd.arg("--self-test").output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && out.contains("test cases 1-7: ok"),
        "{out}"
    );
}

#[test]
fn reference_devices_refuse_version_1_beyond_loopback_and_open_key_files() {
    let open_key = key_file("open", 0o644);
    for which in [Which::Python, Which::C] {
        let Some(mut cmd) = device_cmd(which) else {
            panic!("{which:?}: its tool (python3 or cc) is not installed: bash scripts/install-test-deps.sh installs it");
        };
        // Binding the wildcard address without a key: refused before any datagram.
        let o = cmd
            .args(["--bind", "0.0.0.0:0", "--duration", "1"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{which:?}: {err}");
        assert!(err.contains("loopback only"), "{which:?}: {err}");
        let mut cmd = device_cmd(which).unwrap();
        let o = cmd
            .args(["--bind", "127.0.0.1:0", "--duration", "1", "--key-file"])
            .arg(&open_key)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_ne!(o.status.code(), Some(0), "{which:?}: {err}");
        assert!(err.contains("chmod 600"), "{which:?}: {err}");
    }
}
