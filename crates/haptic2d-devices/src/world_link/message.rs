//! The world link's datagram: one port message per period in each direction, version-2 framed and
//! MACed with the device protocol's key ([`UdpKey`]). Pure: no clock, socket or allocation.
//!
//! ```text
//!   0  "H2" | 2 | kind | session u64             12 B  (kind 5: device → world, 6: world → device)
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
//! 164  MAC[16]          HMAC-SHA256(key, bytes 0..164)[..16]
//! ```
//!
//! All numbers little-endian. A datagram with a non-finite number is malformed.

use crate::udp::auth::{session_of, Drop2, UdpKey, HEADER2_LEN, MAC_LEN, VERSION2};
use crate::udp::codec::MAGIC;

/// Kind byte of a device → world port message.
pub const KIND_TO_WORLD: u8 = 5;
/// Kind byte of a world → device port message.
pub const KIND_TO_DEVICE: u8 = 6;
/// Size of a port message (bytes).
pub const PORT_LEN: usize = 180;
/// Flag: the sender is closing the session.
pub const FLAG_BYE: u32 = 1 << 0;
/// Flag: the sender's safety latch tripped (the device side's torques are zero).
pub const FLAG_LATCHED: u32 = 1 << 1;
/// Flag: the sender runs its TDPA passivity controller (else it only observes).
pub const FLAG_TDPA: u32 = 1 << 2;
/// Every flag this version defines.
pub const FLAGS: u32 = FLAG_BYE | FLAG_LATCHED | FLAG_TDPA;

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
        key.seal(out);
    }

    /// Checks and decodes a received datagram of `kind` in `session`: size, framing, MAC (constant
    /// time), session, flags and finite numbers, in that order.
    pub fn open(key: &UdpKey, b: &[u8], kind: u8, session: u64) -> Result<Self, Drop2> {
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
        })
    }
}

const _: () = assert!(PORT_LEN == HEADER2_LEN + 32 + 5 * 24 + MAC_LEN);

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
        assert_eq!(
            PortMessage::open(&other, &b, KIND_TO_WORLD, 42),
            Err(Drop2::BadMac)
        );
        assert_eq!(
            PortMessage::open(&k, &b, KIND_TO_WORLD, 43),
            Err(Drop2::WrongSession)
        );
        assert_eq!(
            PortMessage::open(&k, &b, KIND_TO_DEVICE, 42),
            Err(Drop2::Malformed)
        );
        assert_eq!(
            PortMessage::open(&k, &b[..PORT_LEN - 1], KIND_TO_WORLD, 42),
            Err(Drop2::Malformed)
        );
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
}
