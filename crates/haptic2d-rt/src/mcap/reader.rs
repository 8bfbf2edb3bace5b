//! Reading haptic2d MCAP logs back: what a file holds ([`LogInfo`], for `haptic2d log info`), its
//! tick rows ([`read_ticks`], for `log convert` and the tests) and its encoder angles
//! ([`read_encoders`], for `--device replay:FILE.mcap`). One linear pass over the records (chunks
//! unpacked, [`frame::walk`]: every length checked before it is used), so a file whose summary is
//! missing still reads up to its last complete record, and a malformed one is an error.

use crate::mcap::columns::{row_from_json, TickRow, LOOP_COLUMN_COUNT};
use crate::mcap::frame::{self, End, Rec, MAGIC};
use crate::mcap::limits::read_log_file;
use crate::mcap::schemas::TOPIC_TICK;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// One channel of a log.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelInfo {
    /// Topic.
    pub topic: String,
    /// Schema name (empty without a schema).
    pub schema: String,
    /// Schema encoding (`jsonschema`).
    pub schema_encoding: String,
    /// Message encoding (`json`).
    pub message_encoding: String,
    /// The schema's text.
    pub schema_data: Vec<u8>,
    /// Messages on the channel.
    pub count: u64,
}

/// What a log holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LogInfo {
    /// Channels in id order.
    pub channels: Vec<ChannelInfo>,
    /// Messages in the file.
    pub messages: u64,
    /// Earliest and latest `log_time` (ns), if there are messages.
    pub time_range_ns: Option<(u64, u64)>,
    /// Metadata records (name, key → value), in file order.
    pub metadata: Vec<(String, BTreeMap<String, String>)>,
    /// False when the file ends before its footer (a log that was not finished); the records
    /// before the damage are still counted.
    pub complete: bool,
    /// The error that ended the read early, if any.
    pub damage: Option<String>,
}

impl LogInfo {
    /// Messages on `topic`.
    pub fn count(&self, topic: &str) -> u64 {
        self.channels
            .iter()
            .filter(|c| c.topic == topic)
            .map(|c| c.count)
            .sum()
    }

    /// The metadata record `name`, if present (the last one of that name).
    pub fn metadata(&self, name: &str) -> Option<&BTreeMap<String, String>> {
        self.metadata
            .iter()
            .rev()
            .find(|(n, _)| n == name)
            .map(|(_, m)| m)
    }
}

/// Reads the whole MCAP file `path` (errors name it): at most
/// [`MAX_LOG_BYTES`](crate::mcap::limits::MAX_LOG_BYTES) (1 GiB; a larger file is refused before it
/// is read), and only if it starts with the MCAP magic bytes (checked on the first 8 bytes, so
/// `/dev/zero` or a CSV given as an MCAP log is refused at once).
pub fn read_file(path: &Path) -> Result<Vec<u8>, String> {
    read_log_file(path, "MCAP file", Some(MAGIC))
}

/// Calls `on_message(topic, log_time, data)` for every message, and returns the file's
/// description. `label` names the file in errors. Every record length and every length inside a
/// record is checked against the bytes that follow before anything is read or allocated
/// ([`frame::walk`]). A file that is not MCAP, or whose records are malformed (a length past the
/// end of the file above the log cap, a string past its record, an unknown record inside a chunk, a
/// compressed chunk), is an error naming the byte offset and the messages read before it; a log
/// cut while it was written (it ends inside a record, or before its footer) is read up to the cut
/// ([`LogInfo::complete`] false, [`LogInfo::damage`] says where).
pub fn scan(
    bytes: &[u8],
    label: &str,
    mut on_message: impl FnMut(&str, u64, &[u8]) -> Result<(), String>,
) -> Result<LogInfo, String> {
    if !bytes.starts_with(MAGIC) {
        return Err(format!(
            "{label} is not an MCAP file (it does not start with the MCAP magic bytes)\n    fix: give a file written by `haptic2d run --log FILE.mcap` or another MCAP writer"
        ));
    }
    let mut info = LogInfo::default();
    let mut schemas: HashMap<u16, (String, String, Vec<u8>)> = HashMap::new();
    let mut channel_index: HashMap<u16, usize> = HashMap::new();
    // Errors of the callback are the caller's (e.g. a tick that is not JSON): passed on as they are.
    let mut own_error: Option<String> = None;
    let end = frame::walk(bytes, &mut |_at, rec| {
        match rec {
            Rec::Schema {
                id,
                name,
                encoding,
                data,
            } => {
                schemas
                    .entry(id)
                    .or_insert_with(|| (name.to_string(), encoding.to_string(), data.to_vec()));
            }
            Rec::Channel {
                id,
                schema_id,
                topic,
                message_encoding,
            } => {
                if let std::collections::hash_map::Entry::Vacant(slot) = channel_index.entry(id) {
                    let (schema, schema_encoding, schema_data) =
                        schemas.get(&schema_id).cloned().unwrap_or_default();
                    info.channels.push(ChannelInfo {
                        topic: topic.to_string(),
                        schema,
                        schema_encoding,
                        message_encoding: message_encoding.to_string(),
                        schema_data,
                        count: 0,
                    });
                    slot.insert(info.channels.len() - 1);
                }
            }
            Rec::Message {
                channel_id,
                log_time: t,
                data,
                ..
            } => {
                let Some(&k) = channel_index.get(&channel_id) else {
                    return Err(format!(
                        "a message on channel {channel_id} comes before that channel's record"
                    ));
                };
                info.channels[k].count += 1;
                info.messages += 1;
                info.time_range_ns = Some(match info.time_range_ns {
                    None => (t, t),
                    Some((a, b)) => (a.min(t), b.max(t)),
                });
                if let Err(e) = on_message(&info.channels[k].topic, t, data) {
                    own_error = Some(e.clone());
                    return Err(e);
                }
            }
            Rec::Metadata { name, map } => info.metadata.push((name.to_string(), map)),
            Rec::Footer => info.complete = true,
        }
        Ok(())
    });
    match end {
        Ok(End::Footer | End::Unfinished) => {}
        Ok(End::Cut(where_)) => info.damage = Some(where_),
        Err(e) if own_error.as_ref() == Some(&e) => return Err(e),
        Err(e) => {
            return Err(format!(
                "{label} is a damaged MCAP file: {e} ({} messages read before it)\n    fix: give a log written by `haptic2d run --log FILE.mcap` or `haptic2d simulate --out FILE.mcap`; an MCAP from elsewhere must be uncompressed",
                info.messages
            ))
        }
    }
    Ok(info)
}

/// Reads the file's description (counts, time range, metadata).
pub fn read_info(bytes: &[u8], label: &str) -> Result<LogInfo, String> {
    scan(bytes, label, |_, _, _| Ok(()))
}

/// The `/haptic2d/tick` rows of a log, in file order (errors name the message).
pub fn read_ticks(bytes: &[u8], label: &str) -> Result<(Vec<TickRow>, LogInfo), String> {
    let mut rows = Vec::new();
    let info = scan(bytes, label, |topic, t, data| {
        if topic != TOPIC_TICK {
            return Ok(());
        }
        let v: serde_json::Value = serde_json::from_slice(data).map_err(|e| {
            format!(
                "{label}: tick message {} (log_time {t} ns) is not JSON: {e}",
                rows.len()
            )
        })?;
        let row =
            row_from_json(&v).map_err(|e| format!("{label}: tick message {}: {e}", rows.len()))?;
        rows.push(row);
        Ok(())
    })?;
    Ok((rows, info))
}

/// The encoder angles `[q11, q12, q21, q22]` (rad) of every tick of the log at `path`, for a
/// replay. Errors name the file and say what is missing.
pub fn read_encoders(path: &Path) -> Result<Vec<[f64; 4]>, String> {
    let bytes = read_file(path)?;
    encoders_of(&bytes, &path.display().to_string())
}

/// [`read_encoders`] of a log already in memory (`label` names it in errors).
pub fn encoders_of(bytes: &[u8], label: &str) -> Result<Vec<[f64; 4]>, String> {
    let (rows, _) = read_ticks(bytes, label)?;
    if rows.is_empty() {
        return Err(format!(
            "{label} has no {TOPIC_TICK} messages: it needs a log of `haptic2d run --log FILE.mcap` to replay"
        ));
    }
    let mut out = Vec::with_capacity(rows.len());
    for (i, r) in rows.iter().enumerate() {
        let mut q = [0.0; 4];
        for (k, qk) in q.iter_mut().enumerate() {
            let v = r[LOOP_COLUMN_COUNT - 4 + k].map(|v| v.as_f64());
            *qk = v.filter(|v| v.is_finite()).ok_or_else(|| {
                format!(
                    "{label}: tick message {i} has no finite encoders.q{} (rad): the log was converted from a CSV without encoder angles, or the device was lost on that tick",
                    k + 1
                )
            })?;
        }
        out.push(q);
    }
    Ok(out)
}
