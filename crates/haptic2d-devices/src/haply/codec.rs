//! The Haply board protocol (docs/DEVICES.md §1) as a pure codec: bytes in, typed frames out, buffers owned
//! by the caller; no clock, no port, no allocation.
//!
//! ```text
//! host → board  reset  [0x00][id]                                                    no reply
//!               setup  [0x01][id][motor_mask][motor_dir × n_m][enc_mask][enc_dir × n_e]
//!                      [n_sensors][pin × n_s][n_pwm][pin × n_p][offset_deg f32, resolution f32] × n_e
//!               write  [0x02][id][pwm u8 × n_p][torque f32 × n_m]                   → reply
//! board → host  reply  [id][analog f32 × n_s][angle_deg f32 × n_e]   (1 + 4·(n_s + n_e) bytes)
//! ```
//!
//! f32 little-endian; angles in degrees, torques in N·m (vendor units on the wire, SI above the
//! driver). Mask bit `i` is port `i + 1`; per-port values (directions, encoder pairs, torques) travel
//! in ascending port order, one per used port.

use std::fmt;

/// Ports on a board.
pub const PORTS: usize = 4;
/// Most analog sensor pins (A0–A11).
pub const MAX_SENSORS: usize = 12;
/// First analog pin number (A0).
pub const ANALOG_PIN_MIN: u8 = 54;
/// Last analog pin number (A11).
pub const ANALOG_PIN_MAX: u8 = 65;
/// The firmware's torque clamp `|τ| ≤ 0.123 N·m`.
pub const FIRMWARE_TORQUE_LIMIT: f32 = 0.123;
/// Command byte of a reset.
pub const CMD_RESET: u8 = 0x00;
/// Command byte of a setup.
pub const CMD_SETUP: u8 = 0x01;
/// Command byte of a write.
pub const CMD_WRITE: u8 = 0x02;
/// Command byte of haptic2d firmware's identify query (docs/DEVICES.md §6): a lone byte, no id. The
/// stock firmware discards it.
pub const CMD_IDENTIFY: u8 = 0x03;
/// Command byte of haptic2d firmware's watchdog setting: `[0x04][watchdog_ms u16 LE]`. Sent only to
/// a board that answered identify.
pub const CMD_SET_WATCHDOG: u8 = 0x04;
/// Length of haptic2d firmware's identify frame (bytes).
pub const IDENTIFY_LEN: usize = 10;
/// The identify frame's magic bytes after its first byte `0x03`.
pub const IDENTIFY_MAGIC: [u8; 4] = *b"H2DF";
/// The watchdog times haptic2d firmware accepts (ms).
pub const WATCHDOG_MS_RANGE: std::ops::RangeInclusive<u16> = 1..=1000;
/// Largest setup frame (bytes): 3 + 4 + 1 + 4 + 1 + 12 + 1 + 4 + 8·4.
pub const SETUP_MAX_LEN: usize = 62;
/// Largest write frame (bytes): 2 + 4 + 4·4.
pub const WRITE_MAX_LEN: usize = 22;
/// Largest reply (bytes): 1 + 4·(12 + 4).
pub const REPLY_MAX_LEN: usize = 65;

/// Rotation sense of a motor or encoder direction byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rotation {
    /// Byte 0.
    Clockwise,
    /// Byte 1.
    CounterClockwise,
}

impl Rotation {
    /// The wire byte.
    pub fn byte(self) -> u8 {
        match self {
            Rotation::Clockwise => 0,
            Rotation::CounterClockwise => 1,
        }
    }
    /// From a wire byte (0 = CW, anything else CCW, as the firmware reads it).
    pub fn from_byte(b: u8) -> Self {
        if b == 0 {
            Rotation::Clockwise
        } else {
            Rotation::CounterClockwise
        }
    }
}

/// A board configuration: what a setup frame carries. Per-port arrays are indexed by `port − 1`;
/// entries of unused ports are ignored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoardSetup {
    /// Board id (echoed as the first byte of every reply).
    pub id: u8,
    /// Motor mask: bit `i` = port `i + 1` drives a motor.
    pub motor_mask: u8,
    /// Motor direction per port.
    pub motor_dir: [Rotation; PORTS],
    /// Encoder mask: bit `i` = port `i + 1` reads an encoder.
    pub enc_mask: u8,
    /// Encoder direction per port.
    pub enc_dir: [Rotation; PORTS],
    /// Encoder start angle per port (degrees).
    pub enc_offset_deg: [f32; PORTS],
    /// Encoder counts per turn per port.
    pub enc_resolution: [f32; PORTS],
    /// Number of analog sensors.
    pub n_sensors: u8,
    /// Analog pins (54–65), first `n_sensors` used.
    pub sensor_pins: [u8; MAX_SENSORS],
    /// Number of PWM outputs.
    pub n_pwm: u8,
    /// PWM pins, first `n_pwm` used.
    pub pwm_pins: [u8; PORTS],
}

impl BoardSetup {
    /// A board `id` with nothing configured.
    pub fn empty(id: u8) -> Self {
        Self {
            id,
            motor_mask: 0,
            motor_dir: [Rotation::Clockwise; PORTS],
            enc_mask: 0,
            enc_dir: [Rotation::Clockwise; PORTS],
            enc_offset_deg: [0.0; PORTS],
            enc_resolution: [0.0; PORTS],
            n_sensors: 0,
            sensor_pins: [0; MAX_SENSORS],
            n_pwm: 0,
            pwm_pins: [0; PORTS],
        }
    }

    /// Number of motors (used motor ports).
    pub fn n_motors(&self) -> usize {
        (self.motor_mask & 0x0f).count_ones() as usize
    }

    /// Number of encoders (used encoder ports).
    pub fn n_encoders(&self) -> usize {
        (self.enc_mask & 0x0f).count_ones() as usize
    }

    /// Length of the board's reply to a write (bytes): `1 + 4·(n_sensors + n_enc)`.
    pub fn reply_len(&self) -> usize {
        1 + 4 * (self.n_sensors as usize + self.n_encoders())
    }

    /// Length of a write frame (bytes): `2 + n_pwm + 4·n_motors`.
    pub fn write_len(&self) -> usize {
        2 + self.n_pwm as usize + 4 * self.n_motors()
    }

    /// Checks what the wire can carry: masks within 4 ports, ≤ 12 analog pins in 54–65, ≤ 4 PWM
    /// pins, finite offsets, resolutions > 0 on used encoder ports.
    pub fn validate(&self) -> Result<(), CodecError> {
        if self.motor_mask > 0x0f || self.enc_mask > 0x0f {
            return Err(CodecError::Invalid("a mask has bits above port 4"));
        }
        if self.n_sensors as usize > MAX_SENSORS || self.n_pwm as usize > PORTS {
            return Err(CodecError::Invalid("too many sensors or PWM pins"));
        }
        if self.sensor_pins[..self.n_sensors as usize]
            .iter()
            .any(|p| !(ANALOG_PIN_MIN..=ANALOG_PIN_MAX).contains(p))
        {
            return Err(CodecError::Invalid(
                "analog pins are numbered 54–65 (A0–A11)",
            ));
        }
        for port in used_ports(self.enc_mask) {
            let (o, r) = (self.enc_offset_deg[port], self.enc_resolution[port]);
            if !(o.is_finite() && r.is_finite() && r > 0.0) {
                return Err(CodecError::Invalid(
                    "encoder offsets must be finite and resolutions > 0",
                ));
            }
        }
        Ok(())
    }
}

/// The used ports of `mask` as 0-based port indices, ascending.
pub fn used_ports(mask: u8) -> impl Iterator<Item = usize> {
    (0..PORTS).filter(move |i| mask & (1 << i) != 0)
}

/// A decoded reply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reply {
    /// Analog readings, first `n_sensors` valid.
    pub analog: [f32; MAX_SENSORS],
    /// Encoder angles (degrees) in ascending port order, first `n_enc` valid.
    pub angles_deg: [f32; PORTS],
}

/// A codec failure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CodecError {
    /// The output buffer is too small (bytes needed).
    BufferTooSmall(usize),
    /// The reply does not start with the board's id: the stream is out of step.
    WrongId {
        /// Id expected.
        expected: u8,
        /// First byte received.
        got: u8,
    },
    /// Fewer bytes than a full reply (or frame).
    Short {
        /// Bytes expected.
        expected: usize,
        /// Bytes present.
        got: usize,
    },
    /// A value in a reply is NaN or infinite (garbage on the line).
    NonFinite {
        /// Byte offset of the value.
        offset: usize,
    },
    /// A frame starts with an unknown command byte.
    UnknownCommand(u8),
    /// A setup cannot be encoded (what is wrong).
    Invalid(&'static str),
    /// Bytes that are not haptic2d firmware's identify frame (what is wrong).
    NotIdentify(&'static str),
}

impl fmt::Display for CodecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CodecError::BufferTooSmall(n) => write!(f, "buffer too small: {n} bytes needed"),
            CodecError::WrongId { expected, got } => write!(
                f,
                "reply starts with 0x{got:02x}, not the board id 0x{expected:02x} (stream out of step)"
            ),
            CodecError::Short { expected, got } => {
                write!(f, "short reply: {got} of {expected} bytes")
            }
            CodecError::NonFinite { offset } => {
                write!(f, "non-finite number at byte {offset} of the reply (garbage on the line)")
            }
            CodecError::UnknownCommand(b) => write!(f, "unknown command byte 0x{b:02x}"),
            CodecError::Invalid(s) => write!(f, "invalid setup: {s}"),
            CodecError::NotIdentify(s) => write!(f, "not an identify frame: {s}"),
        }
    }
}

impl std::error::Error for CodecError {}

fn need(out: &[u8], n: usize) -> Result<(), CodecError> {
    if out.len() < n {
        Err(CodecError::BufferTooSmall(n))
    } else {
        Ok(())
    }
}

/// Encodes a reset of board `id` into `out`; returns the length (2).
pub fn encode_reset(id: u8, out: &mut [u8]) -> Result<usize, CodecError> {
    need(out, 2)?;
    out[0] = CMD_RESET;
    out[1] = id;
    Ok(2)
}

/// Encodes `setup` into `out`; returns the length.
pub fn encode_setup(setup: &BoardSetup, out: &mut [u8]) -> Result<usize, CodecError> {
    setup.validate()?;
    let len = 3
        + setup.n_motors()
        + 1
        + setup.n_encoders()
        + 1
        + setup.n_sensors as usize
        + 1
        + setup.n_pwm as usize
        + 8 * setup.n_encoders();
    need(out, len)?;
    let mut w = Writer { out, at: 0 };
    w.u8(CMD_SETUP);
    w.u8(setup.id);
    w.u8(setup.motor_mask);
    for p in used_ports(setup.motor_mask) {
        w.u8(setup.motor_dir[p].byte());
    }
    w.u8(setup.enc_mask);
    for p in used_ports(setup.enc_mask) {
        w.u8(setup.enc_dir[p].byte());
    }
    w.u8(setup.n_sensors);
    for i in 0..setup.n_sensors as usize {
        w.u8(setup.sensor_pins[i]);
    }
    w.u8(setup.n_pwm);
    for i in 0..setup.n_pwm as usize {
        w.u8(setup.pwm_pins[i]);
    }
    for p in used_ports(setup.enc_mask) {
        w.f32(setup.enc_offset_deg[p]);
        w.f32(setup.enc_resolution[p]);
    }
    debug_assert_eq!(w.at, len);
    Ok(len)
}

/// Encodes a write to board `id`: PWM duties `pwm` and torques `torques` (N·m, one per used motor
/// port, ascending port order); returns the length. Torques are sent as given (the driver clamps).
pub fn encode_write(
    id: u8,
    pwm: &[u8],
    torques: &[f32],
    out: &mut [u8],
) -> Result<usize, CodecError> {
    let len = 2 + pwm.len() + 4 * torques.len();
    need(out, len)?;
    let mut w = Writer { out, at: 0 };
    w.u8(CMD_WRITE);
    w.u8(id);
    for &d in pwm {
        w.u8(d);
    }
    for &t in torques {
        w.f32(t);
    }
    Ok(len)
}

/// Decodes a reply of board `id` with `n_sensors` analog values and `n_enc` angles from `bytes`
/// (exactly the reply; extra bytes are ignored). Errors: [`CodecError::WrongId`],
/// [`CodecError::Short`], [`CodecError::NonFinite`].
pub fn decode_reply(
    id: u8,
    n_sensors: usize,
    n_enc: usize,
    bytes: &[u8],
) -> Result<Reply, CodecError> {
    let n_sensors = n_sensors.min(MAX_SENSORS);
    let n_enc = n_enc.min(PORTS);
    let expected = 1 + 4 * (n_sensors + n_enc);
    if let Some(&b) = bytes.first() {
        if b != id {
            return Err(CodecError::WrongId {
                expected: id,
                got: b,
            });
        }
    }
    if bytes.len() < expected {
        return Err(CodecError::Short {
            expected,
            got: bytes.len(),
        });
    }
    let mut reply = Reply {
        analog: [0.0; MAX_SENSORS],
        angles_deg: [0.0; PORTS],
    };
    let mut at = 1;
    for i in 0..n_sensors + n_enc {
        let v = f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
        if !v.is_finite() {
            return Err(CodecError::NonFinite { offset: at });
        }
        if i < n_sensors {
            reply.analog[i] = v;
        } else {
            reply.angles_deg[i - n_sensors] = v;
        }
        at += 4;
    }
    Ok(reply)
}

/// Encodes a reply (the board side, for the emulator); returns the length.
pub fn encode_reply(
    id: u8,
    analog: &[f32],
    angles_deg: &[f32],
    out: &mut [u8],
) -> Result<usize, CodecError> {
    let len = 1 + 4 * (analog.len() + angles_deg.len());
    need(out, len)?;
    let mut w = Writer { out, at: 0 };
    w.u8(id);
    for &a in analog.iter().chain(angles_deg) {
        w.f32(a);
    }
    Ok(len)
}

/// What haptic2d's own board firmware says about itself (its identify frame, docs/DEVICES.md §6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FirmwareIdentity {
    /// Firmware version.
    pub version: u8,
    /// Motor/encoder ports of the board (2 on an M0, 4 on an M3).
    pub ports: u8,
    /// Capability bits: [`CAP_WATCHDOG`], [`CAP_RESET_ZEROES`], [`CAP_BOARD_CLAMP`].
    pub caps: u8,
    /// The watchdog time now in force (ms).
    pub watchdog_ms: u16,
}

/// Capability bit: the board zeroes its motors when no write arrives within the watchdog time.
pub const CAP_WATCHDOG: u8 = 1 << 0;
/// Capability bit: reset zeroes the motor output.
pub const CAP_RESET_ZEROES: u8 = 1 << 1;
/// Capability bit: the board clamps every torque itself.
pub const CAP_BOARD_CLAMP: u8 = 1 << 2;

impl FirmwareIdentity {
    /// True when the board has a watchdog.
    pub fn has_watchdog(&self) -> bool {
        self.caps & CAP_WATCHDOG != 0
    }
    /// True when reset zeroes the motor output.
    pub fn reset_zeroes_motors(&self) -> bool {
        self.caps & CAP_RESET_ZEROES != 0
    }
    /// True when the board clamps the torques itself.
    pub fn clamps_torque(&self) -> bool {
        self.caps & CAP_BOARD_CLAMP != 0
    }
}

/// Encodes the identify query `[0x03]` into `out`; returns the length (1).
pub fn encode_identify(out: &mut [u8]) -> Result<usize, CodecError> {
    need(out, 1)?;
    out[0] = CMD_IDENTIFY;
    Ok(1)
}

/// Encodes the watchdog setting `[0x04][watchdog_ms u16 LE]`; returns the length (3). Errors when
/// `watchdog_ms` is outside 1–1000.
pub fn encode_set_watchdog(watchdog_ms: u16, out: &mut [u8]) -> Result<usize, CodecError> {
    if !WATCHDOG_MS_RANGE.contains(&watchdog_ms) {
        return Err(CodecError::Invalid("the watchdog time must be 1–1000 ms"));
    }
    need(out, 3)?;
    out[0] = CMD_SET_WATCHDOG;
    out[1..3].copy_from_slice(&watchdog_ms.to_le_bytes());
    Ok(3)
}

/// Encodes an identify frame (the board side, for tests and emulators); returns the length (10).
pub fn encode_identity(id: &FirmwareIdentity, out: &mut [u8]) -> Result<usize, CodecError> {
    need(out, IDENTIFY_LEN)?;
    out[0] = CMD_IDENTIFY;
    out[1..5].copy_from_slice(&IDENTIFY_MAGIC);
    out[5] = id.version;
    out[6] = id.ports;
    out[7] = id.caps;
    out[8..10].copy_from_slice(&id.watchdog_ms.to_le_bytes());
    Ok(IDENTIFY_LEN)
}

/// Decodes an identify frame from `bytes` (exactly the frame; extra bytes are ignored). Errors:
/// [`CodecError::Short`], [`CodecError::NotIdentify`].
pub fn decode_identity(bytes: &[u8]) -> Result<FirmwareIdentity, CodecError> {
    if bytes.first().is_some_and(|&b| b != CMD_IDENTIFY) {
        return Err(CodecError::NotIdentify("the first byte is not 0x03"));
    }
    if bytes.len() < IDENTIFY_LEN {
        return Err(CodecError::Short {
            expected: IDENTIFY_LEN,
            got: bytes.len(),
        });
    }
    if bytes[1..5] != IDENTIFY_MAGIC {
        return Err(CodecError::NotIdentify("the magic bytes are not \"H2DF\""));
    }
    Ok(FirmwareIdentity {
        version: bytes[5],
        ports: bytes[6],
        caps: bytes[7],
        watchdog_ms: u16::from_le_bytes([bytes[8], bytes[9]]),
    })
}

/// A host frame as the board reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HostFrame {
    /// Reset of board `id`.
    Reset {
        /// Board id.
        id: u8,
    },
    /// Setup, with the direction bytes as they appeared on the wire: see [`decode_setup`].
    Setup(BoardSetup),
    /// Write to board `id`: first `n_pwm` PWM duties and first `n_motors` torques (N·m, as sent).
    Write {
        /// Board id.
        id: u8,
        /// PWM duties.
        pwm: [u8; PORTS],
        /// Torques in port order (N·m).
        torques: [f32; PORTS],
    },
}

/// Decodes one host frame from the start of `bytes` the way the firmware does. `current` is the
/// board's current setup (a write's length depends on it). Returns `Ok(None)` while the frame is
/// incomplete, else the frame and its length.
///
/// Direction bytes follow the firmware's quirk (docs/DEVICES.md §1): the `k`-th direction byte on the wire
/// is assigned to port `k + 1`, whatever the mask says, so a mask that does not start at port 1
/// shifts the directions onto the wrong ports (ports past the bytes sent get clockwise). Hosts that
/// use masks starting at port 1 with no gaps, as our driver does, are unaffected.
pub fn decode_host_frame(
    bytes: &[u8],
    current: &BoardSetup,
) -> Result<Option<(HostFrame, usize)>, CodecError> {
    let Some(&cmd) = bytes.first() else {
        return Ok(None);
    };
    let mut r = Reader { b: bytes, at: 1 };
    match cmd {
        CMD_RESET => Ok(r.u8().map(|id| (HostFrame::Reset { id }, 2))),
        CMD_SETUP => Ok(decode_setup_body(&mut r).map(|s| (HostFrame::Setup(s), r.at))),
        CMD_WRITE => {
            let (n_pwm, n_m) = (current.n_pwm as usize, current.n_motors());
            if bytes.len() < 2 + n_pwm + 4 * n_m {
                return Ok(None);
            }
            let id = bytes[1];
            let mut pwm = [0u8; PORTS];
            let mut torques = [0f32; PORTS];
            r.at = 2;
            for d in pwm.iter_mut().take(n_pwm) {
                *d = r.u8().unwrap_or(0);
            }
            for t in torques.iter_mut().take(n_m) {
                *t = r.f32().unwrap_or(0.0);
            }
            Ok(Some((HostFrame::Write { id, pwm, torques }, r.at)))
        }
        other => Err(CodecError::UnknownCommand(other)),
    }
}

/// Decodes a complete setup frame (with its command byte), applying the firmware's direction-byte
/// quirk (see [`decode_host_frame`]).
pub fn decode_setup(bytes: &[u8]) -> Result<BoardSetup, CodecError> {
    match decode_host_frame(bytes, &BoardSetup::empty(0))? {
        Some((HostFrame::Setup(s), _)) => Ok(s),
        Some(_) => Err(CodecError::UnknownCommand(bytes[0])),
        None => Err(CodecError::Short {
            expected: SETUP_MAX_LEN,
            got: bytes.len(),
        }),
    }
}

fn decode_setup_body(r: &mut Reader) -> Option<BoardSetup> {
    let mut s = BoardSetup::empty(r.u8()?);
    s.motor_mask = r.u8()? & 0x0f;
    // Quirk: the k-th byte goes to port k + 1 (not to the k-th used port).
    for k in 0..s.n_motors() {
        s.motor_dir[k] = Rotation::from_byte(r.u8()?);
    }
    s.enc_mask = r.u8()? & 0x0f;
    for k in 0..s.n_encoders() {
        s.enc_dir[k] = Rotation::from_byte(r.u8()?);
    }
    s.n_sensors = r.u8()?.min(MAX_SENSORS as u8);
    for i in 0..s.n_sensors as usize {
        s.sensor_pins[i] = r.u8()?;
    }
    s.n_pwm = r.u8()?.min(PORTS as u8);
    for i in 0..s.n_pwm as usize {
        s.pwm_pins[i] = r.u8()?;
    }
    for p in used_ports(s.enc_mask) {
        s.enc_offset_deg[p] = r.f32()?;
        s.enc_resolution[p] = r.f32()?;
    }
    Some(s)
}

struct Writer<'a> {
    out: &'a mut [u8],
    at: usize,
}

impl Writer<'_> {
    fn u8(&mut self, v: u8) {
        self.out[self.at] = v;
        self.at += 1;
    }
    fn f32(&mut self, v: f32) {
        self.out[self.at..self.at + 4].copy_from_slice(&v.to_le_bytes());
        self.at += 4;
    }
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn u8(&mut self) -> Option<u8> {
        let v = *self.b.get(self.at)?;
        self.at += 1;
        Some(v)
    }
    fn f32(&mut self) -> Option<f32> {
        let s = self.b.get(self.at..self.at + 4)?;
        self.at += 4;
        Some(f32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identify_query_is_one_byte_0x03_without_an_id() {
        let mut out = [0u8; 4];
        assert_eq!(encode_identify(&mut out), Ok(1));
        assert_eq!(out[0], 0x03);
    }

    #[test]
    fn set_watchdog_is_0x04_and_the_time_little_endian_within_1_to_1000_ms() {
        let mut out = [0u8; 3];
        assert_eq!(encode_set_watchdog(20, &mut out), Ok(3));
        assert_eq!(out, [0x04, 20, 0]);
        assert_eq!(encode_set_watchdog(1000, &mut out), Ok(3));
        assert_eq!(out, [0x04, 0xe8, 0x03]);
        assert!(matches!(
            encode_set_watchdog(0, &mut out),
            Err(CodecError::Invalid(_))
        ));
        assert!(matches!(
            encode_set_watchdog(1001, &mut out),
            Err(CodecError::Invalid(_))
        ));
    }

    #[test]
    fn identify_frame_bytes_by_hand_decode_to_the_identity() {
        // [0x03]['H','2','D','F'][version 2][ports 4][caps 0b101][watchdog 300 ms = 0x012c LE]
        let bytes = [0x03, b'H', b'2', b'D', b'F', 2, 4, 0b101, 0x2c, 0x01];
        let id = decode_identity(&bytes).unwrap();
        assert_eq!(
            id,
            FirmwareIdentity {
                version: 2,
                ports: 4,
                caps: 0b101,
                watchdog_ms: 300
            }
        );
        assert!(id.has_watchdog() && !id.reset_zeroes_motors() && id.clamps_torque());
        let mut out = [0u8; IDENTIFY_LEN];
        assert_eq!(encode_identity(&id, &mut out), Ok(IDENTIFY_LEN));
        assert_eq!(out, bytes);
    }

    #[test]
    fn identify_frame_with_a_wrong_magic_a_wrong_first_byte_or_short_is_refused() {
        let good = [0x03, b'H', b'2', b'D', b'F', 1, 4, 7, 20, 0];
        let mut bad = good;
        bad[2] = b'X';
        assert!(matches!(
            decode_identity(&bad),
            Err(CodecError::NotIdentify(_))
        ));
        bad = good;
        bad[0] = 0x01;
        assert!(matches!(
            decode_identity(&bad),
            Err(CodecError::NotIdentify(_))
        ));
        assert_eq!(
            decode_identity(&good[..9]),
            Err(CodecError::Short {
                expected: 10,
                got: 9
            })
        );
    }
}
