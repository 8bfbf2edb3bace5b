//! haptic2d's own board firmware (`devices/firmware`, docs/FIRMWARE.md), compiled natively with `cc`
//! against its Arduino stub, spoken to in raw protocol bytes over its pseudo-terminal; what the
//! motors do is read from the stub's motor log (every change of the PWM and direction pins).
//!
//! Timing assertions allow a scheduling margin (the firmware runs as a normal process on a shared
//! machine) and every wait polls against a deadline.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use haptic2d_devices::haply::serial::{open_port, BoardPort};
use haptic2d_test_support::firmware::{compile_native_firmware, start_native_firmware};
use haptic2d_test_support::process::Killed;
use haptic2d_test_support::{holds_for, wait_until};

/// How late past its time the native watchdog may act on a loaded machine (µs).
const SCHEDULING_MARGIN_US: u64 = 30_000;

/// Board variants of the native build.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Board {
    M0,
    M3,
}

/// Compiles the native firmware for `board` once per test binary; returns the executable.
fn firmware_exe(board: Board) -> PathBuf {
    static M0: OnceLock<PathBuf> = OnceLock::new();
    static M3: OnceLock<PathBuf> = OnceLock::new();
    let cell = match board {
        Board::M0 => &M0,
        Board::M3 => &M3,
    };
    cell.get_or_init(|| compile(board)).clone()
}

fn compile(board: Board) -> PathBuf {
    let dir =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("fw-native-{}", std::process::id()));
    compile_native_firmware(&format!("{board:?}"), &dir)
}

/// A running native firmware: its pseudo-terminal and its motor log. Killed on drop.
struct Firmware {
    _child: Killed,
    pty: String,
    log: PathBuf,
}

impl Firmware {
    fn start(board: Board, tag: &str) -> Self {
        Self::start_with(board, tag, &[])
    }

    /// Started with extra arguments (e.g. `--hand-move`).
    fn start_with(board: Board, tag: &str, args: &[&str]) -> Self {
        let exe = firmware_exe(board);
        let log = exe.with_file_name(format!("motors-{tag}.txt"));
        let (child, pty) = start_native_firmware(&exe, &log, args);
        Self {
            _child: child,
            pty,
            log,
        }
    }

    fn port(&self) -> BoardPort {
        open_port(&self.pty).unwrap()
    }

    fn log(&self) -> MotorLog {
        MotorLog::parse(&std::fs::read_to_string(&self.log).unwrap())
    }

    /// Polls the motor log until `done` holds (or panics after `limit`).
    fn wait_log(&self, limit: Duration, what: &str, done: impl Fn(&MotorLog) -> bool) -> MotorLog {
        let mut log = self.log();
        let seen = wait_until(Instant::now() + limit, || {
            log = self.log();
            done(&log)
        });
        assert!(
            seen,
            "{what}: not seen within {limit:?}; motor log:\n{}",
            log.tail()
        );
        log
    }
}

impl Drop for Firmware {
    fn drop(&mut self) {
        // The child is killed when `_child` drops, after this.
        if !std::thread::panicking() {
            let _ = std::fs::remove_file(&self.log);
        }
    }
}

/// One line of the motor log.
#[derive(Clone, Debug, PartialEq)]
enum Entry {
    /// Motor outputs changed: time (µs), torque per port (N·m, signed by the direction pin).
    Motors(u64, [f64; 4]),
    /// An event of the firmware: time (µs), name.
    Event(u64, String),
}

struct MotorLog {
    entries: Vec<Entry>,
    text: String,
}

impl MotorLog {
    fn parse(text: &str) -> Self {
        let mut entries = Vec::new();
        for line in text.lines() {
            // A line being written may be incomplete: only whole lines count.
            let f: Vec<&str> = line.split_whitespace().collect();
            match f.first() {
                Some(&"M") if f.len() == 10 => {
                    let t = f[1].parse().unwrap();
                    let tau = std::array::from_fn(|k| f[6 + k].parse().unwrap());
                    entries.push(Entry::Motors(t, tau));
                }
                Some(&"E") if f.len() == 3 => {
                    entries.push(Entry::Event(f[1].parse().unwrap(), f[2].to_string()))
                }
                _ => {}
            }
        }
        Self {
            entries,
            text: text.to_string(),
        }
    }

    fn tail(&self) -> String {
        let lines: Vec<&str> = self.text.lines().collect();
        lines[lines.len().saturating_sub(25)..].join("\n")
    }

    /// Torques after the whole log.
    fn now(&self) -> [f64; 4] {
        self.entries
            .len()
            .checked_sub(1)
            .map_or([0.0; 4], |i| self.at(i))
    }

    /// Index and time of the last event `name`.
    fn last_event(&self, name: &str) -> Option<(usize, u64)> {
        self.entries
            .iter()
            .enumerate()
            .rev()
            .find_map(|(i, e)| match e {
                Entry::Event(t, n) if n == name => Some((i, *t)),
                _ => None,
            })
    }

    /// Torques right after entry `i`.
    fn at(&self, i: usize) -> [f64; 4] {
        self.entries[..=i]
            .iter()
            .rev()
            .find_map(|e| match e {
                Entry::Motors(_, t) => Some(*t),
                _ => None,
            })
            .unwrap_or([0.0; 4])
    }

    /// Time of the first motor change after entry `i` that leaves every output zero.
    fn zero_after(&self, i: usize) -> Option<u64> {
        self.entries[i + 1..].iter().find_map(|e| match e {
            Entry::Motors(t, tau) if tau.iter().all(|&x| x == 0.0) => Some(*t),
            _ => None,
        })
    }

    fn has_event(&self, name: &str) -> bool {
        self.last_event(name).is_some()
    }
}

/// Reads exactly `n` bytes, or what came within `limit`.
fn read_n(port: &mut BoardPort, n: usize, limit: Duration) -> Vec<u8> {
    let mut out = vec![0u8; n];
    let mut got = 0;
    let t0 = Instant::now();
    while got < n && t0.elapsed() < limit {
        match port.read(&mut out[got..]) {
            Ok(k) => got += k,
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
            Err(e) => panic!("reading the pty: {e}"),
        }
    }
    out.truncate(got);
    out
}

/// Bytes arriving within `limit` (for "no reply" checks).
fn read_any(port: &mut BoardPort, limit: Duration) -> Vec<u8> {
    read_n(port, 256, limit)
}

fn send(port: &mut BoardPort, bytes: &[u8]) {
    port.write_all(bytes).unwrap();
    port.flush().unwrap();
}

/// The identity frame our firmware must send: `[0x03]['H','2','D','F'][1][ports][7][ms LE]`.
fn identity(ports: u8, watchdog_ms: u16) -> Vec<u8> {
    let mut v = vec![0x03, b'H', b'2', b'D', b'F', 1, ports, 0b111];
    v.extend_from_slice(&watchdog_ms.to_le_bytes());
    v
}

/// A setup of board 1: motors and encoders on the ports of `mask` (all CCW), analog `pins`,
/// encoder `(offset°, counts per turn)` per used port.
fn setup_frame(mask: u8, pins: &[u8], enc: &[(f32, f32)]) -> Vec<u8> {
    let n = mask.count_ones() as usize;
    assert_eq!(enc.len(), n);
    let mut v = vec![0x01, 1, mask];
    v.extend(std::iter::repeat_n(1u8, n));
    v.push(mask);
    v.extend(std::iter::repeat_n(1u8, n));
    v.push(pins.len() as u8);
    v.extend_from_slice(pins);
    v.push(0);
    for (o, r) in enc {
        v.extend_from_slice(&o.to_le_bytes());
        v.extend_from_slice(&r.to_le_bytes());
    }
    v
}

fn write_frame(torques: &[f32]) -> Vec<u8> {
    let mut v = vec![0x02, 1];
    for t in torques {
        v.extend_from_slice(&t.to_le_bytes());
    }
    v
}

/// The shipped gen 3 encoders (DEVICES §2): offsets 168° and 12°, 4880 counts per turn.
const GEN3: [(f32, f32); 2] = [(168.0, 4880.0), (12.0, 4880.0)];

fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// The angle DEVICES §1 says a board reports at the setup pose: the count is
/// `trunc(offset · resolution / 360)`, the angle `360 · count / resolution`.
fn truncated_angle(offset: f32, resolution: f32) -> f32 {
    let count = (offset * resolution / 360.0).trunc();
    360.0 * count / resolution
}

const WAIT: Duration = Duration::from_secs(3);

/// An M3 board started as `tag`, its watchdog set to `watchdog_ms` first where given (the 20 ms
/// default otherwise), then set up with motors and encoders on ports 1 and 2 ([`GEN3`]); the
/// board and its port.
fn set_up_m3(tag: &str, watchdog_ms: Option<u16>) -> (Firmware, BoardPort) {
    let fw = Firmware::start(Board::M3, tag);
    let mut port = fw.port();
    if let Some(ms) = watchdog_ms {
        let [lo, hi] = ms.to_le_bytes();
        send(&mut port, &[0x04, lo, hi]);
        assert_eq!(read_n(&mut port, 10, WAIT), identity(4, ms));
    }
    send(&mut port, &setup_frame(0b11, &[], &GEN3));
    (fw, port)
}

#[test]
fn identify_answers_h2df_version_1_its_ports_its_capabilities_and_the_20_ms_default() {
    for (board, ports) in [(Board::M3, 4u8), (Board::M0, 2u8)] {
        let fw = Firmware::start(board, &format!("identify-{board:?}"));
        let mut port = fw.port();
        send(&mut port, &[0x03]);
        assert_eq!(
            read_n(&mut port, 10, WAIT),
            identity(ports, 20),
            "{board:?}"
        );
        // Nothing more than the 10 bytes.
        assert!(read_any(&mut port, Duration::from_millis(50)).is_empty());
    }
}

#[test]
fn set_watchdog_takes_1_to_1000_ms_keeps_the_old_value_otherwise_and_answers_the_identity() {
    let fw = Firmware::start(Board::M3, "set-watchdog");
    let mut port = fw.port();
    let set = |port: &mut BoardPort, ms: u16| {
        let mut f = vec![0x04];
        f.extend_from_slice(&ms.to_le_bytes());
        send(port, &f);
        read_n(port, 10, WAIT)
    };
    assert_eq!(set(&mut port, 50), identity(4, 50));
    assert_eq!(set(&mut port, 0), identity(4, 50), "0 ms is out of range");
    assert_eq!(
        set(&mut port, 1001),
        identity(4, 50),
        "1001 ms is out of range"
    );
    assert_eq!(set(&mut port, 1), identity(4, 1));
    assert_eq!(set(&mut port, 1000), identity(4, 1000));
    send(&mut port, &[0x03]);
    assert_eq!(read_n(&mut port, 10, WAIT), identity(4, 1000));
}

#[test]
fn motors_are_zero_at_power_up_and_nothing_answers_reset_or_setup() {
    let fw = Firmware::start(Board::M3, "power-up");
    let log = fw.log();
    assert!(
        matches!(log.entries.first(), Some(Entry::Motors(_, t)) if *t == [0.0; 4]),
        "the first thing the board does is zero its motors:\n{}",
        log.tail()
    );
    let mut port = fw.port();
    send(&mut port, &[0x00, 1]);
    send(&mut port, &setup_frame(0b11, &[], &GEN3));
    assert!(read_any(&mut port, Duration::from_millis(100)).is_empty());
    fw.wait_log(WAIT, "the setup", |l| l.has_event("setup"));
}

#[test]
fn a_write_of_0_3_nm_is_clamped_to_0_123_on_the_board_and_answered_with_truncated_angles() {
    let (fw, mut port) = set_up_m3("clamp", None);
    send(&mut port, &write_frame(&[0.3, -0.3]));
    let reply = read_n(&mut port, 9, WAIT);
    assert_eq!(reply.len(), 9, "reply {reply:?}");
    assert_eq!(reply[0], 1, "the board id");
    // Static encoders: the handle is where the setup put it.
    let want = [
        truncated_angle(GEN3[0].0, GEN3[0].1),
        truncated_angle(GEN3[1].0, GEN3[1].1),
    ];
    assert_eq!(f32s(&reply[1..]), want);
    assert!(want[0] < 168.0 && want[1] < 12.0, "truncated, not rounded");
    let log = fw.wait_log(WAIT, "the write", |l| l.has_event("write"));
    let (i, _) = log.last_event("write").unwrap();
    let tau = log.at(i);
    assert_eq!(tau, [0.123, -0.123, 0.0, 0.0], "{}", log.tail());
    // Below the clamp the duty is proportional (12-bit at the clamp).
    send(&mut port, &write_frame(&[0.0615, 0.0]));
    read_n(&mut port, 9, WAIT);
    let log = fw.wait_log(WAIT, "the half-torque write", |l| {
        (l.now()[0] - 0.0615).abs() < 0.123 / 4095.0 && l.now()[1] == 0.0
    });
    assert_eq!(log.now()[2..], [0.0, 0.0]);
}

#[test]
fn non_finite_torques_drive_nothing() {
    let (fw, mut port) = set_up_m3("nan", None);
    send(&mut port, &write_frame(&[f32::NAN, f32::INFINITY]));
    assert_eq!(read_n(&mut port, 9, WAIT).len(), 9);
    let log = fw.wait_log(WAIT, "the write", |l| l.has_event("write"));
    let (i, _) = log.last_event("write").unwrap();
    assert_eq!(log.at(i), [0.0; 4], "{}", log.tail());
}

#[test]
fn analog_inputs_are_reported_in_ascending_pin_order() {
    let fw = Firmware::start(Board::M3, "analog");
    let mut port = fw.port();
    // A2, A0, A11 listed out of order; the stub's analogRead(pin) is 4·pin.
    send(&mut port, &setup_frame(0b01, &[56, 54, 65], &GEN3[..1]));
    send(&mut port, &write_frame(&[0.0]));
    let reply = read_n(&mut port, 1 + 4 * 4, WAIT);
    assert_eq!(reply.len(), 17, "reply {reply:?}");
    assert_eq!(
        f32s(&reply[1..]),
        [
            4.0 * 54.0,
            4.0 * 56.0,
            4.0 * 65.0,
            truncated_angle(GEN3[0].0, GEN3[0].1)
        ]
    );
}

#[test]
fn reset_zeroes_the_motors_at_once() {
    // A long watchdog, so that only the reset can zero the motors within the test's wait.
    let (fw, mut port) = set_up_m3("reset", Some(1000));
    send(&mut port, &write_frame(&[0.1, -0.05]));
    assert_eq!(read_n(&mut port, 9, WAIT).len(), 9);
    fw.wait_log(WAIT, "torque on", |l| l.now()[0] > 0.09);
    send(&mut port, &[0x00, 1]);
    let log = fw.wait_log(WAIT, "the reset", |l| l.has_event("reset"));
    let (i, t_reset) = log.last_event("reset").unwrap();
    assert_eq!(log.at(i), [0.0; 4], "{}", log.tail());
    assert!(!log.has_event("watchdog"), "{}", log.tail());
    let (_, t_write) = log.last_event("write").unwrap();
    assert!(t_reset - t_write < 1_000_000, "{}", log.tail());
}

#[test]
fn a_new_setup_zeroes_the_motors() {
    let (fw, mut port) = set_up_m3("re-setup", Some(1000));
    send(&mut port, &write_frame(&[0.1, 0.1]));
    assert_eq!(read_n(&mut port, 9, WAIT).len(), 9);
    fw.wait_log(WAIT, "torque on", |l| l.now()[0] > 0.09);
    send(&mut port, &setup_frame(0b11, &[], &GEN3));
    let log = fw.wait_log(WAIT, "the second setup", |l| {
        l.entries
            .iter()
            .filter(|e| matches!(e, Entry::Event(_, n) if n == "setup"))
            .count()
            == 2
    });
    let (i, _) = log.last_event("setup").unwrap();
    assert_eq!(log.at(i), [0.0; 4], "{}", log.tail());
    assert!(!log.has_event("watchdog"), "{}", log.tail());
}

/// Writes at about 1 kHz for `for_ms`, then stops; returns the log once the motors are zero
/// (panics if they are not within `limit`) with the time from the last write to zero (µs).
fn stop_writing_and_time_the_zero(fw: &Firmware, port: &mut BoardPort, for_ms: u64) -> u64 {
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_millis(for_ms) {
        send(port, &write_frame(&[0.1, -0.1]));
        assert_eq!(read_n(port, 9, WAIT).len(), 9);
        std::thread::sleep(Duration::from_millis(1));
    }
    let log = fw.wait_log(
        WAIT,
        "all motors zero after the last write (is the watchdog running?)",
        |l| {
            l.last_event("write")
                .is_some_and(|(i, _)| l.zero_after(i).is_some())
        },
    );
    let (i, t_write) = log.last_event("write").unwrap();
    assert!(
        log.at(i).iter().any(|&t| t != 0.0),
        "torques were on at the last write:\n{}",
        log.tail()
    );
    let t_zero = log.zero_after(i).unwrap();
    // Nothing turns them on again: zero throughout 50 ms.
    let mut later = fw.log();
    let stays_zero = holds_for(Duration::from_millis(50), || {
        later = fw.log();
        later.now() == [0.0; 4]
    });
    assert!(stays_zero, "{}", later.tail());
    t_zero - t_write
}

/// Sets up an M3 board (its watchdog set to `set_ms` first, where given; 20 ms otherwise), stops
/// writing and checks that the motors are zero `watchdog_ms` after the last write, within the
/// scheduling margin.
fn check_watchdog_zeroes_the_motors(tag: &str, set_ms: Option<u16>, watchdog_ms: u64) {
    let (fw, mut port) = set_up_m3(tag, set_ms);
    let dt = stop_writing_and_time_the_zero(&fw, &mut port, 100);
    let at = watchdog_ms * 1000;
    assert!(
        (at..=at + SCHEDULING_MARGIN_US).contains(&dt),
        "motors zero {dt} µs after the last write; the watchdog is {watchdog_ms} ms"
    );
}

#[test]
fn motors_are_zero_within_the_20_ms_watchdog_when_the_host_stops_writing() {
    check_watchdog_zeroes_the_motors("watchdog-default", None, 20);
}

#[test]
fn a_watchdog_set_to_80_ms_zeroes_the_motors_80_ms_after_the_last_write() {
    check_watchdog_zeroes_the_motors("watchdog-80", Some(80), 80);
}

#[test]
fn an_incomplete_frame_left_for_10_ms_is_dropped_not_completed_by_later_bytes() {
    let (fw, mut port) = set_up_m3("stale", Some(1000));
    // A host dies after the first 2 bytes of a write; its torques arrive (from someone) 50 ms later.
    send(&mut port, &[0x02, 1]);
    fw.wait_log(WAIT, "the stale frame dropped", |l| {
        l.has_event("stale-frame")
    });
    let rest: Vec<u8> = [0.1f32, 0.1].iter().flat_map(|t| t.to_le_bytes()).collect();
    send(&mut port, &rest);
    fw.wait_log(WAIT, "the late bytes skipped", |l| {
        l.entries
            .iter()
            .filter(|e| matches!(e, Entry::Event(_, n) if n == "bad-byte"))
            .count()
            == 8
    });
    let log = fw.log();
    assert!(!log.has_event("write"), "{}", log.tail());
    assert_eq!(log.now(), [0.0; 4]);
    assert!(read_any(&mut port, Duration::from_millis(50)).is_empty());
}

#[test]
fn an_m0_board_drives_2_ports_and_answers_a_4_port_setup_short() {
    let fw = Firmware::start(Board::M0, "m0-ports");
    let mut port = fw.port();
    let enc = [
        (168.0, 4880.0),
        (12.0, 4880.0),
        (90.0, 4880.0),
        (45.0, 4880.0),
    ];
    send(&mut port, &setup_frame(0b1111, &[], &enc));
    send(&mut port, &write_frame(&[0.05, 0.05, 0.05, 0.05]));
    // 2 of the 4 angles: shorter than asked, not silence.
    let reply = read_n(&mut port, 17, Duration::from_millis(300));
    assert_eq!(reply.len(), 9, "reply {reply:?}");
    assert_eq!(
        f32s(&reply[1..]),
        [
            truncated_angle(168.0, 4880.0),
            truncated_angle(12.0, 4880.0)
        ]
    );
    let log = fw.wait_log(WAIT, "the write", |l| l.has_event("write"));
    let (i, _) = log.last_event("write").unwrap();
    let tau = log.at(i);
    assert!((tau[0] - 0.05).abs() < 0.123 / 1023.0, "{tau:?}");
    assert!((tau[1] - 0.05).abs() < 0.123 / 1023.0, "{tau:?}");
    assert_eq!(tau[2..], [0.0, 0.0]);
}

#[test]
fn encoder_motion_is_counted_from_the_setup_count_in_the_direction_the_setup_names() {
    // The stub's hand turns encoder port 1 by +100 and port 2 by -40 counts, 500 ms after each
    // setup (quadrature edges into board.c's decoder). Port 1 is set up counter-clockwise (counts add),
    // port 2 clockwise (counts subtract).
    let fw = Firmware::start_with(
        Board::M3,
        "encoders",
        &["--hand-move", "500,20,100,-40,0,0"],
    );
    let mut port = fw.port();
    let mut setup = setup_frame(0b11, &[], &GEN3);
    setup[7] = 0; // enc_dir of port 2: clockwise
    assert_eq!(&setup[3..8], &[1, 1, 0b11, 1, 0]);
    send(&mut port, &setup);
    let angles = |port: &mut BoardPort| {
        send(port, &write_frame(&[0.0, 0.0]));
        let r = read_n(port, 9, WAIT);
        assert_eq!(r.len(), 9, "reply {r:?}");
        f32s(&r[1..])
    };
    let count = |o: f32, r: f32| (o * r / 360.0).trunc();
    let (c1, c2) = (count(GEN3[0].0, GEN3[0].1), count(GEN3[1].0, GEN3[1].1));
    let want = [
        360.0 * (c1 + 100.0) / GEN3[0].1,
        360.0 * (c2 + 40.0) / GEN3[1].1,
    ];
    let t0 = Instant::now();
    let mut got = angles(&mut port);
    while got != want && t0.elapsed() < WAIT {
        std::thread::sleep(Duration::from_millis(5));
        got = angles(&mut port);
    }
    assert_eq!(got, want, "angles after the hand's move");
    // A new setup puts the count back to the setup count wherever the handle is (DEVICES §1).
    send(&mut port, &setup_frame(0b11, &[], &GEN3));
    assert_eq!(
        angles(&mut port),
        [
            truncated_angle(GEN3[0].0, GEN3[0].1),
            truncated_angle(GEN3[1].0, GEN3[1].1)
        ]
    );
}
