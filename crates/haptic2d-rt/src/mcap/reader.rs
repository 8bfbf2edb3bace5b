//! Reading haptic2d MCAP logs back: what a file holds ([`LogInfo`], for `haptic2d log info`), its
//! tick rows ([`read_ticks`], for `log convert` and the tests) and its encoder angles
//! ([`read_encoders`], for `--device replay:FILE.mcap`). One linear pass over the records (chunks
//! unpacked), so a file whose summary is missing still reads up to its last complete record.

use crate::mcap::columns::{row_from_json, TickRow, LOOP_COLUMN_COUNT};
use crate::mcap::schemas::TOPIC_TICK;
use ::mcap::records::Record;
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

/// Reads the whole file `path` (errors name it).
pub fn read_file(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("cannot read the MCAP file {}: {e}", path.display()))
}

/// Calls `on_message(topic, log_time, data)` for every message, and returns the file's
/// description. `label` names the file in errors. A file that is not MCAP at all is an error; a
/// truncated one is read up to the damage ([`LogInfo::complete`] false).
pub fn scan(
    bytes: &[u8],
    label: &str,
    mut on_message: impl FnMut(&str, u64, &[u8]) -> Result<(), String>,
) -> Result<LogInfo, String> {
    if !bytes.starts_with(::mcap::MAGIC) {
        return Err(format!(
            "{label} is not an MCAP file (it does not start with the MCAP magic bytes)\n    fix: give a file written by `haptic2d run --log FILE.mcap` or another MCAP writer"
        ));
    }
    let reader = ::mcap::read::ChunkFlattener::new_with_options(
        bytes,
        ::mcap::read::Options::IgnoreEndMagic.into(),
    )
    .map_err(|e| format!("{label}: {e}"))?;
    let mut info = LogInfo::default();
    let mut schemas: HashMap<u16, (String, String, Vec<u8>)> = HashMap::new();
    let mut channel_index: HashMap<u16, usize> = HashMap::new();
    for rec in reader {
        let rec = match rec {
            Ok(r) => r,
            Err(e) => {
                info.damage = Some(e.to_string());
                break;
            }
        };
        match rec {
            Record::Schema { header, data } => {
                schemas.insert(header.id, (header.name, header.encoding, data.into_owned()));
            }
            Record::Channel(c) => {
                let (schema, schema_encoding, schema_data) =
                    schemas.get(&c.schema_id).cloned().unwrap_or_default();
                channel_index.entry(c.id).or_insert_with(|| {
                    info.channels.push(ChannelInfo {
                        topic: c.topic,
                        schema,
                        schema_encoding,
                        message_encoding: c.message_encoding,
                        schema_data,
                        count: 0,
                    });
                    info.channels.len() - 1
                });
            }
            Record::Message { header, data } => {
                let Some(&k) = channel_index.get(&header.channel_id) else {
                    return Err(format!(
                        "{label}: a message on channel {} comes before that channel's record",
                        header.channel_id
                    ));
                };
                info.channels[k].count += 1;
                info.messages += 1;
                let t = header.log_time;
                info.time_range_ns = Some(match info.time_range_ns {
                    None => (t, t),
                    Some((a, b)) => (a.min(t), b.max(t)),
                });
                on_message(&info.channels[k].topic, t, &data)?;
            }
            Record::Metadata(m) => info.metadata.push((m.name, m.metadata)),
            Record::Footer(_) => info.complete = true,
            _ => {}
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
    let label = path.display().to_string();
    let (rows, _) = read_ticks(&bytes, &label)?;
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
