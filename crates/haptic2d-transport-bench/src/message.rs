//! What the bench sends: the world link's real port message (252 bytes, version 2, HMAC-SHA256,
//! `haptic2d_devices::world_link`), device → world from the ping side and world → device back.
//!
//! Both processes know the key and the session ids below instead of running the link's
//! `HELLO`/`WELCOME` handshake (the handshake is not part of a period's exchange). The warm-up
//! before a run uses its own session id, so its messages are answered but never counted.

use haptic2d_devices::udp::UdpKey;
use haptic2d_devices::world_link::message::FLAG_TDPA;
use haptic2d_devices::world_link::PortMessage;

/// Session id of the measured messages (sequence numbers `1..=n`).
pub const SESSION_RUN: u64 = 0x4832_6265_6e63_6801;
/// Session id of the warm-up messages, answered but not recorded.
pub const SESSION_WARM: u64 = 0x4832_6265_6e63_6802;

/// The bench's key (32 bytes; a loopback measurement, not a secret).
pub fn key() -> UdpKey {
    UdpKey::from_bytes(&[0x5a; 32]).expect("a 32-byte key is valid")
}

/// A device → world message as the device side sends it every period: sequence number `seq`,
/// sent at `time_ns` (CLOCK_MONOTONIC), with plausible port values.
pub fn to_world(seq: u32, flags: u32, time_ns: u64) -> PortMessage {
    let s = seq as f64 * 1e-3;
    PortMessage {
        seq,
        flags: flags | FLAG_TDPA,
        time_ns,
        pose: [0.01 * s.sin(), 0.02 * s.cos(), 0.1],
        twist: [0.01 * s.cos(), -0.02 * s.sin(), 0.0],
        force: [0.5, -0.25, 0.001],
        energy_in: [1e-3 * s, 2e-3 * s, 0.0],
        energy_out: [5e-4 * s, 1e-3 * s, 0.0],
        ..Default::default()
    }
}

/// The world's answer to `m`, sent at `time_ns` (ns) by a world whose own counter is `seq`:
/// it echoes `m`'s send time and sequence number and says how long ago `m` arrived
/// (`age_ns`), as the world side of the link does, so the first side can take the round trip.
pub fn to_device(m: &PortMessage, seq: u32, time_ns: u64, age_ns: u64) -> PortMessage {
    PortMessage {
        seq,
        flags: FLAG_TDPA,
        time_ns,
        echo_time_ns: m.time_ns,
        echo_age_ns: age_ns.min(u32::MAX as u64) as u32,
        echo_seq: m.seq,
        pose: m.pose,
        twist: m.twist,
        force: [-m.force[0], -m.force[1], -m.force[2]],
        energy_in: m.energy_out,
        energy_out: m.energy_in,
        ..Default::default()
    }
}
