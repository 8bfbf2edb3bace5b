//! A stand-in Haply board: the stock firmware's behaviour (docs/DEVICES.md §1.3), hazards included,
//! over any byte stream, moving a simulated linkage ([`Plant`]) under the motor torques and a
//! simulated hand.
//!
//! What it reproduces (each item is pinned by a test in `tests/it/codec_vectors.rs` or
//! `tests/it/driver_safety.rs`):
//!
//! - reset, setup, write; a reply **only** after a write; nothing after reset or setup;
//! - a service time of at least 50 µs between two serviced frames;
//! - the torque clamp `|τ| ≤ 0.123 N·m` on every motor;
//! - **encoders set at every setup**: the count becomes `trunc(offset_deg · resolution / 360)`
//!   (toward zero, in f32 as the firmware computes) at the moment of the setup, then follows the
//!   shaft; the reported angle is `360 · count / resolution` (f32). The angle reported right after a
//!   setup is the offset within one count wherever the handle is; the pose at power-up only sets
//!   the phase of the encoder's edges ([`Firmware::power_up`]);
//! - **no watchdog**: the last torque is held until the next write, for ever;
//! - **reset does not zero the motor output** (nor does setup): it forgets the configuration only;
//! - **an M0 board has 2 ports** ([`BoardKind`]): a setup naming port 3 or 4 leaves it with no motor
//!   and no encoder configured, so it answers every write with the id and the analog values only
//!   (a 4-encoder setup: 1 of 17 bytes), and the torque bytes of the host's longer writes are read
//!   as commands;
//! - analog inputs ([`Firmware::analog_in`]) reported in **ascending pin order**;
//!   [`serve_with_analog`] takes their values from an [`AnalogInputs`], which another thread (a test
//!   pressing a button) may set at any time ([`serve`]: all pins read 0);
//! - unknown command bytes discarded **one byte at a time** (a lone `0x03`, haptic2d's identify
//!   query, is ignored: the stock firmware has no identify);
//! - the direction-byte quirk (see [`decode_host_frame`]);
//! - a board wired as the emulator's own device file says (the *truth*): a host whose setup has a
//!   wrong direction byte sees that motor push the wrong way and that encoder count backwards.

use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use haptic2d::device::HandModel;

use super::codec::{
    decode_host_frame, encode_reply, used_ports, BoardSetup, HostFrame, Rotation, ANALOG_PIN_MIN,
    CMD_WRITE, FIRMWARE_TORQUE_LIMIT, MAX_SENSORS, PORTS, REPLY_MAX_LEN,
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

/// Which Haply board is emulated (docs/DEVICES.md §1.3.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BoardKind {
    /// The M0 board: 2 motor/encoder ports.
    M0,
    /// The M3 board: 4 motor/encoder ports.
    #[default]
    M3,
}

impl BoardKind {
    /// Motor/encoder ports on the board.
    pub fn ports(self) -> usize {
        match self {
            BoardKind::M0 => 2,
            BoardKind::M3 => 4,
        }
    }

    /// From a name: `m0` or `m3` (case-insensitive).
    pub fn from_name(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "m0" => Some(BoardKind::M0),
            "m3" => Some(BoardKind::M3),
            _ => None,
        }
    }
}

/// How the emulated board is wired (from its device file).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Wiring {
    joints: usize,
    /// Port (0-based) of joint `j`.
    port_of: [usize; PORTS],
    /// Joint on port `p`, if any.
    joint_on: [Option<usize>; PORTS],
    motor_dir: [Rotation; PORTS],
    enc_dir: [Rotation; PORTS],
    /// Encoder counts per turn of the physical encoder on port `p`.
    resolution: [f64; PORTS],
}

/// The firmware's state machine (no I/O): frames in, replies out.
#[derive(Clone, Debug)]
pub struct Firmware {
    wiring: Wiring,
    board: BoardKind,
    /// The set-up as the board runs it: for an M0 asked for ports it lacks, no motor and no encoder.
    setup: BoardSetup,
    /// Joint angles (rad) at power-up: the phase of the encoders' edges. `None` until the first
    /// [`power_up`](Self::power_up) or service.
    power_up_q: Option<[f64; PORTS]>,
    /// Count set by the last setup, per port.
    count0: [i64; PORTS],
    /// The physical edge count at the last setup, per port.
    edge_at_setup: [i64; PORTS],
    /// Held motor torques per port (N·m), after the clamp and the direction signs (the truth's
    /// sense). Never zeroed by reset or setup; no watchdog.
    torques: [f64; PORTS],
    /// Analog input values of pins A0–A11 (what the board reads on pin `54 + i`).
    pub analog_in: [f32; MAX_SENSORS],
    buf: [u8; 256],
    len: usize,
    /// Frames serviced so far (all kinds).
    pub frames: u64,
    /// Writes answered so far.
    pub replies: u64,
    /// Setups serviced so far.
    pub setups: u64,
    /// Bytes discarded as unknown commands.
    pub discarded: u64,
}

impl Firmware {
    /// An M3 board wired as `file` says, not yet set up (the power-up pose is the one of the first
    /// service, unless [`power_up`](Self::power_up) is called before).
    pub fn new(file: &HaplyDeviceFile) -> Self {
        Self::with_board(file, BoardKind::M3)
    }

    /// A board of kind `board` wired as `file` says (ports the board lacks are not connected).
    pub fn with_board(file: &HaplyDeviceFile, board: BoardKind) -> Self {
        let mut w = Wiring {
            joints: file.joints(),
            port_of: [0; PORTS],
            joint_on: [None; PORTS],
            motor_dir: [Rotation::Clockwise; PORTS],
            enc_dir: [Rotation::Clockwise; PORTS],
            resolution: [1.0; PORTS],
        };
        for (j, m) in file.motors.iter().enumerate() {
            let p = (m.port - 1) as usize;
            w.port_of[j] = p;
            if p < board.ports() {
                w.joint_on[p] = Some(j);
            }
            w.motor_dir[p] = m.direction;
            w.enc_dir[p] = m.encoder_direction;
            w.resolution[p] = m.counts_per_turn;
        }
        Self {
            wiring: w,
            board,
            setup: BoardSetup::empty(file.id),
            power_up_q: None,
            count0: [0; PORTS],
            edge_at_setup: [0; PORTS],
            torques: [0.0; PORTS],
            analog_in: [0.0; MAX_SENSORS],
            buf: [0; 256],
            len: 0,
            frames: 0,
            replies: 0,
            setups: 0,
            discarded: 0,
        }
    }

    /// Powers the board up with the linkage at joint angles `q` (rad, joint order): the encoders'
    /// edges are counted from here. Only the phase of the counts depends on it (under one count):
    /// the angles reported are set by the last setup (docs/DEVICES.md §1.3.3).
    pub fn power_up(&mut self, q: &[f64; PORTS]) {
        self.power_up_q = Some(*q);
    }

    /// The board kind.
    pub fn board(&self) -> BoardKind {
        self.board
    }

    /// The current set-up, as the board runs it (an M0 asked for ports it lacks runs none).
    pub fn setup(&self) -> &BoardSetup {
        &self.setup
    }

    /// Held joint torques (N·m) in joint order: what the motors apply now (no watchdog: until the
    /// next write, whatever happens to the host).
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

    /// Services the next complete frame, if any, with the linkage at `joint_angles` (rad, joint
    /// order). For a write, applies its torques and writes the reply into `out`, returning its
    /// length; `Some(0)` for a frame without reply, `None` when no complete frame is waiting.
    pub fn service(&mut self, joint_angles: &[f64; PORTS], out: &mut [u8]) -> Option<usize> {
        if self.power_up_q.is_none() {
            self.power_up_q = Some(*joint_angles);
        }
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
                Err(_) => {
                    // Not a command: the firmware skips the byte and looks again.
                    self.buf.copy_within(1..self.len, 0);
                    self.len -= 1;
                    self.discarded += 1;
                }
            }
        }
    }

    /// The physical edge count of the encoder on port `p` at joint angles `q` (rad), counted from
    /// power-up.
    fn edges(&self, p: usize, q: &[f64; PORTS]) -> i64 {
        let Some(j) = self.wiring.joint_on[p] else {
            return 0;
        };
        let q0 = self.power_up_q.map_or(0.0, |pu| pu[j]);
        ((q[j] - q0).to_degrees() * self.wiring.resolution[p] / 360.0).floor() as i64
    }

    fn apply(&mut self, frame: HostFrame, q: &[f64; PORTS], out: &mut [u8]) -> usize {
        match frame {
            HostFrame::Reset { id } => {
                // Forgets the configuration; the motor output stays as it was.
                self.setup = BoardSetup::empty(id);
                0
            }
            HostFrame::Setup(s) => {
                let lacking = !((1u8 << self.board.ports()) - 1);
                self.setup = s;
                if (s.motor_mask | s.enc_mask) & lacking != 0 {
                    // A port the board does not have: nothing motor or encoder is configured.
                    self.setup.motor_mask = 0;
                    self.setup.enc_mask = 0;
                }
                self.setups += 1;
                for p in used_ports(self.setup.enc_mask) {
                    // f32 arithmetic and a C float-to-int conversion (toward zero).
                    let c = s.enc_offset_deg[p] * s.enc_resolution[p] / 360.0f32;
                    self.count0[p] = c as i64;
                    self.edge_at_setup[p] = self.edges(p, q);
                }
                0
            }
            HostFrame::Write { torques, .. } => {
                let w = &self.wiring;
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
                    let sign = if self.setup.enc_dir[p] == self.wiring.enc_dir[p] {
                        1
                    } else {
                        -1
                    };
                    let count = self.count0[p] + sign * (self.edges(p, q) - self.edge_at_setup[p]);
                    let r = self.setup.enc_resolution[p];
                    angles[k] = 360.0f32 * count as f32 / r;
                }
                // Analog values in ascending pin order, whatever order the setup listed them in.
                let n_s = self.setup.n_sensors as usize;
                let mut pins = self.setup.sensor_pins;
                pins[..n_s].sort_unstable();
                let mut analog = [0f32; MAX_SENSORS];
                for (a, &pin) in analog.iter_mut().zip(&pins[..n_s]) {
                    *a = pin
                        .checked_sub(ANALOG_PIN_MIN)
                        .and_then(|i| self.analog_in.get(i as usize))
                        .copied()
                        .unwrap_or(0.0);
                }
                self.replies += 1;
                encode_reply(self.setup.id, &analog[..n_s], &angles[..n_enc], out).unwrap_or(0)
            }
        }
    }
}

/// The voltages on the emulated board's analog pins A0–A11, as the values its ADC reports (the
/// board's units, e.g. counts 0–1023), shared with whoever sets them (a test pressing a button wired
/// to a pin). A clone shares the same pins. Lock-free: f32 bits in atomics.
#[derive(Clone, Debug, Default)]
pub struct AnalogInputs(Arc<[AtomicU32; MAX_SENSORS]>);

impl AnalogInputs {
    /// Sets the reading of analog pin `pin` (54–65 = A0–A11; other pins are ignored) to `value`.
    pub fn set(&self, pin: u8, value: f32) {
        if let Some(a) = pin
            .checked_sub(ANALOG_PIN_MIN)
            .and_then(|i| self.0.get(usize::from(i)))
        {
            a.store(value.to_bits(), Ordering::Relaxed);
        }
    }

    /// The readings of A0–A11.
    pub fn values(&self) -> [f32; MAX_SENSORS] {
        let mut v = [0.0; MAX_SENSORS];
        for (o, a) in v.iter_mut().zip(self.0.iter()) {
            *o = f32::from_bits(a.load(Ordering::Relaxed));
        }
        v
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
    /// The board: M3 (4 ports, default) or M0 (2 ports).
    pub board: BoardKind,
    /// Where the handle was when the board was powered (2DIY `(x, y)`, twin `(x, y, θ)`; m, rad);
    /// `None` = where the plant starts, i.e. where the handle is when the host sets the board up.
    /// Only the phase of the encoder counts depends on it (docs/DEVICES.md §1.3.3).
    pub power_up: Option<[f64; 3]>,
}

impl Default for EmulatorConfig {
    fn default() -> Self {
        Self {
            hand: HandModel::Free,
            service_time: Duration::from_micros(50),
            clock: EmulatorClock::RealTime,
            hand_damping: 2.0,
            board: BoardKind::M3,
            power_up: None,
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
    /// Setups serviced.
    pub setups: u64,
    /// Bytes skipped as unknown commands.
    pub discarded: u64,
    /// Final joint angles (rad).
    pub joint_angles: [f64; PORTS],
    /// The joint torques the motors still apply (N·m, joint order): no watchdog.
    pub held_torques: [f64; PORTS],
    /// Why it stopped.
    pub reason: String,
}

/// The plant for device file `file`, at rest at `start` (2DIY: end point `(x, y)` in the board
/// frame, m; twin: handle pose `(x, y, θ)`, m, m, rad); `None` = the file's rest pose, where the
/// user holds the handle when a host starts (docs/DEVICES.md §7).
pub fn plant_for(
    file: &HaplyDeviceFile,
    start: Option<[f64; 3]>,
    config: &EmulatorConfig,
) -> Result<Plant, String> {
    let s = match start {
        Some(s) => s,
        None => file.rest_pose()?,
    };
    match &file.kind {
        HaplyKind::TwoDiy { linkage, .. } => Ok(Plant::TwoDiy(Plant2::new(
            *linkage,
            haptic2d::geom::Vec2::new(s[0], s[1]),
        )?)),
        HaplyKind::Twin(p) => Plant::twin(p, s, config.hand_damping),
    }
}

/// Runs the emulated board of `file` on `stream` until `stop` is set or the stream fails, moving
/// `plant`. The stream's read timeout should be short (≤ 1 ms): it paces the loop while idle. Every
/// analog pin reads 0 ([`serve_with_analog`] sets them).
pub fn serve<S: Read + Write>(
    stream: S,
    file: &HaplyDeviceFile,
    plant: Plant,
    config: &EmulatorConfig,
    stop: &AtomicBool,
) -> EmulatorReport {
    serve_with_analog(stream, file, plant, config, stop, &AnalogInputs::default())
}

/// [`serve`] with the analog pins reading `analog`, sampled at every serviced write (as the board
/// samples its encoders).
pub fn serve_with_analog<S: Read + Write>(
    mut stream: S,
    file: &HaplyDeviceFile,
    mut plant: Plant,
    config: &EmulatorConfig,
    stop: &AtomicBool,
    analog: &AnalogInputs,
) -> EmulatorReport {
    let mut fw = Firmware::with_board(file, config.board);
    let power_up_q = match config.power_up {
        Some(p) => plant_for(file, Some(p), config).map(|pl| pl.joint_angles()),
        None => Ok(plant.joint_angles()),
    };
    let mut reason = "stopped".to_string();
    match power_up_q {
        Ok(q) => fw.power_up(&q),
        Err(e) => {
            reason = format!("the power-up pose is not a pose of the linkage: {e}");
            stop.store(true, Ordering::Relaxed);
        }
    }
    let service = config.service_time.max(Duration::from_micros(50));
    let mut rx = [0u8; 256];
    let mut out = [0u8; REPLY_MAX_LEN];
    let mut last_service = Instant::now();
    let mut last_step = Instant::now();
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
        // Real time: the linkage moves while no write arrives too (the motors hold the last
        // torque, the hand keeps acting), in steps of at least 1 ms.
        if config.clock == EmulatorClock::RealTime && !fw.next_is_write() {
            let now = Instant::now();
            let dt = now.duration_since(last_step).as_secs_f64();
            if dt >= 1e-3 {
                last_step = now;
                if let Err(e) = plant.step(&fw.joint_torques(), &config.hand, b_h, dt.min(0.1)) {
                    reason = format!("the simulated linkage failed: {e}");
                    break 'outer;
                }
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
            // The board samples its encoders (and analog pins) when it services the frame.
            let q = plant.joint_angles();
            fw.analog_in = analog.values();
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
        setups: fw.setups,
        discarded: fw.discarded,
        joint_angles: plant.joint_angles(),
        held_torques: fw.joint_torques(),
        reason,
    }
}
