//! Caps on log input (issue 38): every log reader of haptic2d (`log info`, `log convert`,
//! `--device replay:FILE.csv|FILE.mcap`) checks what a file is and how big it is before it reads or
//! allocates, so a hostile or mistaken input (`/dev/zero`, a pipe that never ends, one endless
//! line, a length field of 2⁶⁴ − 1) is a clear error, never an exhausted memory or a panic.
//!
//! - a log file is at most [`MAX_LOG_BYTES`] (1 GiB): a regular file above it is refused before
//!   anything is read; a file without a length (a pipe, a character device) is read through the
//!   same cap ([`read_log_file`]);
//! - an MCAP log must start with the MCAP magic bytes, checked on the first 8 bytes before the rest
//!   is read (so `/dev/zero` is refused at once);
//! - a CSV log is text: a NUL byte or a line longer than [`MAX_CSV_LINE_BYTES`] (1 MiB) is refused
//!   where it is found ([`TextGuard`]), before a record of it is buffered.

use std::fs::{File, Metadata};
use std::io::Read;
use std::path::Path;

/// Largest log file read (bytes): 1 GiB, about 10 million ticks of a CSV tick log (17 min at
/// 10 kHz, 2.8 h at 1 kHz) or about a million ticks of an MCAP log with the world channels.
pub const MAX_LOG_BYTES: u64 = 1 << 30;

/// Longest line of a CSV log (bytes, newline excluded): 1 MiB. A tick row of every column is about
/// 1.5 KB; a line this long is not a log (a binary file, one endless line).
pub const MAX_CSV_LINE_BYTES: u64 = 1 << 20;

/// Reads the whole log file `path` (`what` names it in errors: "MCAP file", "replay file"), at most
/// [`MAX_LOG_BYTES`]. With `magic`, the file must start with those bytes (checked before the rest
/// is read). Errors name the file, the cap and the fix.
pub fn read_log_file(path: &Path, what: &str, magic: Option<&[u8]>) -> Result<Vec<u8>, String> {
    let (file, meta, label) = open_log_file(path, what)?;
    let declared = meta.is_file().then_some(meta.len());
    read_capped(file, &label, what, declared, MAX_LOG_BYTES, magic)
}

/// Opens the log file `path` for reading (`what` names it in errors: "CSV log", "MCAP file"):
/// the file, its metadata and its label (the path as text). A directory is refused.
pub fn open_log_file(path: &Path, what: &str) -> Result<(File, Metadata, String), String> {
    let label = path.display().to_string();
    let file = File::open(path).map_err(|e| format!("cannot read the {what} {label}: {e}"))?;
    let meta = file
        .metadata()
        .map_err(|e| format!("cannot read the {what} {label}: {e}"))?;
    if meta.is_dir() {
        return Err(format!("the {what} {label} is a directory"));
    }
    Ok((file, meta, label))
}

/// [`read_log_file`] from any reader: `declared` is the reader's length if it has one (a regular
/// file's size), checked against `cap` before anything is read; the bytes read are capped at `cap`
/// whatever was declared (a file that grows, a pipe, a device).
pub fn read_capped<R: Read>(
    reader: R,
    label: &str,
    what: &str,
    declared: Option<u64>,
    cap: u64,
    magic: Option<&[u8]>,
) -> Result<Vec<u8>, String> {
    let too_big = |n: String| {
        format!(
            "the {what} {label} is {n} bytes, above the cap of {cap} bytes ({})\n    fix: cut the recording into parts (`haptic2d run --duration`), or record fewer channels (a CSV tick log)",
            human(cap)
        )
    };
    if let Some(n) = declared {
        if n > cap {
            return Err(too_big(n.to_string()));
        }
    }
    let mut r = reader.take(cap.saturating_add(1));
    let mut bytes = Vec::with_capacity(declared.unwrap_or(0).min(cap) as usize);
    if let Some(m) = magic {
        let mut head = vec![0u8; m.len()];
        let mut got = 0;
        while got < head.len() {
            match r.read(&mut head[got..]) {
                Ok(0) => break,
                Ok(n) => got += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(format!("cannot read the {what} {label}: {e}")),
            }
        }
        if head[..got] != m[..] {
            return Err(format!(
                "{label} is not an MCAP file (it does not start with the MCAP magic bytes)\n    fix: give a file written by `haptic2d run --log FILE.mcap` or another MCAP writer"
            ));
        }
        bytes.extend_from_slice(&head);
    }
    r.read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read the {what} {label}: {e}"))?;
    if bytes.len() as u64 > cap {
        return Err(too_big(format!("more than {cap}")));
    }
    Ok(bytes)
}

/// `bytes` in the largest binary unit that divides it evenly (for messages).
fn human(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b % (1 << 30) == 0 => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b % (1 << 20) == 0 => format!("{} MiB", b >> 20),
        b if b >= 1 << 10 && b % (1 << 10) == 0 => format!("{} KiB", b >> 10),
        b => format!("{b} B"),
    }
}

/// A reader of CSV text that fails (an [`std::io::ErrorKind::InvalidData`] error naming the cap)
/// on more than `cap` bytes in all, a line longer than `line_cap` bytes, or a NUL byte (binary
/// data), where it meets them: the CSV parser above it never buffers more than one capped line.
#[derive(Debug)]
pub struct TextGuard<R> {
    inner: R,
    total: u64,
    cap: u64,
    line: u64,
    line_cap: u64,
}

impl<R: Read> TextGuard<R> {
    /// Guards `inner` with the log caps ([`MAX_LOG_BYTES`], [`MAX_CSV_LINE_BYTES`]).
    pub fn new(inner: R) -> Self {
        Self::with_caps(inner, MAX_LOG_BYTES, MAX_CSV_LINE_BYTES)
    }

    /// Guards `inner` with the caps `cap` (bytes in all) and `line_cap` (bytes a line).
    pub fn with_caps(inner: R, cap: u64, line_cap: u64) -> Self {
        Self {
            inner,
            total: 0,
            cap,
            line: 0,
            line_cap,
        }
    }
}

impl<R: Read> Read for TextGuard<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let bad = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidData, m);
        // Never hand out more than one byte past the cap, so the cap is found on this read.
        let room = (self.cap + 1 - self.total.min(self.cap + 1)).min(buf.len() as u64) as usize;
        if room == 0 && !buf.is_empty() {
            return Err(bad(format!(
                "the file is above the cap of {} bytes ({})",
                self.cap,
                human(self.cap)
            )));
        }
        let n = self.inner.read(&mut buf[..room])?;
        for &b in &buf[..n] {
            match b {
                b'\n' => self.line = 0,
                0 => {
                    return Err(bad(
                        "the file holds a NUL byte: it is binary data, not a CSV text log".into(),
                    ))
                }
                _ => {
                    self.line += 1;
                    if self.line > self.line_cap {
                        return Err(bad(format!(
                            "a line is longer than the cap of {} bytes ({}): not a CSV log",
                            self.line_cap,
                            human(self.line_cap)
                        )));
                    }
                }
            }
        }
        self.total += n as u64;
        if self.total > self.cap {
            return Err(bad(format!(
                "the file is above the cap of {} bytes ({})",
                self.cap,
                human(self.cap)
            )));
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_declared_size_above_the_cap_is_refused_before_reading() {
        // A reader that fails if read: the size alone refuses it.
        struct Untouchable;
        impl Read for Untouchable {
            fn read(&mut self, _: &mut [u8]) -> std::io::Result<usize> {
                panic!("read although the declared size is above the cap")
            }
        }
        let e =
            read_capped(Untouchable, "big.mcap", "MCAP file", Some(2048), 1024, None).unwrap_err();
        assert!(
            e.contains("is 2048 bytes, above the cap of 1024 bytes (1 KiB)"),
            "{e}"
        );
    }

    #[test]
    fn an_endless_reader_stops_at_the_cap() {
        let e = read_capped(std::io::repeat(7), "pipe", "MCAP file", None, 4096, None).unwrap_err();
        assert!(e.contains("above the cap of 4096 bytes"), "{e}");
    }

    #[test]
    fn dev_zero_as_mcap_is_refused_on_its_first_8_bytes() {
        let t = std::time::Instant::now();
        let e =
            read_log_file(Path::new("/dev/zero"), "MCAP file", Some(b"\x89MCAP0\r\n")).unwrap_err();
        assert!(e.contains("not an MCAP file"), "{e}");
        assert!(t.elapsed().as_secs_f64() < 0.5, "{:?}", t.elapsed());
    }

    #[test]
    fn text_guard_refuses_nul_long_lines_and_too_much() {
        let read = |g: &mut dyn Read| {
            let mut s = Vec::new();
            g.read_to_end(&mut s).map(|_| s)
        };
        let e = read(&mut TextGuard::with_caps(&b"a,b\n1,\0"[..], 100, 10)).unwrap_err();
        assert!(e.to_string().contains("NUL byte"), "{e}");
        let e = read(&mut TextGuard::with_caps(
            &b"a,b\n0123456789x\n"[..],
            100,
            10,
        ))
        .unwrap_err();
        assert!(
            e.to_string().contains("longer than the cap of 10 bytes"),
            "{e}"
        );
        let e = read(&mut TextGuard::with_caps(std::io::repeat(b'\n'), 100, 10)).unwrap_err();
        assert!(e.to_string().contains("above the cap of 100 bytes"), "{e}");
        let ok = read(&mut TextGuard::with_caps(
            &b"a,b\n0123456789\n"[..],
            100,
            10,
        ))
        .unwrap();
        assert_eq!(ok.len(), 15);
    }
}
