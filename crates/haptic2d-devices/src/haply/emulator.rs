//! A stand-in Haply board: the firmware's behaviour (docs/DEVICES.md §1) over any byte stream, moving a
//! simulated linkage ([`Plant`]) under the motor torques and a simulated hand.
//!
//! What it reproduces:
//!
//! - reset, setup, write; a reply **only** after a write; nothing after reset or setup;
//! - a service time of at least 50 µs between two serviced frames;
//! - the torque clamp `|τ| ≤ 0.123 N·m` on every motor;
//! - encoder counts start at `offset_deg · resolution / 360` and the reported angle is
//!   `360 · count / resolution`;
//! - the direction-byte quirk (see [`decode_host_frame`]);
//! - a board wired as the emulator's own device file says (the *truth*): a host whose setup has a
//!   wrong direction byte sees that motor push the wrong way and that encoder count backwards, a
//!   wrong offset shifts the reported angle — which is what `haptic2d device check` detects.

use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use haptic2d::device::HandModel;

use super::codec::{
    decode_host_frame, encode_reply, used_ports, BoardSetup, CodecError, HostFrame, Rotation,
    CMD_WRITE, FIRMWARE_TORQUE_LIMIT, PORTS, REPLY_MAX_LEN,
};
use super::device_file::{HaplyDeviceFile, HaplyKind};
use super::plant::{Plant, Plant2};

/// How the emulated linkage's time advances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EmulatorClock {
    /// Wall time between serviced writes (a real board).
    RealTime,
    /// A fixed step per serviced write (s): reproducible physics, whatever the scheduling.
    PerWrite(f64),
}

/// How the emulated board is wired (from its device file).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Wiring {
    joints: usize,
    /// Port (0-based) of joint `j`.
    port_of: [usize; PORTS],
    motor_dir: [Rotation; PORTS],
    enc_dir: [Rotation; PORTS],
    offset_deg: [f64; PORTS],
    resolution: [f64; PORTS],
}

/// The firmware's state machine (no I/O): frames in, replies out.
#[derive(Clone, Debug)]
pub struct Firmware {
    wiring: Wiring,
    setup: BoardSetup,
    configured: bool,
    /// Held joint torques (N·m), after the clamp and the direction signs.
    torques: [f64; PORTS],
    buf: [u8; 256],
    len: usize,
    /// Frames serviced so far (all kinds).
    pub frames: u64,
    /// Writes answered so far.
    pub replies: u64,
    /// Bytes discarded as unknown commands.
    pub discarded: u64,
}

impl Firmware {
    /// A board wired as `file` says, not yet set up.
    pub fn new(file: &HaplyDeviceFile) -> Self {
        let mut w = Wiring {
            joints: file.joints(),
            port_of: [0; PORTS],
            motor_dir: [Rotation::Clockwise; PORTS],
            enc_dir: [Rotation::Clockwise; PORTS],
            offset_deg: [0.0; PORTS],
            resolution: [1.0; PORTS],
        };
        for (j, m) in file.motors.iter().enumerate() {
            let p = (m.port - 1) as usize;
            w.port_of[j] = p;
            w.motor_dir[p] = m.direction;
            w.enc_dir[p] = m.encoder_direction;
            w.offset_deg[p] = m.offset_deg;
            w.resolution[p] = m.counts_per_turn;
        }
        Self {
            wiring: w,
            setup: BoardSetup::empty(file.id),
            configured: false,
            torques: [0.0; PORTS],
            buf: [0; 256],
            len: 0,
            frames: 0,
            replies: 0,
            discarded: 0,
        }
    }

    /// The current set-up (as the firmware understood it).
    pub fn setup(&self) -> &BoardSetup {
        &self.setup
    }

    /// Held joint torques (N·m) in joint order.
    pub fn joint_torques(&self) -> [f64; PORTS] {
        let mut t = [0.0; PORTS];
        for (j, tj) in t.iter_mut().enumerate().take(self.wiring.joints) {
            *tj = self.torques[self.wiring.port_of[j]];
        }
        t
    }

    /// True when a complete write frame is next in the input.
    pub fn next_is_write(&self) -> bool {
        self.len > 0 && self.buf[0] == CMD_WRITE && self.len >= self.setup.write_len()
    }

    /// Appends received bytes (dropping what does not fit: a flooded board loses bytes).
    pub fn receive(&mut self, bytes: &[u8]) {
        let n = bytes.len().min(self.buf.len() - self.len);
        self.buf[self.len..self.len + n].copy_from_slice(&bytes[..n]);
        self.len += n;
    }

    /// Services the next complete frame, if any. For a write, applies its torques and writes the
    /// reply (with the encoder angles of `joint_angles`, rad, joint order) into `out`, returning its
    /// length; `Some(0)` for a frame without reply, `None` when no complete frame is waiting.
    pub fn service(&mut self, joint_angles: &[f64; PORTS], out: &mut [u8]) -> Option<usize> {
        loop {
            if self.len == 0 {
                return None;
            }
            match decode_host_frame(&self.buf[..self.len], &self.setup) {
                Ok(None) => return None,
                Ok(Some((frame, used))) => {
                    self.buf.copy_within(used..self.len, 0);
                    self.len -= used;
                    self.frames += 1;
                    return Some(self.apply(frame, joint_angles, out));
                }
                Err(CodecError::UnknownCommand(_)) | Err(_) => {
                    // Not a command: the firmware skips the byte.
                    self.buf.copy_within(1..self.len, 0);
                    self.len -= 1;
                    self.discarded += 1;
                }
            }
        }
    }

    fn apply(&mut self, frame: HostFrame, q: &[f64; PORTS], out: &mut [u8]) -> usize {
        match frame {
            HostFrame::Reset { id } => {
                self.setup = BoardSetup::empty(id);
                self.configured = false;
                self.torques = [0.0; PORTS];
                0
            }
            HostFrame::Setup(s) => {
                self.setup = s;
                self.configured = true;
                self.torques = [0.0; PORTS];
                0
            }
            HostFrame::Write { torques, .. } => {
                let w = &self.wiring;
                self.torques = [0.0; PORTS];
                for (k, p) in used_ports(self.setup.motor_mask).enumerate() {
                    let t = if torques[k].is_finite() {
                        torques[k]
                    } else {
                        0.0
                    };
                    let t = t.clamp(-FIRMWARE_TORQUE_LIMIT, FIRMWARE_TORQUE_LIMIT) as f64;
                    let sign = if self.setup.motor_dir[p] == w.motor_dir[p] {
                        1.0
                    } else {
                        -1.0
                    };
                    self.torques[p] = sign * t;
                }
                // Encoder angles, in port order of the encoder mask.
                let mut angles = [0f32; PORTS];
                let n_enc = self.setup.n_encoders();
                for (k, p) in used_ports(self.setup.enc_mask).enumerate() {
                    let (o, r) = (
                        self.setup.enc_offset_deg[p] as f64,
                        self.setup.enc_resolution[p] as f64,
                    );
                    let joint = (0..w.joints).find(|&j| w.port_of[j] == p);
                    let count0 = (o * r / 360.0).round();
                    let count = match joint {
                        Some(j) => {
                            let sign = if self.setup.enc_dir[p] == w.enc_dir[p] {
                                1.0
                            } else {
                                -1.0
                            };
                            let moved = q[j].to_degrees() - w.offset_deg[p];
                            count0 + sign * (moved * w.resolution[p] / 360.0).round()
                        }
                        None => count0,
                    };
                    angles[k] = if r > 0.0 {
                        (360.0 * count / r) as f32
                    } else {
                        0.0
                    };
                }
                let analog = [0f32; 12];
                self.replies += 1;
                encode_reply(
                    self.setup.id,
                    &analog[..self.setup.n_sensors as usize],
                    &angles[..n_enc],
                    out,
                )
                .unwrap_or(0)
            }
        }
    }
}

/// Settings of [`serve`].
#[derive(Clone, Debug)]
pub struct EmulatorConfig {
    /// The simulated hand.
    pub hand: HandModel,
    /// Minimum time between two serviced frames. Default (and minimum) 50 µs.
    pub service_time: Duration,
    /// Linkage time. Default real time.
    pub clock: EmulatorClock,
    /// The hand's own damping at the handle (N·s/m), on top of the hand model: a hand that holds a
    /// handle is never undamped. Default 2 N·s/m.
    pub hand_damping: f64,
}

impl Default for EmulatorConfig {
    fn default() -> Self {
        Self {
            hand: HandModel::Free,
            service_time: Duration::from_micros(50),
            clock: EmulatorClock::RealTime,
            hand_damping: 2.0,
        }
    }
}

/// What a finished emulator run did.
#[derive(Clone, Debug, PartialEq)]
pub struct EmulatorReport {
    /// Frames serviced.
    pub frames: u64,
    /// Replies sent.
    pub replies: u64,
    /// Bytes skipped as unknown commands.
    pub discarded: u64,
    /// Final joint angles (rad).
    pub joint_angles: [f64; PORTS],
    /// Why it stopped.
    pub reason: String,
}

/// The plant for device file `file`, at rest at `start` (2DIY: end point `(x, y)` in the board
/// frame, m; twin: handle pose `(x, y, θ)`, m, m, rad); `None` = the workspace centre.
pub fn plant_for(
    file: &HaplyDeviceFile,
    start: Option<[f64; 3]>,
    config: &EmulatorConfig,
) -> Result<Plant, String> {
    let s = start.unwrap_or_else(|| file.workspace_center());
    match &file.kind {
        HaplyKind::TwoDiy { linkage, .. } => Ok(Plant::TwoDiy(Plant2::new(
            *linkage,
            haptic2d::geom::Vec2::new(s[0], s[1]),
        )?)),
        HaplyKind::Twin(p) => Plant::twin(p, s, config.hand_damping),
    }
}

/// Runs the emulated board of `file` on `stream` until `stop` is set or the stream fails, moving
/// `plant`. The stream's read timeout should be short (≤ 1 ms): it paces the loop while idle.
pub fn serve<S: Read + Write>(
    mut stream: S,
    file: &HaplyDeviceFile,
    mut plant: Plant,
    config: &EmulatorConfig,
    stop: &AtomicBool,
) -> EmulatorReport {
    let mut fw = Firmware::new(file);
    let service = config.service_time.max(Duration::from_micros(50));
    let mut rx = [0u8; 256];
    let mut out = [0u8; REPLY_MAX_LEN];
    let mut last_service = Instant::now();
    let mut last_step = Instant::now();
    let mut reason = "stopped".to_string();
    // Folded into the twin's joint friction by `plant_for`.
    let b_h = match plant {
        Plant::TwoDiy(_) => config.hand_damping,
        Plant::Twin(_) => 0.0,
    };
    'outer: while !stop.load(Ordering::Relaxed) {
        match stream.read(&mut rx) {
            Ok(0) => {}
            Ok(n) => fw.receive(&rx[..n]),
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
                ) => {}
            Err(e) => {
                reason = format!("the port failed: {e}");
                break;
            }
        }
        loop {
            // The firmware services the port at most every 50 µs.
            let ready = last_service + service;
            while Instant::now() < ready {
                std::hint::spin_loop();
            }
            if fw.next_is_write() {
                // A write: first the linkage moves under the torques held since the last one.
                let now = Instant::now();
                let dt = match config.clock {
                    EmulatorClock::RealTime => now.duration_since(last_step).as_secs_f64(),
                    EmulatorClock::PerWrite(dt) => dt,
                };
                last_step = now;
                if let Err(e) = plant.step(&fw.joint_torques(), &config.hand, b_h, dt.min(0.1)) {
                    reason = format!("the simulated linkage failed: {e}");
                    break 'outer;
                }
            }
            // The board samples its encoders when it services the frame.
            let q = plant.joint_angles();
            let Some(n) = fw.service(&q, &mut out) else {
                break;
            };
            last_service = Instant::now();
            if n > 0
                && stream
                    .write_all(&out[..n])
                    .and_then(|_| stream.flush())
                    .is_err()
            {
                reason = "the host closed the port".into();
                break 'outer;
            }
        }
    }
    EmulatorReport {
        frames: fw.frames,
        replies: fw.replies,
        discarded: fw.discarded,
        joint_angles: plant.joint_angles(),
        reason,
    }
}
