//! The world link's datagram: one port message per period in each direction, version-2 framed and
//! MACed with the device protocol's key ([`UdpKey`]). Pure: no clock, socket or allocation.
//!
//! This is the world link's message **version 2** (kinds 7 and 8, 252 bytes): version 1 (kinds 5
//! and 6, 180 bytes, before wave variables crossed the link) is recognised and refused as
//! [`Refused::OldVersion`], so an end of the older build is told apart from noise.
//!
//! ```text
//!   0  "H2" | 2 | kind | session u64             12 B  (kind 7: device → world, 8: world → device)
//!  12  seq              u32   sender's counter, 1 for the first message of a session
//!  16  flags            u32   FLAG_BYE, FLAG_LATCHED, FLAG_TDPA
//!  20  time_ns          u64   sender's monotonic clock at sending
//!  28  echo_time_ns     u64   `time_ns` of the newest message received from the other side (0: none)
//!  36  echo_age_ns      u32   how long ago that message arrived (ns, saturating): the round trip
//!                             is `now − echo_time_ns − echo_age_ns` on the first side's clock
//!  40  echo_seq         u32   `seq` of that message
//!  44  pose[3]          f64   the sender's port body: (x, y, θ) (m, m, rad) from its origin
//!  68  twist[3]         f64   its rate (m/s, m/s, rad/s)
//!  92  force[3]         f64   device → world: the force applied to the handle by the link;
//!                             world → device: the force for the handle (N, N, N·m)
//! 116  energy_in[3]     f64   the sender's TDPA port, per axis (J, non-decreasing)
//! 140  energy_out[3]    f64
//! 164  wave[3]          f64   wave variables (FLAG_WAVE): device → world u_m, world → device w_s,
//!                             per axis (√W); 0 without waves
//! 188  wave_energy[3]   f64   the wave energy the sender has put on the link so far, Σ ½·wave²·T
//!                             per axis (J, non-decreasing): the receiver never uses more
//! 212  wave_x[3]        f64   the sender's wave position: device → world the handle's x_m (for the
//!                             drift compensation), world → device the commanded point x_d
//! 236  MAC[16]          HMAC-SHA256(key, bytes 0..236)[..16]
//! ```
//!
//! All numbers little-endian. A datagram with a non-finite number is malformed.

use crate::udp::auth::{session_of, Drop2, UdpKey, HEADER2_LEN, MAC_LEN, VERSION2};
use crate::udp::codec::MAGIC;

/// Kind byte of a device → world port message (message version 2).
pub const KIND_TO_WORLD: u8 = 7;
/// Kind byte of a world → device port message (message version 2).
pub const KIND_TO_DEVICE: u8 = 8;
/// Size of a port message (bytes).
pub const PORT_LEN: usize = 252;
/// Kind bytes of the version-1 port messages (device → world, world → device), refused.
pub const KINDS_V1: [u8; 2] = [5, 6];
/// Size of a version-1 port message (bytes).
pub const PORT_LEN_V1: usize = 180;
/// Flag: the sender is closing the session.
pub const FLAG_BYE: u32 = 1 << 0;
/// Flag: the sender's safety latch tripped (the device side's torques are zero).
pub const FLAG_LATCHED: u32 = 1 << 1;
/// Flag: the sender runs its TDPA passivity controller (else it only observes).
pub const FLAG_TDPA: u32 = 1 << 2;
/// Flag: the sender runs wave variables (the `wave*` fields are its waves).
pub const FLAG_WAVE: u32 = 1 << 3;
/// Every flag this version defines.
pub const FLAGS: u32 = FLAG_BYE | FLAG_LATCHED | FLAG_TDPA | FLAG_WAVE;

/// The link-kind flag of an end running TDPA (`tdpa`), else wave variables (`wave`), else plain
/// force/velocity (no flag): what every message of that end carries, its goodbye included.
pub fn link_flags(tdpa: bool, wave: bool) -> u32 {
    if tdpa {
        FLAG_TDPA
    } else if wave {
        FLAG_WAVE
    } else {
        0
    }
}

/// Why a datagram was not accepted as a port message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refused {
    /// Wrong size, framing, kind or flags, or a non-finite number; or the MAC or session failed.
    Drop(Drop2),
    /// An authentic version-1 port message (kinds 5/6, 180 B) of this session: the other end is an
    /// older build.
    OldVersion,
}

/// One port message (either direction). SI units, see the module doc.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PortMessage {
    /// Sender's sequence number.
    pub seq: u32,
    /// `FLAG_*` bits.
    pub flags: u32,
    /// Sender's clock at sending (ns).
    pub time_ns: u64,
    /// `time_ns` of the newest message received from the other side (ns; 0 = none).
    pub echo_time_ns: u64,
    /// Time between that message's arrival and this one's sending (ns, saturating).
    pub echo_age_ns: u32,
    /// `seq` of that message.
    pub echo_seq: u32,
    /// Port body pose from the sender's origin (m, m, rad).
    pub pose: [f64; 3],
    /// Port body twist (m/s, m/s, rad/s).
    pub twist: [f64; 3],
    /// Force (N, N, N·m), see the module doc.
    pub force: [f64; 3],
    /// The sender's TDPA energy-in per axis (J).
    pub energy_in: [f64; 3],
    /// The sender's TDPA energy-out per axis (J).
    pub energy_out: [f64; 3],
    /// The sender's wave per axis (√W; `FLAG_WAVE`): `u_m` device → world, `w_s` world → device.
    pub wave: [f64; 3],
    /// The wave energy the sender has put on the link so far per axis (J, non-decreasing).
    pub wave_energy: [f64; 3],
    /// The sender's wave position per axis (m, m, rad): the handle's, or the commanded point's.
    pub wave_x: [f64; 3],
}

fn put3(b: &mut [u8], at: usize, v: &[f64; 3]) {
    for (i, x) in v.iter().enumerate() {
        b[at + 8 * i..at + 8 * i + 8].copy_from_slice(&x.to_le_bytes());
    }
}

fn get3(b: &[u8], at: usize) -> Option<[f64; 3]> {
    let mut v = [0.0; 3];
    for (i, x) in v.iter_mut().enumerate() {
        let mut w = [0u8; 8];
        w.copy_from_slice(&b[at + 8 * i..at + 8 * i + 8]);
        *x = f64::from_le_bytes(w);
        if !x.is_finite() {
            return None;
        }
    }
    Some(v)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut w = [0u8; 8];
    w.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(w)
}

impl PortMessage {
    /// Encodes and seals the message as `kind` of `session` into `out`.
    pub fn seal(&self, key: &UdpKey, kind: u8, session: u64, out: &mut [u8; PORT_LEN]) {
        out[0..2].copy_from_slice(&MAGIC);
        out[2] = VERSION2;
        out[3] = kind;
        out[4..12].copy_from_slice(&session.to_le_bytes());
        out[12..16].copy_from_slice(&self.seq.to_le_bytes());
        out[16..20].copy_from_slice(&self.flags.to_le_bytes());
        out[20..28].copy_from_slice(&self.time_ns.to_le_bytes());
        out[28..36].copy_from_slice(&self.echo_time_ns.to_le_bytes());
        out[36..40].copy_from_slice(&self.echo_age_ns.to_le_bytes());
        out[40..44].copy_from_slice(&self.echo_seq.to_le_bytes());
        put3(out, 44, &self.pose);
        put3(out, 68, &self.twist);
        put3(out, 92, &self.force);
        put3(out, 116, &self.energy_in);
        put3(out, 140, &self.energy_out);
        put3(out, 164, &self.wave);
        put3(out, 188, &self.wave_energy);
        put3(out, 212, &self.wave_x);
        key.seal(out);
    }

    /// Checks and decodes a received datagram of `kind` in `session`: size, framing, MAC (constant
    /// time), session, flags and finite numbers, in that order.
    pub fn open(key: &UdpKey, b: &[u8], kind: u8, session: u64) -> Result<Self, Drop2> {
        Self::open_versioned(key, b, kind, session).map_err(|r| match r {
            Refused::Drop(d) => d,
            Refused::OldVersion => Drop2::Malformed,
        })
    }

    /// As [`Self::open`], but an authentic version-1 port message of this session is told apart
    /// ([`Refused::OldVersion`]) from a malformed datagram.
    pub fn open_versioned(key: &UdpKey, b: &[u8], kind: u8, session: u64) -> Result<Self, Refused> {
        if b.len() == PORT_LEN_V1
            && b[0..2] == MAGIC
            && b[2] == VERSION2
            && KINDS_V1.contains(&b[3])
            && key.verify(b)
            && session_of(b) == session
        {
            return Err(Refused::OldVersion);
        }
        Self::open_v2(key, b, kind, session).map_err(Refused::Drop)
    }

    fn open_v2(key: &UdpKey, b: &[u8], kind: u8, session: u64) -> Result<Self, Drop2> {
        if b.len() != PORT_LEN || b[0..2] != MAGIC || b[2] != VERSION2 || b[3] != kind {
            return Err(Drop2::Malformed);
        }
        if !key.verify(b) {
            return Err(Drop2::BadMac);
        }
        if session_of(b) != session {
            return Err(Drop2::WrongSession);
        }
        let flags = u32_at(b, 16);
        if flags & !FLAGS != 0 {
            return Err(Drop2::Malformed);
        }
        let three = |at| get3(b, at).ok_or(Drop2::Malformed);
        Ok(Self {
            seq: u32_at(b, 12),
            flags,
            time_ns: u64_at(b, 20),
            echo_time_ns: u64_at(b, 28),
            echo_age_ns: u32_at(b, 36),
            echo_seq: u32_at(b, 40),
            pose: three(44)?,
            twist: three(68)?,
            force: three(92)?,
            energy_in: three(116)?,
            energy_out: three(140)?,
            wave: three(164)?,
            wave_energy: three(188)?,
            wave_x: three(212)?,
        })
    }
}

const _: () = assert!(PORT_LEN == HEADER2_LEN + 32 + 8 * 24 + MAC_LEN);
const _: () = assert!(PORT_LEN_V1 == HEADER2_LEN + 32 + 5 * 24 + MAC_LEN);

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> PortMessage {
        PortMessage {
            seq: 7,
            flags: FLAG_TDPA,
            time_ns: 1_000_000,
            echo_time_ns: 999_000,
            echo_age_ns: 500,
            echo_seq: 6,
            pose: [0.01, -0.02, 0.1],
            twist: [0.5, 0.0, -1.0],
            force: [-2.0, 0.25, 0.001],
            energy_in: [1e-3, 2e-3, 0.0],
            energy_out: [5e-4, 0.0, 0.0],
            wave: [1.5, -0.5, 0.01],
            wave_energy: [2e-3, 1e-4, 0.0],
            wave_x: [0.012, 0.0, -0.1],
        }
    }

    #[test]
    fn a_sealed_port_message_opens_to_itself() {
        let k = UdpKey::from_bytes(&[3; 32]).unwrap();
        let mut b = [0u8; PORT_LEN];
        example().seal(&k, KIND_TO_WORLD, 42, &mut b);
        assert_eq!(PortMessage::open(&k, &b, KIND_TO_WORLD, 42), Ok(example()));
    }

    #[test]
    fn a_port_message_of_another_key_session_kind_or_with_a_flipped_bit_is_dropped() {
        let k = UdpKey::from_bytes(&[3; 32]).unwrap();
        let other = UdpKey::from_bytes(&[4; 32]).unwrap();
        let mut b = [0u8; PORT_LEN];
        example().seal(&k, KIND_TO_WORLD, 42, &mut b);
        // (key, datagram, kind, session) → why it is dropped.
        let cases: [(&UdpKey, &[u8], u8, u64, Drop2); 4] = [
            (&other, &b, KIND_TO_WORLD, 42, Drop2::BadMac),
            (&k, &b, KIND_TO_WORLD, 43, Drop2::WrongSession),
            (&k, &b, KIND_TO_DEVICE, 42, Drop2::Malformed),
            (&k, &b[..PORT_LEN - 1], KIND_TO_WORLD, 42, Drop2::Malformed),
        ];
        for (key, bytes, kind, session, why) in cases {
            let got = PortMessage::open(key, bytes, kind, session);
            assert_eq!(got, Err(why), "kind {kind}, session {session}");
        }
        for i in 4 * 8..b.len() * 8 {
            let mut c = b;
            c[i / 8] ^= 1 << (i % 8);
            assert!(
                PortMessage::open(&k, &c, KIND_TO_WORLD, 42).is_err(),
                "bit {i}"
            );
        }
    }

    #[test]
    fn an_authentic_port_message_with_a_nan_is_malformed() {
        let k = UdpKey::from_bytes(&[3; 32]).unwrap();
        let mut m = example();
        m.force[1] = f64::NAN;
        let mut b = [0u8; PORT_LEN];
        m.seal(&k, KIND_TO_DEVICE, 1, &mut b);
        assert_eq!(
            PortMessage::open(&k, &b, KIND_TO_DEVICE, 1),
            Err(Drop2::Malformed)
        );
    }

    #[test]
    fn a_version_1_port_message_of_the_session_is_refused_as_old_not_as_noise() {
        let k = UdpKey::from_bytes(&[3; 32]).unwrap();
        // A version-1 datagram as the older build sealed it: kind 5, 180 bytes.
        let mut b = [0u8; PORT_LEN_V1];
        b[0..2].copy_from_slice(&MAGIC);
        b[2] = VERSION2;
        b[3] = KINDS_V1[0];
        b[4..12].copy_from_slice(&42u64.to_le_bytes());
        k.seal(&mut b);
        assert_eq!(
            PortMessage::open_versioned(&k, &b, KIND_TO_WORLD, 42),
            Err(Refused::OldVersion)
        );
        assert_eq!(
            PortMessage::open(&k, &b, KIND_TO_WORLD, 42),
            Err(Drop2::Malformed)
        );
        // Another key's or another session's old datagram is not credited as an older end.
        let other = UdpKey::from_bytes(&[4; 32]).unwrap();
        assert_eq!(
            PortMessage::open_versioned(&other, &b, KIND_TO_WORLD, 42),
            Err(Refused::Drop(Drop2::Malformed))
        );
        assert_eq!(
            PortMessage::open_versioned(&k, &b, KIND_TO_WORLD, 43),
            Err(Refused::Drop(Drop2::Malformed))
        );
    }

    #[test]
    fn the_wave_fields_and_flag_cross_the_link() {
        let k = UdpKey::from_bytes(&[3; 32]).unwrap();
        let m = PortMessage {
            flags: FLAG_WAVE,
            ..example()
        };
        let mut b = [0u8; PORT_LEN];
        m.seal(&k, KIND_TO_DEVICE, 9, &mut b);
        let got = PortMessage::open(&k, &b, KIND_TO_DEVICE, 9).unwrap();
        assert_eq!(got.wave, m.wave);
        assert_eq!(got.wave_energy, m.wave_energy);
        assert_eq!(got.wave_x, m.wave_x);
        assert_eq!(got.flags, FLAG_WAVE);
    }
}
