//! Authentication of the UDP protocol, version 2 (docs/DEVICE-PROTOCOL.md §3): the shared key, the
//! 16-byte datagram MAC (HMAC-SHA256 truncated to its first 16 bytes, RustCrypto's `hmac` and
//! `sha2`), the session handshake (`HELLO` with the host's nonce, `WELCOME` with the device's) and
//! the version-2 framing of the version-1 command and state bodies.
//!
//! ```text
//! every v2 datagram:  "H2" | 2 | kind | session u64 | body | MAC[16] = HMAC-SHA256(key, all before)[..16]
//! HELLO   (kind 3), 44 B: session 0, host_nonce[16]
//! WELCOME (kind 4), 60 B: session, host_nonce[16] (echoed), device_nonce[16]
//! COMMAND (kind 1), 68 B: session, the v1 command's bytes 4..44 (seq … command)
//! STATE   (kind 2), 92 B: session, the v1 state's bytes 4..68 (seq … force)
//! session = u64 LE of HMAC-SHA256(key, "H2v2 session" | host_nonce | device_nonce)[..8]
//! ```
//!
//! The MAC is computed from a keyed `Hmac<Sha256>` cloned per datagram (no allocation, no re-keying);
//! its check is constant-time (`verify_truncated_left`).

use hmac::{Hmac, Mac};
use sha2::Sha256;

use super::codec::{COMMAND_LEN, MAGIC, STATE_LEN};

/// Protocol version of an authenticated datagram.
pub const VERSION2: u8 = 2;
/// Kind byte of a `HELLO` (host → device: a new session, the host's nonce).
pub const KIND_HELLO: u8 = 3;
/// Kind byte of a `WELCOME` (device → host: the session, the device's nonce).
pub const KIND_WELCOME: u8 = 4;
/// Bytes of the MAC at the end of every version-2 datagram.
pub const MAC_LEN: usize = 16;
/// Bytes of a nonce.
pub const NONCE_LEN: usize = 16;
/// Header of a version-2 datagram: magic, version, kind, session (u64).
pub const HEADER2_LEN: usize = 12;
/// Size of a version-2 `HELLO`.
pub const HELLO_LEN: usize = HEADER2_LEN + NONCE_LEN + MAC_LEN;
/// Size of a version-2 `WELCOME`.
pub const WELCOME_LEN: usize = HEADER2_LEN + 2 * NONCE_LEN + MAC_LEN;
/// Size of a version-2 command.
pub const COMMAND2_LEN: usize = HEADER2_LEN + (COMMAND_LEN - 4) + MAC_LEN;
/// Size of a version-2 state.
pub const STATE2_LEN: usize = HEADER2_LEN + (STATE_LEN - 4) + MAC_LEN;
/// The shortest key accepted (bytes).
pub const MIN_KEY_LEN: usize = 16;
/// The largest key file read (bytes).
pub const MAX_KEY_FILE: u64 = 4096;

type HmacSha256 = Hmac<Sha256>;

/// A shared key, keyed once. Its `Debug` never shows the key.
#[derive(Clone)]
pub struct UdpKey {
    mac: HmacSha256,
}

impl std::fmt::Debug for UdpKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("UdpKey(…)")
    }
}

impl PartialEq for UdpKey {
    /// Equal when they MAC a fixed message alike (the keys themselves are not kept around).
    fn eq(&self, other: &Self) -> bool {
        self.tag(&[b"H2 key identity"]) == other.tag(&[b"H2 key identity"])
    }
}

/// Why a version-2 datagram was dropped before its body was read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Drop2 {
    /// Wrong size, magic, version or kind.
    Malformed,
    /// The MAC does not match.
    BadMac,
    /// A valid MAC, but another session's.
    WrongSession,
}

impl UdpKey {
    /// A key from its bytes (at least [`MIN_KEY_LEN`]).
    pub fn from_bytes(key: &[u8]) -> Result<Self, String> {
        if key.len() < MIN_KEY_LEN {
            return Err(format!(
                "a key of {} bytes is too short (at least {MIN_KEY_LEN})",
                key.len()
            ));
        }
        let mac = HmacSha256::new_from_slice(key).map_err(|e| e.to_string())?;
        Ok(Self { mac })
    }

    /// Reads a key file: hex digits (whitespace ignored, at least 32 digits) or raw bytes (at least
    /// 16). Refused when group or others have any permission on it (the fix says `chmod 600`), or
    /// when larger than [`MAX_KEY_FILE`].
    pub fn from_file(path: &std::path::Path) -> Result<Self, String> {
        use std::io::Read;
        let shown = path.display();
        let f = std::fs::File::open(path).map_err(|e| format!("key file {shown}: {e}"))?;
        let meta = f.metadata().map_err(|e| format!("key file {shown}: {e}"))?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = meta.permissions().mode() & 0o777;
            if mode & 0o077 != 0 {
                return Err(format!(
                    "key file {shown} is open to group or others (mode {mode:03o}); a key others can read is no key\n    fix: chmod 600 {shown}"
                ));
            }
        }
        if !meta.is_file() || meta.len() > MAX_KEY_FILE {
            return Err(format!(
                "key file {shown}: not a regular file of at most {MAX_KEY_FILE} bytes"
            ));
        }
        let mut raw = Vec::new();
        f.take(MAX_KEY_FILE + 1)
            .read_to_end(&mut raw)
            .map_err(|e| format!("key file {shown}: {e}"))?;
        Self::from_bytes(&key_bytes(&raw))
            .map_err(|e| format!("key file {shown}: {e}\n    fix: write 32 random bytes as hex, e.g. `head -c 32 /dev/urandom | od -An -tx1 | tr -d ' \\n' > KEY; chmod 600 KEY`"))
    }

    /// The first 16 bytes of HMAC-SHA256(key, `parts` concatenated).
    pub fn tag(&self, parts: &[&[u8]]) -> [u8; MAC_LEN] {
        let mut m = self.mac.clone();
        for p in parts {
            m.update(p);
        }
        let full = m.finalize().into_bytes();
        let mut t = [0u8; MAC_LEN];
        t.copy_from_slice(&full[..MAC_LEN]);
        t
    }

    /// Writes the MAC of `b[..len − 16]` into its last 16 bytes.
    pub fn seal(&self, b: &mut [u8]) {
        let n = b.len() - MAC_LEN;
        let t = self.tag(&[&b[..n]]);
        b[n..].copy_from_slice(&t);
    }

    /// True when the last 16 bytes of `b` are the MAC of the rest (constant-time comparison).
    pub fn verify(&self, b: &[u8]) -> bool {
        if b.len() < MAC_LEN {
            return false;
        }
        let n = b.len() - MAC_LEN;
        let mut m = self.mac.clone();
        m.update(&b[..n]);
        m.verify_truncated_left(&b[n..]).is_ok()
    }

    /// The session id both ends derive from the two nonces.
    pub fn session_id(&self, host_nonce: &[u8; NONCE_LEN], device_nonce: &[u8; NONCE_LEN]) -> u64 {
        let t = self.tag(&[b"H2v2 session", host_nonce, device_nonce]);
        let mut w = [0u8; 8];
        w.copy_from_slice(&t[..8]);
        // 0 is "no session" in a HELLO; a derived 0 (p = 2⁻⁶⁴) becomes 1.
        u64::from_le_bytes(w).max(1)
    }

    /// A `HELLO` carrying `host_nonce`.
    pub fn hello(&self, host_nonce: &[u8; NONCE_LEN]) -> [u8; HELLO_LEN] {
        let mut b = [0u8; HELLO_LEN];
        header2(&mut b, KIND_HELLO, 0);
        b[HEADER2_LEN..HEADER2_LEN + NONCE_LEN].copy_from_slice(host_nonce);
        self.seal(&mut b);
        b
    }

    /// A `WELCOME` answering `host_nonce` with `device_nonce` (the device's side; tests use it).
    pub fn welcome(
        &self,
        host_nonce: &[u8; NONCE_LEN],
        device_nonce: &[u8; NONCE_LEN],
    ) -> [u8; WELCOME_LEN] {
        let mut b = [0u8; WELCOME_LEN];
        header2(
            &mut b,
            KIND_WELCOME,
            self.session_id(host_nonce, device_nonce),
        );
        b[HEADER2_LEN..HEADER2_LEN + NONCE_LEN].copy_from_slice(host_nonce);
        b[HEADER2_LEN + NONCE_LEN..HEADER2_LEN + 2 * NONCE_LEN].copy_from_slice(device_nonce);
        self.seal(&mut b);
        b
    }

    /// The session a `WELCOME` opens, if `b` is a valid one answering `host_nonce`.
    pub fn check_welcome(&self, b: &[u8], host_nonce: &[u8; NONCE_LEN]) -> Result<u64, Drop2> {
        if b.len() != WELCOME_LEN || !is_v2(b, KIND_WELCOME) {
            return Err(Drop2::Malformed);
        }
        if !self.verify(b) {
            return Err(Drop2::BadMac);
        }
        let mut dn = [0u8; NONCE_LEN];
        dn.copy_from_slice(&b[HEADER2_LEN + NONCE_LEN..HEADER2_LEN + 2 * NONCE_LEN]);
        let sid = self.session_id(host_nonce, &dn);
        if b[HEADER2_LEN..HEADER2_LEN + NONCE_LEN] != host_nonce[..] || session_of(b) != sid {
            // Authentic, but the answer to another HELLO (an old one, replayed).
            return Err(Drop2::WrongSession);
        }
        Ok(sid)
    }

    /// Frames the v1 command `v1` as a version-2 command of `session`.
    pub fn command2(&self, session: u64, v1: &[u8; COMMAND_LEN], out: &mut [u8; COMMAND2_LEN]) {
        header2(out, v1[3], session);
        out[HEADER2_LEN..COMMAND2_LEN - MAC_LEN].copy_from_slice(&v1[4..]);
        self.seal(out);
    }

    /// Frames the v1 state `v1` as a version-2 state of `session` (the device's side; tests use it).
    pub fn state2(&self, session: u64, v1: &[u8; STATE_LEN], out: &mut [u8; STATE2_LEN]) {
        header2(out, v1[3], session);
        out[HEADER2_LEN..STATE2_LEN - MAC_LEN].copy_from_slice(&v1[4..]);
        self.seal(out);
    }

    /// Checks a received version-2 datagram of `kind` and `len` bytes against `session` and
    /// rebuilds the version-1 datagram its body carries into `v1` (for the v1 codec).
    pub fn open2(
        &self,
        b: &[u8],
        kind: u8,
        len: usize,
        session: u64,
        v1: &mut [u8],
    ) -> Result<(), Drop2> {
        if b.len() != len || !is_v2(b, kind) || v1.len() != len - HEADER2_LEN - MAC_LEN + 4 {
            return Err(Drop2::Malformed);
        }
        if !self.verify(b) {
            return Err(Drop2::BadMac);
        }
        if session_of(b) != session {
            return Err(Drop2::WrongSession);
        }
        v1[0..2].copy_from_slice(&MAGIC);
        v1[2] = 1;
        v1[3] = kind;
        v1[4..].copy_from_slice(&b[HEADER2_LEN..len - MAC_LEN]);
        Ok(())
    }
}

fn header2(b: &mut [u8], kind: u8, session: u64) {
    b[0..2].copy_from_slice(&MAGIC);
    b[2] = VERSION2;
    b[3] = kind;
    b[4..12].copy_from_slice(&session.to_le_bytes());
}

fn is_v2(b: &[u8], kind: u8) -> bool {
    b.len() >= HEADER2_LEN && b[0..2] == MAGIC && b[2] == VERSION2 && b[3] == kind
}

/// The session field of a version-2 datagram (bytes 4..12).
pub fn session_of(b: &[u8]) -> u64 {
    let mut w = [0u8; 8];
    w.copy_from_slice(&b[4..12]);
    u64::from_le_bytes(w)
}

/// Key bytes from a key file's content: hex (whitespace ignored, an even number of at least 32
/// digits, nothing else) or else the raw bytes as they are.
pub fn key_bytes(raw: &[u8]) -> Vec<u8> {
    let digits: Vec<u8> = raw
        .iter()
        .copied()
        .filter(|c| !c.is_ascii_whitespace())
        .collect();
    let hex = digits.len() >= 32
        && digits.len().is_multiple_of(2)
        && digits.iter().all(u8::is_ascii_hexdigit);
    if !hex {
        return raw.to_vec();
    }
    let val = |c: u8| (c as char).to_digit(16).unwrap_or(0) as u8;
    digits
        .chunks(2)
        .map(|p| val(p[0]) << 4 | val(p[1]))
        .collect()
}

/// 16 bytes from the system's random source (`/dev/urandom`), for a nonce.
pub fn nonce() -> std::io::Result<[u8; NONCE_LEN]> {
    use std::io::Read;
    let mut n = [0u8; NONCE_LEN];
    std::fs::File::open("/dev/urandom")?.read_exact(&mut n)?;
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hex(s: &str) -> Vec<u8> {
        key_bytes(s.as_bytes())
    }

    /// RFC 4231 test case 2 ("Jefe"): the MAC is HMAC-SHA256's first 16 bytes. The key is short,
    /// so it goes through the keyed Hmac directly.
    #[test]
    fn the_tag_is_hmac_sha256_truncated_rfc4231() {
        let m = UdpKey {
            mac: HmacSha256::new_from_slice(b"Jefe").unwrap(),
        };
        let t = m.tag(&[b"what do ya want ", b"for nothing?"]);
        assert_eq!(t.to_vec(), hex("5bdcc146bf60754e6a042426089575c7"));
        // Test case 1: key 0x0b × 20, "Hi There".
        let k = UdpKey::from_bytes(&[0x0b; 20]).unwrap();
        assert_eq!(
            k.tag(&[b"Hi There"]).to_vec(),
            hex("b0344c61d8db38535ca8afceaf0bf12b")
        );
    }

    #[test]
    fn a_sealed_datagram_verifies_and_any_flipped_bit_does_not() {
        let k = UdpKey::from_bytes(b"0123456789abcdef").unwrap();
        let other = UdpKey::from_bytes(b"0123456789abcdeX").unwrap();
        let h = k.hello(&[7; NONCE_LEN]);
        assert!(k.verify(&h));
        assert!(!other.verify(&h));
        for i in 0..h.len() * 8 {
            let mut c = h;
            c[i / 8] ^= 1 << (i % 8);
            assert!(!k.verify(&c), "bit {i}");
        }
    }

    #[test]
    fn a_welcome_opens_the_session_only_for_its_own_hello() {
        let k = UdpKey::from_bytes(&[1; 32]).unwrap();
        let (hn, dn) = ([2; NONCE_LEN], [3; NONCE_LEN]);
        let w = k.welcome(&hn, &dn);
        assert_eq!(k.check_welcome(&w, &hn), Ok(k.session_id(&hn, &dn)));
        assert_eq!(
            k.check_welcome(&w, &[9; NONCE_LEN]),
            Err(Drop2::WrongSession)
        );
        let forged = UdpKey::from_bytes(&[5; 32]).unwrap().welcome(&hn, &dn);
        assert_eq!(k.check_welcome(&forged, &hn), Err(Drop2::BadMac));
        assert_ne!(k.session_id(&hn, &dn), k.session_id(&hn, &[4; NONCE_LEN]));
    }

    #[test]
    fn key_files_are_hex_or_raw_and_short_keys_are_refused() {
        assert_eq!(hex("00ff 10\n20").len(), 10, "too few digits: raw");
        let k = key_bytes(b"000102030405060708090a0b0c0d0e0f\n");
        assert_eq!(k, (0u8..16).collect::<Vec<_>>());
        assert!(UdpKey::from_bytes(&[0; 15]).is_err());
        assert_eq!(
            format!("{:?}", UdpKey::from_bytes(&[0; 16]).unwrap()),
            "UdpKey(…)"
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_key_file_others_can_read_is_refused_with_the_chmod() {
        use std::os::unix::fs::PermissionsExt;
        let p = std::env::temp_dir().join(format!("h2-key-{}", std::process::id()));
        std::fs::write(&p, "000102030405060708090a0b0c0d0e0f").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o644)).unwrap();
        let e = UdpKey::from_file(&p).unwrap_err();
        assert!(e.contains("chmod 600") && e.contains("644"), "{e}");
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o600)).unwrap();
        assert!(UdpKey::from_file(&p).is_ok());
        let _ = std::fs::remove_file(&p);
    }
}
