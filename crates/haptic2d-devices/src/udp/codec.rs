//! The codec of the open UDP device protocol, version 1 (docs/DEVICE-PROTOCOL.md): pure, no clock,
//! socket or allocation. Two fixed-size little-endian datagrams:
//!
//! ```text
//! Command (host → device), 44 bytes          State (device → host), 68 bytes
//!  0  magic "H2"        2 B                   0  magic "H2"          2 B
//!  2  version = 1       u8                    2  version = 1         u8
//!  3  kind = 1          u8                    3  kind = 2            u8
//!  4  seq               u32                   4  seq                 u32  (device's counter)
//!  8  host_time_ns      u64                   8  echo_seq            u32  (command answered)
//! 16  echo_device_ns    u64                  12  status              u32  (bits below)
//! 24  echo_seq          u32                  16  device_time_ns      u64
//! 28  flags             u16                  24  echo_host_ns        u64
//! 30  reserved = 0      u16                  32  position[3]         f32 × 3
//! 32  command[3]        f32 × 3              44  velocity[3]         f32 × 3
//!                                            56  force[3]            f32 × 3
//! ```
//!
//! Units: joint angles rad, joint rates rad/s, joint torques N·m; a pose is `(x, y, θ)` in
//! (m, m, rad), its rate (m/s, m/s, rad/s), a wrench `(f_x, f_y, τ)` in (N, N, N·m). Times are
//! nanoseconds of the sender's own monotonic clock; each side echoes the other's last timestamp so
//! the host gets the round trip without a shared clock.

/// The two magic bytes every datagram starts with.
pub const MAGIC: [u8; 2] = *b"H2";
/// Protocol version of this codec.
pub const VERSION: u8 = 1;
/// Kind byte of a [`Command`].
pub const KIND_COMMAND: u8 = 1;
/// Kind byte of a [`State`].
pub const KIND_STATE: u8 = 2;
/// Size of a command datagram (bytes).
pub const COMMAND_LEN: usize = 44;
/// Size of a state datagram (bytes).
pub const STATE_LEN: usize = 68;

/// Command flag: the device may apply `command` (else it holds zero torque; a poll).
pub const FLAG_ENABLE: u16 = 1 << 0;
/// Command flag: `command` is a wrench `(f_x, f_y, τ)`, else joint torques.
pub const FLAG_WRENCH: u16 = 1 << 1;
/// Command flag: the host has latched a safety stop; the device zeroes its motors and stays so
/// until the host starts again (seq restarts at 1).
pub const FLAG_LATCHED: u16 = 1 << 2;
/// Command flag: the host is closing; the device zeroes its motors.
pub const FLAG_BYE: u16 = 1 << 3;
/// Flags a version-1 host may set; any other bit is malformed.
pub const COMMAND_FLAGS: u16 = FLAG_ENABLE | FLAG_WRENCH | FLAG_LATCHED | FLAG_BYE;

/// Status bit: `position` is a pose `(x, y, θ)`, else joint angles.
pub const STATUS_POSE: u32 = 1 << 0;
/// Status bit: `velocity` holds measured rates (else zeros, ignored).
pub const STATUS_VELOCITY: u32 = 1 << 1;
/// Status bit: `force` holds sensed forces (else zeros, ignored).
pub const STATUS_FORCE: u32 = 1 << 2;
/// Status bit: the device applies the host's commands (its motors are powered and enabled).
pub const STATUS_ENABLED: u32 = 1 << 3;
/// Status bit: the device clamped the last command to its own limits.
pub const STATUS_LIMITED: u32 = 1 << 4;
/// Status bit: the device has a fault of its own (e.g. its watchdog zeroed the motors); the host
/// treats it as lost.
pub const STATUS_FAULT: u32 = 1 << 5;
/// Status bits 8–15: the device's buttons 0–7 (bit `8 + i` set = button `i` pressed when the
/// state was sampled). A device without buttons sends 0 there, as every device before them did.
pub const STATUS_BUTTONS: u32 = 0xff << STATUS_BUTTONS_SHIFT;
/// The position of button 0 in `status`.
pub const STATUS_BUTTONS_SHIFT: u32 = 8;
/// Status bits a device may set; any other bit is malformed.
pub const STATUS_BITS: u32 = STATUS_POSE
    | STATUS_VELOCITY
    | STATUS_FORCE
    | STATUS_ENABLED
    | STATUS_LIMITED
    | STATUS_FAULT
    | STATUS_BUTTONS;

/// A host → device datagram.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Command {
    /// Sequence number, 1 for the first command after the host opens, +1 per command.
    pub seq: u32,
    /// Host clock at sending (ns).
    pub host_time_ns: u64,
    /// `device_time_ns` of the latest state the host has received (0 before the first).
    pub echo_device_ns: u64,
    /// `seq` of the latest state the host has received (0 before the first).
    pub echo_seq: u32,
    /// `FLAG_*` bits.
    pub flags: u16,
    /// Joint torques (N·m) or, with [`FLAG_WRENCH`], a wrench (N, N, N·m); unused entries zero.
    pub command: [f32; 3],
}

/// A device → host datagram.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    /// The device's own sequence number, +1 per state sent.
    pub seq: u32,
    /// `seq` of the command this state answers (0: none yet).
    pub echo_seq: u32,
    /// `STATUS_*` bits.
    pub status: u32,
    /// Device clock when `position` was sampled (ns).
    pub device_time_ns: u64,
    /// `host_time_ns` of the command answered (0: none yet).
    pub echo_host_ns: u64,
    /// Joint angles (rad) or, with [`STATUS_POSE`], a pose (m, m, rad).
    pub position: [f32; 3],
    /// Rates of `position` (rad/s or m/s, m/s, rad/s) when [`STATUS_VELOCITY`] is set.
    pub velocity: [f32; 3],
    /// Sensed joint torques (N·m) or wrench (N, N, N·m) when [`STATUS_FORCE`] is set.
    pub force: [f32; 3],
}

/// Why a datagram was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CodecError {
    /// Wrong size (bytes received, bytes expected).
    Length(usize, usize),
    /// The first two bytes are not "H2".
    Magic,
    /// A version this codec does not speak.
    Version(u8),
    /// A kind byte other than the one expected.
    Kind(u8),
    /// Bits set that version 1 does not define.
    ReservedBits,
    /// A NaN or infinite number (index of the f32 field, 0-based in datagram order).
    NonFinite(usize),
}

impl std::fmt::Display for CodecError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CodecError::Length(n, e) => write!(f, "{n} bytes, expected {e}"),
            CodecError::Magic => write!(f, "does not start with \"H2\""),
            CodecError::Version(v) => write!(f, "protocol version {v}, this host speaks {VERSION}"),
            CodecError::Kind(k) => write!(f, "datagram kind {k} unexpected"),
            CodecError::ReservedBits => write!(f, "undefined flag or status bits set"),
            CodecError::NonFinite(i) => write!(f, "number {i} is not finite"),
        }
    }
}

fn header(b: &[u8], len: usize, kind: u8) -> Result<(), CodecError> {
    if b.len() != len {
        return Err(CodecError::Length(b.len(), len));
    }
    if b[0..2] != MAGIC {
        return Err(CodecError::Magic);
    }
    if b[2] != VERSION {
        return Err(CodecError::Version(b[2]));
    }
    if b[3] != kind {
        return Err(CodecError::Kind(b[3]));
    }
    Ok(())
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut w = [0u8; 8];
    w.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(w)
}

fn f32s_at(b: &[u8], at: usize, first: usize) -> Result<[f32; 3], CodecError> {
    let mut v = [0f32; 3];
    for (i, x) in v.iter_mut().enumerate() {
        *x = f32::from_bits(u32_at(b, at + 4 * i));
        if !x.is_finite() {
            return Err(CodecError::NonFinite(first + i));
        }
    }
    Ok(v)
}

fn put_f32s(b: &mut [u8], at: usize, v: &[f32; 3]) {
    for (i, x) in v.iter().enumerate() {
        b[at + 4 * i..at + 4 * i + 4].copy_from_slice(&x.to_le_bytes());
    }
}

impl Command {
    /// Encodes into `out`.
    pub fn encode(&self, out: &mut [u8; COMMAND_LEN]) {
        out[0..2].copy_from_slice(&MAGIC);
        out[2] = VERSION;
        out[3] = KIND_COMMAND;
        out[4..8].copy_from_slice(&self.seq.to_le_bytes());
        out[8..16].copy_from_slice(&self.host_time_ns.to_le_bytes());
        out[16..24].copy_from_slice(&self.echo_device_ns.to_le_bytes());
        out[24..28].copy_from_slice(&self.echo_seq.to_le_bytes());
        out[28..30].copy_from_slice(&self.flags.to_le_bytes());
        out[30..32].copy_from_slice(&[0, 0]);
        put_f32s(out, 32, &self.command);
    }

    /// Decodes a received datagram `b` (exactly [`COMMAND_LEN`] bytes).
    pub fn decode(b: &[u8]) -> Result<Self, CodecError> {
        header(b, COMMAND_LEN, KIND_COMMAND)?;
        let flags = u16::from_le_bytes([b[28], b[29]]);
        if flags & !COMMAND_FLAGS != 0 || b[30] != 0 || b[31] != 0 {
            return Err(CodecError::ReservedBits);
        }
        Ok(Self {
            seq: u32_at(b, 4),
            host_time_ns: u64_at(b, 8),
            echo_device_ns: u64_at(b, 16),
            echo_seq: u32_at(b, 24),
            flags,
            command: f32s_at(b, 32, 0)?,
        })
    }
}

impl State {
    /// Encodes into `out`.
    pub fn encode(&self, out: &mut [u8; STATE_LEN]) {
        out[0..2].copy_from_slice(&MAGIC);
        out[2] = VERSION;
        out[3] = KIND_STATE;
        out[4..8].copy_from_slice(&self.seq.to_le_bytes());
        out[8..12].copy_from_slice(&self.echo_seq.to_le_bytes());
        out[12..16].copy_from_slice(&self.status.to_le_bytes());
        out[16..24].copy_from_slice(&self.device_time_ns.to_le_bytes());
        out[24..32].copy_from_slice(&self.echo_host_ns.to_le_bytes());
        put_f32s(out, 32, &self.position);
        put_f32s(out, 44, &self.velocity);
        put_f32s(out, 56, &self.force);
    }

    /// Decodes a received datagram `b` (exactly [`STATE_LEN`] bytes). Velocities and forces are
    /// checked for finiteness only when their status bit says they are present.
    pub fn decode(b: &[u8]) -> Result<Self, CodecError> {
        header(b, STATE_LEN, KIND_STATE)?;
        let status = u32_at(b, 12);
        if status & !STATUS_BITS != 0 {
            return Err(CodecError::ReservedBits);
        }
        let optional = |at: usize, first: usize, bit: u32| {
            if status & bit != 0 {
                f32s_at(b, at, first)
            } else {
                Ok([0.0; 3])
            }
        };
        Ok(Self {
            seq: u32_at(b, 4),
            echo_seq: u32_at(b, 8),
            status,
            device_time_ns: u64_at(b, 16),
            echo_host_ns: u64_at(b, 24),
            position: f32s_at(b, 32, 0)?,
            velocity: optional(44, 3, STATUS_VELOCITY)?,
            force: optional(56, 6, STATUS_FORCE)?,
        })
    }

    /// True when `position` is a pose.
    pub fn is_pose(&self) -> bool {
        self.status & STATUS_POSE != 0
    }

    /// The buttons of `status` bits 8–15: bit `i` = button `i` pressed.
    pub fn buttons(&self) -> u8 {
        ((self.status & STATUS_BUTTONS) >> STATUS_BUTTONS_SHIFT) as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hex with a space every byte, 16 bytes a line (the form of docs/DEVICE-PROTOCOL.md).
    pub(crate) fn hex(b: &[u8]) -> String {
        b.chunks(16)
            .map(|c| {
                c.iter()
                    .map(|x| format!("{x:02x}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    fn example_command() -> Command {
        Command {
            seq: 42,
            host_time_ns: 1_000_000_000,
            echo_device_ns: 5_000,
            echo_seq: 41,
            flags: FLAG_ENABLE,
            command: [0.05, -0.025, 0.0],
        }
    }

    fn example_state() -> State {
        State {
            seq: 41,
            echo_seq: 42,
            status: STATUS_VELOCITY | STATUS_ENABLED,
            device_time_ns: 6_000,
            echo_host_ns: 1_000_000_000,
            position: [1.5, 0.5, 0.0],
            velocity: [0.25, -0.25, 0.0],
            force: [0.0; 3],
        }
    }

    /// The worked example of docs/DEVICE-PROTOCOL.md §5 (command).
    #[test]
    fn command_byte_vector() {
        let mut b = [0u8; COMMAND_LEN];
        example_command().encode(&mut b);
        let expected = "48 32 01 01 2a 00 00 00 00 ca 9a 3b 00 00 00 00\n\
                        88 13 00 00 00 00 00 00 29 00 00 00 01 00 00 00\n\
                        cd cc 4c 3d cd cc cc bc 00 00 00 00";
        assert_eq!(hex(&b), expected, "\n{}", hex(&b));
        assert_eq!(Command::decode(&b), Ok(example_command()));
    }

    /// The worked example of docs/DEVICE-PROTOCOL.md §5 (state).
    #[test]
    fn state_byte_vector() {
        let mut b = [0u8; STATE_LEN];
        example_state().encode(&mut b);
        let expected = "48 32 01 02 29 00 00 00 2a 00 00 00 0a 00 00 00\n\
                        70 17 00 00 00 00 00 00 00 ca 9a 3b 00 00 00 00\n\
                        00 00 c0 3f 00 00 00 3f 00 00 00 00 00 00 80 3e\n\
                        00 00 80 be 00 00 00 00 00 00 00 00 00 00 00 00\n\
                        00 00 00 00";
        assert_eq!(hex(&b), expected, "\n{}", hex(&b));
        assert_eq!(State::decode(&b), Ok(example_state()));
    }

    #[test]
    fn malformed_datagrams_are_rejected_with_their_reason() {
        let mut b = [0u8; STATE_LEN];
        example_state().encode(&mut b);
        assert_eq!(State::decode(&b[..67]), Err(CodecError::Length(67, 68)));
        let mut c = b;
        c[0] = b'X';
        assert_eq!(State::decode(&c), Err(CodecError::Magic));
        let mut c = b;
        c[2] = 2;
        assert_eq!(State::decode(&c), Err(CodecError::Version(2)));
        let mut c = b;
        c[3] = KIND_COMMAND;
        assert_eq!(State::decode(&c), Err(CodecError::Kind(1)));
        let mut c = b;
        c[15] = 0x80;
        assert_eq!(State::decode(&c), Err(CodecError::ReservedBits));
        let mut c = b;
        c[36..40].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(State::decode(&c), Err(CodecError::NonFinite(1)));
        // A NaN in the force block is ignored while STATUS_FORCE is clear, rejected once set.
        let mut c = b;
        c[56..60].copy_from_slice(&f32::INFINITY.to_le_bytes());
        assert!(State::decode(&c).is_ok());
        c[12] |= STATUS_FORCE as u8;
        assert_eq!(State::decode(&c), Err(CodecError::NonFinite(6)));
        let mut d = [0u8; COMMAND_LEN];
        example_command().encode(&mut d);
        d[29] = 0x01;
        assert_eq!(Command::decode(&d), Err(CodecError::ReservedBits));
        assert_eq!(
            Command::decode(&b[..COMMAND_LEN]),
            Err(CodecError::Kind(KIND_STATE))
        );
    }

    /// Status bits 8–15 (byte 13 of the datagram, the u32 at 12 being little-endian) are buttons
    /// 0–7; an old device's 0 there is no button; bits 16–31 stay malformed.
    #[test]
    fn status_byte_13_carries_the_buttons_and_higher_bits_stay_reserved() {
        let mut b = [0u8; STATE_LEN];
        example_state().encode(&mut b);
        assert_eq!(State::decode(&b).unwrap().buttons(), 0);
        let mut c = b;
        c[13] = 0b1000_0101;
        let s = State::decode(&c).expect("button bits are valid");
        assert_eq!(s.buttons(), 0b1000_0101);
        assert_eq!(s.status & 0xff, 0x0a, "the low status bits are untouched");
        let mut e = [0u8; STATE_LEN];
        s.encode(&mut e);
        assert_eq!(e, c, "round trip");
        let mut c = b;
        c[14] = 0x01;
        assert_eq!(State::decode(&c), Err(CodecError::ReservedBits));
    }

    #[test]
    fn pose_state_round_trips() {
        let s = State {
            status: STATUS_POSE | STATUS_FORCE,
            position: [0.019, 0.1, 0.25],
            force: [1.0, -2.0, 0.01],
            velocity: [0.0; 3],
            ..example_state()
        };
        let mut b = [0u8; STATE_LEN];
        s.encode(&mut b);
        let d = State::decode(&b).unwrap();
        assert!(d.is_pose());
        assert_eq!(d, s);
    }
}
