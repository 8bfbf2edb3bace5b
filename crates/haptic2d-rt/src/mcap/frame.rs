//! A bounded reader of MCAP records (issue 38): every length field of a record is checked against
//! the bytes that really follow it before anything is sliced or allocated, so a malformed file is
//! a clear error naming the byte offset, never a panic or a giant allocation. (The `mcap` crate's
//! readers trust record lengths and string lengths: a record length of 2⁶⁴ − 1 panicked inside it,
//! a string length of 2³² − 1 reserved 4 GiB.) The `mcap` crate still writes the logs.
//!
//! It reads what haptic2d's logs hold: the header, schemas, channels, messages and metadata, in
//! uncompressed chunks or not, up to the footer; every other record (indexes, statistics,
//! attachments, records of unknown opcodes ≥ 0x10) is skipped by its length without being parsed.
//! Record layouts: the MCAP specification, <https://mcap.dev/spec>.

use std::collections::BTreeMap;

/// The 8 magic bytes an MCAP file starts (and ends) with.
pub const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// Record opcodes of the MCAP specification.
pub mod op {
    /// Header.
    pub const HEADER: u8 = 0x01;
    /// Footer.
    pub const FOOTER: u8 = 0x02;
    /// Schema.
    pub const SCHEMA: u8 = 0x03;
    /// Channel.
    pub const CHANNEL: u8 = 0x04;
    /// Message.
    pub const MESSAGE: u8 = 0x05;
    /// Chunk.
    pub const CHUNK: u8 = 0x06;
    /// Metadata.
    pub const METADATA: u8 = 0x0C;
    /// Data end (the last record of the data section).
    pub const DATA_END: u8 = 0x0F;
}

/// A record haptic2d reads; its byte slices and strings borrow from the file.
#[derive(Debug, Clone, PartialEq)]
pub enum Rec<'a> {
    /// A Schema record.
    Schema {
        /// Schema id.
        id: u16,
        /// Schema name.
        name: &'a str,
        /// Schema encoding (`jsonschema`).
        encoding: &'a str,
        /// The schema's text.
        data: &'a [u8],
    },
    /// A Channel record (its metadata map is not read).
    Channel {
        /// Channel id.
        id: u16,
        /// Schema id (0: none).
        schema_id: u16,
        /// Topic.
        topic: &'a str,
        /// Message encoding (`json`).
        message_encoding: &'a str,
    },
    /// A Message record.
    Message {
        /// Channel id.
        channel_id: u16,
        /// Sequence number.
        sequence: u32,
        /// Log time (ns).
        log_time: u64,
        /// Payload.
        data: &'a [u8],
    },
    /// A Metadata record.
    Metadata {
        /// Record name.
        name: &'a str,
        /// Key → value.
        map: BTreeMap<String, String>,
    },
    /// The Footer: the file is complete.
    Footer,
}

/// How a read of the records ended without an error.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum End {
    /// At the footer: the file is complete.
    Footer,
    /// At the end of the file on a record boundary, before any footer (a log whose writer
    /// stopped between records).
    Unfinished,
    /// The file ends inside a record (a log cut while it was written); the text says where.
    Cut(String),
}

/// A cursor over one record body: every read checks the bytes left first.
struct Body<'a> {
    b: &'a [u8],
    what: &'static str,
}

impl<'a> Body<'a> {
    fn take(&mut self, n: u64, field: &str) -> Result<&'a [u8], String> {
        if n > self.b.len() as u64 {
            return Err(format!(
                "the {} record's {field} needs {n} bytes, {} are left in the record",
                self.what,
                self.b.len()
            ));
        }
        let (head, rest) = self.b.split_at(n as usize);
        self.b = rest;
        Ok(head)
    }

    fn array<const N: usize>(&mut self, field: &str) -> Result<[u8; N], String> {
        let s = self.take(N as u64, field)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    fn u16(&mut self, field: &str) -> Result<u16, String> {
        self.array(field).map(u16::from_le_bytes)
    }

    fn u32(&mut self, field: &str) -> Result<u32, String> {
        self.array(field).map(u32::from_le_bytes)
    }

    fn u64(&mut self, field: &str) -> Result<u64, String> {
        self.array(field).map(u64::from_le_bytes)
    }

    /// A `uint32` length-prefixed byte array.
    fn bytes32(&mut self, field: &str) -> Result<&'a [u8], String> {
        let n = self.u32(field)?;
        self.take(u64::from(n), field)
    }

    /// A `uint32` length-prefixed UTF-8 string.
    fn str(&mut self, field: &str) -> Result<&'a str, String> {
        let b = self.bytes32(field)?;
        std::str::from_utf8(b)
            .map_err(|e| format!("the {} record's {field} is not UTF-8: {e}", self.what))
    }

    /// A `Map<string, string>`: a `uint32` byte length, then key and value strings.
    fn string_map(&mut self, field: &str) -> Result<BTreeMap<String, String>, String> {
        let mut inner = Body {
            b: self.bytes32(field)?,
            what: self.what,
        };
        let mut map = BTreeMap::new();
        while !inner.b.is_empty() {
            let k = inner.str(field)?;
            let v = inner.str(field)?;
            if map.insert(k.to_string(), v.to_string()).is_some() {
                return Err(format!(
                    "the {} record's {field} has the key `{k}` twice",
                    self.what
                ));
            }
        }
        Ok(map)
    }
}

fn name_of(op: u8) -> &'static str {
    match op {
        op::HEADER => "Header",
        op::FOOTER => "Footer",
        op::SCHEMA => "Schema",
        op::CHANNEL => "Channel",
        op::MESSAGE => "Message",
        op::CHUNK => "Chunk",
        0x07 => "Message Index",
        0x08 => "Chunk Index",
        0x09 => "Attachment",
        0x0A => "Attachment Index",
        0x0B => "Statistics",
        op::METADATA => "Metadata",
        0x0D => "Metadata Index",
        0x0E => "Summary Offset",
        op::DATA_END => "Data End",
        _ => "unknown",
    }
}

/// Parses the body of a record of opcode `op` that haptic2d reads (`None`: skipped).
fn parse(op: u8, body: &[u8]) -> Result<Option<Rec<'_>>, String> {
    let mut c = Body {
        b: body,
        what: name_of(op),
    };
    Ok(Some(match op {
        op::SCHEMA => Rec::Schema {
            id: c.u16("id")?,
            name: c.str("name")?,
            encoding: c.str("encoding")?,
            data: c.bytes32("data")?,
        },
        op::CHANNEL => Rec::Channel {
            id: c.u16("id")?,
            schema_id: c.u16("schema_id")?,
            topic: c.str("topic")?,
            message_encoding: c.str("message_encoding")?,
        },
        op::MESSAGE => {
            let channel_id = c.u16("channel_id")?;
            let sequence = c.u32("sequence")?;
            let log_time = c.u64("log_time")?;
            let _publish_time = c.u64("publish_time")?;
            Rec::Message {
                channel_id,
                sequence,
                log_time,
                data: c.b,
            }
        }
        op::METADATA => Rec::Metadata {
            name: c.str("name")?,
            map: c.string_map("metadata")?,
        },
        op::FOOTER => Rec::Footer,
        _ => return Ok(None),
    }))
}

/// The records of one chunk's uncompressed `records` (at byte `base` of the file): Schema, Channel
/// and Message only, every one whole — except in a chunk the file's end `cut` short, whose last
/// record may be partial (the records before it are delivered).
fn chunk_records<'a>(
    records: &'a [u8],
    base: u64,
    cut: bool,
    on: &mut dyn FnMut(u64, Rec<'a>) -> Result<(), String>,
) -> Result<(), String> {
    let mut pos = 0usize;
    while pos < records.len() {
        let at = base + pos as u64;
        let left = records.len() - pos;
        if left < 9 {
            if cut {
                return Ok(());
            }
            return Err(format!(
                "byte {at}: the chunk ends inside a record header ({left} bytes left)"
            ));
        }
        let opc = records[pos];
        let len = u64::from_le_bytes(records[pos + 1..pos + 9].try_into().expect("8 bytes"));
        let rest = (left - 9) as u64;
        if len > rest {
            if cut && len <= super::limits::MAX_LOG_BYTES {
                return Ok(());
            }
            return Err(format!(
                "byte {at}: a {} record (opcode 0x{opc:02x}) inside a chunk declares {len} bytes, only {rest} are left in the chunk",
                name_of(opc)
            ));
        }
        if !matches!(opc, op::SCHEMA | op::CHANNEL | op::MESSAGE) {
            return Err(format!(
                "byte {at}: a {} record (opcode 0x{opc:02x}) inside a chunk (a chunk holds schemas, channels and messages only)",
                name_of(opc)
            ));
        }
        let body = &records[pos + 9..pos + 9 + len as usize];
        if let Some(r) = parse(opc, body).map_err(|e| format!("byte {at}: {e}"))? {
            on(at, r)?;
        }
        pos += 9 + len as usize;
    }
    Ok(())
}

/// A Chunk record's body at byte `at`: its header checked, its records delivered. `cut`: the file
/// ends inside this chunk (`body` is what there is of it).
fn chunk<'a>(
    body: &'a [u8],
    at: u64,
    cut: bool,
    on: &mut dyn FnMut(u64, Rec<'a>) -> Result<(), String>,
) -> Result<(), String> {
    let mut c = Body {
        b: body,
        what: "Chunk",
    };
    let head = |c: &mut Body<'a>| -> Result<(u64, &'a str, u64), String> {
        let _start = c.u64("message_start_time")?;
        let _end = c.u64("message_end_time")?;
        let size = c.u64("uncompressed_size")?;
        let _crc = c.u32("uncompressed_crc")?;
        let compression = c.str("compression")?;
        let records = c.u64("records length")?;
        Ok((size, compression, records))
    };
    let (size, compression, records_len) = match head(&mut c) {
        Ok(h) => h,
        // The file ends inside the chunk's header: nothing of it to read.
        Err(_) if cut => return Ok(()),
        Err(e) => return Err(format!("byte {at}: {e}")),
    };
    if !compression.is_empty() {
        return Err(format!(
            "byte {at}: a chunk compressed with `{compression}`: this reader reads uncompressed logs (haptic2d writes no compression)\n    fix: decompress it first, e.g. `mcap compress --compression none IN -o OUT` (the mcap CLI)"
        ));
    }
    if records_len != size {
        return Err(format!(
            "byte {at}: an uncompressed chunk whose records length ({records_len}) differs from its uncompressed size ({size})"
        ));
    }
    let header_len = (body.len() - c.b.len()) as u64;
    let records = if cut {
        &c.b[..c
            .b
            .len()
            .min(usize::try_from(records_len).unwrap_or(usize::MAX))]
    } else {
        c.take(records_len, "records")
            .map_err(|e| format!("byte {at}: {e}"))?
    };
    chunk_records(records, at + 9 + header_len, cut, on)
}

/// Calls `on(byte offset, record)` for every record haptic2d reads, in file order (chunks
/// unpacked), up to the footer. A file that ends inside a record whose declared length is at most
/// the log cap is a log cut while it was written: [`End::Cut`], the records before it delivered.
/// Anything else malformed is an error naming the byte offset (`Err`), and so is a compressed
/// chunk (haptic2d writes none; this reader has no decompressor).
pub fn walk<'a>(
    bytes: &'a [u8],
    on: &mut dyn FnMut(u64, Rec<'a>) -> Result<(), String>,
) -> Result<End, String> {
    if !bytes.starts_with(MAGIC) {
        return Err("it does not start with the MCAP magic bytes".into());
    }
    let mut pos = MAGIC.len();
    loop {
        let at = pos as u64;
        let left = bytes.len() - pos;
        if left == 0 {
            return Ok(End::Unfinished);
        }
        if left < 9 {
            return Ok(End::Cut(format!(
                "the file ends inside a record header at byte {at} ({left} bytes left)"
            )));
        }
        let opc = bytes[pos];
        let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().expect("8 bytes"));
        let rest = (left - 9) as u64;
        if opc == 0 {
            return Err(format!("byte {at}: opcode 0x00 is not an MCAP record"));
        }
        if len > rest {
            if len <= super::limits::MAX_LOG_BYTES && opc <= op::DATA_END {
                // A chunk cut short still gives the whole records before the cut.
                if opc == op::CHUNK {
                    chunk(&bytes[pos + 9..], at, true, on)?;
                }
                return Ok(End::Cut(format!(
                    "the file ends inside a {} record at byte {at} (it declares {len} bytes, {rest} follow)",
                    name_of(opc)
                )));
            }
            return Err(format!(
                "byte {at}: a {} record (opcode 0x{opc:02x}) declares a length of {len} bytes, but only {rest} bytes follow",
                name_of(opc)
            ));
        }
        let body = &bytes[pos + 9..pos + 9 + len as usize];
        if opc == op::CHUNK {
            chunk(body, at, false, on)?;
        } else if let Some(r) = parse(opc, body).map_err(|e| format!("byte {at}: {e}"))? {
            let footer = r == Rec::Footer;
            on(at, r)?;
            if footer {
                return Ok(End::Footer);
            }
        }
        pos += 9 + len as usize;
    }
}
