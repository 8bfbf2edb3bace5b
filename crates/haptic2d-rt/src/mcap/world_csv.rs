//! The world channels of an MCAP log (`/haptic2d/bodies`, `/haptic2d/contacts`,
//! `/haptic2d/energy`) as CSV tables, for `haptic2d log convert FILE.mcap OUT.csv`, which writes
//! each next to the tick CSV (`OUT.bodies.csv`, `OUT.contacts.csv`, `OUT.energy.csv`).
//!
//! Long format: one row per body (per contact) per message, headed by the message's `t` (s) and
//! `count` (bodies or contacts in the world that tick; the arrays keep at most 32) and the entry's
//! position `i` in the message's array. A tick without contacts has no contact rows. Cells are the
//! messages' values: floats in Rust's shortest round-trip form (`NaN`, `inf`, `-inf` as Rust
//! prints them, the same text the CSV tick logger writes), names and states as written. The
//! column lists are fixed (docs/LOGS.md), so a message missing a field is an error naming it.

use crate::mcap::columns::json_f64;
use crate::mcap::reader::{scan, LogInfo};
use crate::mcap::schemas::{TOPIC_BODIES, TOPIC_CONTACTS, TOPIC_ENERGY};
use serde_json::Value;

/// How a column's cell is read from the message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// A float (number or `"NaN"`/`"inf"`/`"-inf"`).
    F,
    /// A non-negative integer.
    U,
    /// A string (body name, contact state).
    S,
}

/// One world channel's table layout: the per-message columns, then the per-entry columns (none for
/// a flat message such as the energy ledger).
#[derive(Clone, Copy, Debug)]
pub struct WorldChannel {
    /// MCAP topic.
    pub topic: &'static str,
    /// File-name suffix of its CSV next to the tick CSV (`OUT` + suffix, `OUT` without `.csv`).
    pub suffix: &'static str,
    /// The array of entries in the message (`bodies`, `contacts`), if any.
    array: Option<&'static str>,
    /// Per-message columns.
    head: &'static [(&'static str, Kind)],
    /// Per-entry columns (after `i`).
    entry: &'static [(&'static str, Kind)],
}

/// The three world channels, in the order `log convert` writes them.
pub const WORLD_CHANNELS: [WorldChannel; 3] = [
    WorldChannel {
        topic: TOPIC_BODIES,
        suffix: ".bodies.csv",
        array: Some("bodies"),
        head: &[("t", Kind::F), ("count", Kind::U)],
        entry: &[
            ("name", Kind::S),
            ("x", Kind::F),
            ("y", Kind::F),
            ("theta", Kind::F),
            ("vx", Kind::F),
            ("vy", Kind::F),
            ("omega", Kind::F),
        ],
    },
    WorldChannel {
        topic: TOPIC_CONTACTS,
        suffix: ".contacts.csv",
        array: Some("contacts"),
        head: &[("t", Kind::F), ("count", Kind::U)],
        entry: &[
            ("body_a", Kind::S),
            ("body_b", Kind::S),
            ("state", Kind::S),
            ("x", Kind::F),
            ("y", Kind::F),
            ("nx", Kind::F),
            ("ny", Kind::F),
            ("penetration", Kind::F),
            ("f_n", Kind::F),
            ("f_t", Kind::F),
            ("slip", Kind::F),
        ],
    },
    WorldChannel {
        topic: TOPIC_ENERGY,
        suffix: ".energy.csv",
        array: None,
        head: &[
            ("t", Kind::F),
            ("kinetic", Kind::F),
            ("stored", Kind::F),
            ("applied_work", Kind::F),
            ("initial", Kind::F),
            ("impact_loss", Kind::F),
            ("excess", Kind::F),
        ],
        entry: &[],
    },
];

impl WorldChannel {
    /// The CSV header: the per-message columns, then `i` and the per-entry columns.
    pub fn header(&self) -> Vec<&'static str> {
        let mut h: Vec<&'static str> = self.head.iter().map(|c| c.0).collect();
        if self.array.is_some() {
            h.push("i");
            h.extend(self.entry.iter().map(|c| c.0));
        }
        h
    }
}

/// A world channel's rows (cells as text).
#[derive(Clone, Debug, PartialEq)]
pub struct WorldTable {
    /// The channel.
    pub channel: WorldChannel,
    /// Messages read on the channel.
    pub messages: u64,
    /// Rows, each `channel.header().len()` cells.
    pub rows: Vec<Vec<String>>,
}

impl PartialEq for WorldChannel {
    fn eq(&self, other: &Self) -> bool {
        self.topic == other.topic
    }
}

/// The text of `v` read as `kind` (`None` if it is not of that kind).
fn cell(v: &Value, kind: Kind) -> Option<String> {
    match kind {
        Kind::F => json_f64(v).map(|x| x.to_string()),
        Kind::U => v.as_u64().map(|x| x.to_string()),
        Kind::S => v.as_str().map(str::to_string),
    }
}

fn field(obj: &Value, name: &str, kind: Kind, what: &dyn Fn() -> String) -> Result<String, String> {
    let v = obj
        .get(name)
        .ok_or_else(|| format!("{}: no field `{name}`", what()))?;
    cell(v, kind).ok_or_else(|| {
        format!(
            "{}: field `{name}` = {v} is not {}",
            what(),
            match kind {
                Kind::F => "a float",
                Kind::U => "a non-negative integer",
                Kind::S => "a string",
            }
        )
    })
}

/// Appends the rows of one message of `ch` to `rows`.
fn message_rows(
    ch: &WorldChannel,
    msg: &Value,
    what: &dyn Fn() -> String,
    rows: &mut Vec<Vec<String>>,
) -> Result<(), String> {
    let mut head = Vec::with_capacity(ch.head.len());
    for &(name, kind) in ch.head {
        head.push(field(msg, name, kind, what)?);
    }
    let Some(array) = ch.array else {
        rows.push(head);
        return Ok(());
    };
    let entries = msg
        .get(array)
        .and_then(Value::as_array)
        .ok_or_else(|| format!("{}: no array `{array}`", what()))?;
    for (i, e) in entries.iter().enumerate() {
        let mut row = Vec::with_capacity(head.len() + 1 + ch.entry.len());
        row.extend(head.iter().cloned());
        row.push(i.to_string());
        let what_e = || format!("{} {array}[{i}]", what());
        for &(name, kind) in ch.entry {
            row.push(field(e, name, kind, &what_e)?);
        }
        rows.push(row);
    }
    Ok(())
}

/// The world channels of the MCAP file `bytes` as tables (every channel of [`WORLD_CHANNELS`], in
/// that order, empty if the log has none of its messages), and the file's description. `label`
/// names the file in errors, which also name the message and the field.
pub fn read_world_tables(bytes: &[u8], label: &str) -> Result<(Vec<WorldTable>, LogInfo), String> {
    let mut tables: Vec<WorldTable> = WORLD_CHANNELS
        .iter()
        .map(|&channel| WorldTable {
            channel,
            messages: 0,
            rows: Vec::new(),
        })
        .collect();
    let info = scan(bytes, label, |topic, t, data| {
        let Some(tab) = tables.iter_mut().find(|x| x.channel.topic == topic) else {
            return Ok(());
        };
        let n = tab.messages;
        let what = || format!("{label}: {topic} message {n} (log_time {t} ns)");
        let v: Value =
            serde_json::from_slice(data).map_err(|e| format!("{}: not JSON: {e}", what()))?;
        message_rows(&tab.channel, &v, &what, &mut tab.rows)?;
        tab.messages += 1;
        Ok(())
    })?;
    Ok((tables, info))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bodies_message_becomes_one_row_per_body_with_exact_floats() {
        let msg: Value = serde_json::from_str(
            r#"{"t":0.002,"count":2,"bodies":[{"name":"box","x":0.1,"y":-2.5e-7,"theta":"NaN","vx":1.0,"vy":0.0,"omega":"-inf"},{"name":"wall","x":0.0,"y":0.0,"theta":0.0,"vx":0.0,"vy":0.0,"omega":0.0}]}"#,
        )
        .unwrap();
        let mut rows = Vec::new();
        message_rows(&WORLD_CHANNELS[0], &msg, &|| "m".into(), &mut rows).unwrap();
        assert_eq!(
            WORLD_CHANNELS[0].header(),
            ["t", "count", "i", "name", "x", "y", "theta", "vx", "vy", "omega"]
        );
        assert_eq!(
            rows[0],
            [
                "0.002",
                "2",
                "0",
                "box",
                "0.1",
                "-0.00000025",
                "NaN",
                "1",
                "0",
                "-inf"
            ]
        );
        assert_eq!(rows[1][2..4], ["1", "wall"]);
        assert_eq!(rows.len(), 2);
    }

    #[test]
    fn a_message_missing_a_field_names_it() {
        let msg: Value = serde_json::from_str(r#"{"t":0.0,"kinetic":1.0}"#).unwrap();
        let e = message_rows(
            &WORLD_CHANNELS[2],
            &msg,
            &|| "energy 3".into(),
            &mut Vec::new(),
        )
        .unwrap_err();
        assert!(e.contains("energy 3") && e.contains("`stored`"), "{e}");
    }
}
