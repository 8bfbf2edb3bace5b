//! Safety of the Haply driver (issue 12 item 6): a lost device is an error within the timeout, no
//! panic; garbage and truncated replies give a clear error after one resynchronisation; the device
//! file's torque limit is enforced in the driver; zero torques are sent before the port closes.

mod support;
use support::*;

use std::collections::VecDeque;
use std::io::{Read, Write};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use haptic2d::device::HandModel;
use haptic2d_devices::haply::codec::{decode_host_frame, BoardSetup, HostFrame};
use haptic2d_devices::haply::{Firmware, HaplyDevice, HaplyError, Transport};
use haptic2d_rt::{DeviceError, DeviceIo};

/// An in-memory board: a [`Firmware`] answering writes, with a hook that may corrupt reply `n`.
#[derive(Clone)]
struct MockBoard {
    fw: Arc<Mutex<Firmware>>,
    to_host: Arc<Mutex<VecDeque<u8>>>,
    from_host: Arc<Mutex<Vec<u8>>>,
    replies: Arc<Mutex<usize>>,
    corrupt: fn(usize, &mut Vec<u8>),
}

impl MockBoard {
    fn new(corrupt: fn(usize, &mut Vec<u8>)) -> Self {
        let file = device_file("haply-2diy-gen3.toml");
        Self {
            fw: Arc::new(Mutex::new(Firmware::new(&file))),
            to_host: Default::default(),
            from_host: Default::default(),
            replies: Default::default(),
            corrupt,
        }
    }

    /// Torques of every write frame the host sent, in order.
    fn writes(&self) -> Vec<[f32; 4]> {
        let bytes = self.from_host.lock().unwrap().clone();
        let mut setup = BoardSetup::empty(1);
        let mut at = 0;
        let mut out = Vec::new();
        while let Ok(Some((f, n))) = decode_host_frame(&bytes[at..], &setup) {
            match f {
                HostFrame::Setup(s) => setup = s,
                HostFrame::Write { torques, .. } => out.push(torques),
                HostFrame::Reset { .. } => {}
            }
            at += n;
        }
        out
    }
}

impl Read for MockBoard {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let mut q = self.to_host.lock().unwrap();
        let n = buf.len().min(q.len());
        for b in buf.iter_mut().take(n) {
            *b = q.pop_front().unwrap();
        }
        Ok(n)
    }
}

impl Write for MockBoard {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.from_host.lock().unwrap().extend_from_slice(buf);
        let mut fw = self.fw.lock().unwrap();
        fw.receive(buf);
        let mut out = [0u8; 65];
        let q = [0.3f64.to_radians() + 2.0, 1.0, 0.0, 0.0];
        while let Some(n) = fw.service(&q, &mut out) {
            if n > 0 {
                let mut r = out[..n].to_vec();
                let mut k = self.replies.lock().unwrap();
                (self.corrupt)(*k, &mut r);
                *k += 1;
                self.to_host.lock().unwrap().extend(r);
            }
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

fn open_mock(board: &MockBoard, torque_limit: f64) -> Result<HaplyDevice<MockBoard>, String> {
    let mut file = device_file("haply-2diy-gen3.toml");
    file.timeout_periods = 3.0;
    file.torque_limit = torque_limit;
    HaplyDevice::open(board.clone(), &file, Duration::from_millis(1), "haply:mock")
}

#[test]
fn torque_limit_of_the_device_file_is_enforced_in_the_driver() {
    let board = MockBoard::new(|_, _| {});
    let mut dev = open_mock(&board, 0.05).unwrap();
    dev.read_encoders().unwrap();
    dev.write_torques(&[1.0, -0.2, 0.0, 0.0]).unwrap();
    // Joint 0 (motor 1) is on port 2, joint 1 on port 1.
    assert_eq!(&dev.last_sent()[..2], &[-0.05, 0.05]);
    assert_eq!(board.writes().last().unwrap()[..2], [-0.05, 0.05]);
}

#[test]
fn non_finite_torque_sends_zeros_and_fails() {
    let board = MockBoard::new(|_, _| {});
    let mut dev = open_mock(&board, 0.123).unwrap();
    dev.read_encoders().unwrap();
    let e = dev.write_torques(&[f64::NAN, 0.1, 0.0, 0.0]).unwrap_err();
    assert!(
        matches!(e, DeviceError::Io(ref m) if m.contains("non-finite") && m.contains("zero")),
        "{e}"
    );
    assert_eq!(board.writes().last().unwrap()[..2], [0.0, 0.0]);
}

#[test]
fn dropping_the_driver_sends_zero_torques_before_the_port_closes() {
    let board = MockBoard::new(|_, _| {});
    let mut dev = open_mock(&board, 0.123).unwrap();
    dev.read_encoders().unwrap();
    dev.write_torques(&[0.1, 0.1, 0.0, 0.0]).unwrap();
    drop(dev);
    let w = board.writes();
    assert_eq!(w[w.len() - 2][..2], [0.1, 0.1]);
    assert_eq!(w.last().unwrap()[..2], [0.0, 0.0]);
}

#[test]
fn one_wrong_id_is_resynchronised_with_zero_torques() {
    // Reply 2 (the second after the handshake) comes with a wrong first byte.
    let board = MockBoard::new(|k, r| {
        if k == 2 {
            r[0] = 0x7f;
        }
    });
    let mut dev = open_mock(&board, 0.123).unwrap();
    dev.read_encoders().unwrap();
    dev.write_torques(&[0.1, 0.1, 0.0, 0.0]).unwrap();
    let q = dev.read_encoders().unwrap();
    assert!(q.iter().all(|v| v.is_finite()));
    assert_eq!(dev.resyncs(), 1);
    // The resynchronisation sent reset + setup + a zero write.
    assert_eq!(board.writes().last().unwrap()[..2], [0.0, 0.0]);
}

#[test]
fn truncated_replies_twice_stop_with_a_clear_error() {
    let board = MockBoard::new(|k, r| {
        if k >= 2 {
            r.truncate(5);
        }
    });
    let mut dev = open_mock(&board, 0.123).unwrap();
    dev.read_encoders().unwrap();
    dev.write_torques(&[0.0; 4]).unwrap();
    let e = dev.read_encoders().unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, DeviceError::Lost(_)), "{msg}");
    assert!(
        msg.contains("out of step") && msg.contains("haply:mock") && msg.contains("check"),
        "{msg}"
    );
    assert_eq!(dev.resyncs(), 1);
}

#[test]
fn random_garbage_never_panics_and_is_an_error() {
    // A deterministic byte soup in place of every reply after the handshake.
    for seed in 1..40u64 {
        let mut x = seed;
        let mut soup = Vec::new();
        for _ in 0..64 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            soup.push((x & 0xff) as u8);
        }
        let soup = Arc::new(soup);
        let mut t = Transport::from_stream(
            Garbage {
                soup: soup.clone(),
                at: 0,
            },
            device_file("haply-2diy-gen3.toml").board_setup(),
            Duration::from_millis(2),
        )
        .unwrap();
        // Every outcome is a typed error or (if the soup happens to start with the id and be
        // finite) a reply; never a panic.
        match t.handshake() {
            Ok(_) | Err(HaplyError::OutOfStep(_)) | Err(HaplyError::Lost(_)) => {}
            Err(e) => panic!("seed {seed}: unexpected {e:?}"),
        }
    }
}

struct Garbage {
    soup: Arc<Vec<u8>>,
    at: usize,
}
impl Read for Garbage {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = buf.len().min(self.soup.len() - self.at).min(3);
        buf[..n].copy_from_slice(&self.soup[self.at..self.at + n]);
        self.at += n;
        Ok(n)
    }
}
impl Write for Garbage {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn emulator_killed_mid_run_is_a_lost_device_within_the_timeout() {
    // 20 periods: the live phase must not time out on a machine shared with compilers.
    let mut file = device_file("haply-2diy-gen3.toml");
    file.timeout_periods = 20.0;
    let start = file.workspace_center();
    let mut emu = start_emulator(&file, HandModel::grip(start), 0.001);
    let port = haptic2d_devices::haply::serial::open_port(&emu.path).unwrap();
    let mut dev = HaplyDevice::open(port, &file, Duration::from_millis(1), "haply:pty").unwrap();
    for _ in 0..100 {
        dev.read_encoders().unwrap();
        dev.write_torques(&[0.01, 0.01, 0.0, 0.0]).unwrap();
    }
    emu.kill();
    let t0 = Instant::now();
    let e = dev.read_encoders().unwrap_err();
    let waited = t0.elapsed();
    let msg = e.to_string();
    assert!(matches!(e, DeviceError::Lost(_)), "{msg}");
    assert!(msg.contains("haply:pty") && msg.contains("check"), "{msg}");
    // Within the timeout (20 ms) plus scheduling slack on a shared machine.
    assert!(waited < Duration::from_millis(200), "{waited:?}");
    // Later calls fail at once, and zeroing does not block or panic.
    assert!(dev.write_torques(&[0.1; 4]).is_err());
    dev.zero_torques();
}
