//! The one table of the tick channel's columns, with units: it generates the CSV header of a tick
//! log, the JSON Schema of the MCAP channel `/haptic2d/tick`, and the nested JSON of each message.
//!
//! A column name is a path of at most two parts: `t` is a top-level field, `device.x` is the field
//! `x` of the object `device`. Columns of one object are contiguous, so a message is written in one
//! pass over the table (`{"t":…,"device":{"x":…,"y":…},…}`) and a CSV column maps back to one path.

use haptic2d::haptic::{TickRecord, TICK_COLUMNS};
use std::io::Write;

/// How a column's values are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// An unsigned integer (exact up to `u64::MAX`; JSON integer).
    U64,
    /// A float (`f64`, written in Rust's shortest round-trip form; JSON has no NaN or infinity, so
    /// non-finite values are the strings `"NaN"`, `"inf"`, `"-inf"`).
    F64,
}

/// One column: dotted name, unit, meaning.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Column {
    /// Name, `field` or `object.field`.
    pub name: &'static str,
    /// Unit (SI), `1` for a count or a 0/1 flag.
    pub unit: &'static str,
    /// Value kind.
    pub kind: Kind,
    /// One-line meaning.
    pub doc: &'static str,
}

const fn u(name: &'static str, unit: &'static str, doc: &'static str) -> Column {
    Column {
        name,
        unit,
        kind: Kind::U64,
        doc,
    }
}
const fn f(name: &'static str, unit: &'static str, doc: &'static str) -> Column {
    Column {
        name,
        unit,
        kind: Kind::F64,
        doc,
    }
}

/// Number of loop columns ahead of the [`TickRecord`] columns in [`TICK_TABLE`].
pub const LOOP_COLUMN_COUNT: usize = 7;

/// Number of columns of [`TICK_TABLE`].
pub const TICK_TABLE_LEN: usize = LOOP_COLUMN_COUNT + TICK_COLUMNS.len();

/// The tick channel's columns: the loop's own (tick index, deadline, lateness, encoder angles),
/// then the [`TickRecord`] columns in [`TickRecord::values`] order (names = [`TICK_COLUMNS`]; a test
/// pins them). The CSV tick log has the `TickRecord` columns ([`csv_header`]).
pub const TICK_TABLE: [Column; TICK_TABLE_LEN] = [
    u("index", "1", "tick index among executed ticks (0, 1, 2, …)"),
    u(
        "deadline_ns",
        "ns",
        "the tick's deadline, CLOCK_MONOTONIC (the message's log_time is this plus the Unix offset of the haptic2d.clock metadata)",
    ),
    u(
        "lateness_ns",
        "ns",
        "how late the tick started, wake − deadline",
    ),
    f("encoders.q1", "rad", "joint angle q11 read this tick"),
    f("encoders.q2", "rad", "joint angle q12 read this tick"),
    f("encoders.q3", "rad", "joint angle q21 read this tick"),
    f("encoders.q4", "rad", "joint angle q22 read this tick"),
    f("t", "s", "simulated time k·T"),
    f("device.x", "m", "device (handle) pose x"),
    f("device.y", "m", "device (handle) pose y"),
    f("device.theta", "rad", "device (handle) pose θ"),
    f("device.vx", "m/s", "filtered device twist vx"),
    f("device.vy", "m/s", "filtered device twist vy"),
    f("device.omega", "rad/s", "filtered device twist ω"),
    f(
        "hand.fx",
        "N",
        "hand-wrench estimate fx (handle coordinates)",
    ),
    f(
        "hand.fy",
        "N",
        "hand-wrench estimate fy (handle coordinates)",
    ),
    f(
        "hand.tau",
        "N·m",
        "hand-wrench estimate τ (handle coordinates)",
    ),
    f("slave.x", "m", "slave pose x after impacts"),
    f("slave.y", "m", "slave pose y after impacts"),
    f("slave.theta", "rad", "slave pose θ after impacts"),
    f("slave.vx", "m/s", "post-impulse slave twist vx"),
    f("slave.vy", "m/s", "post-impulse slave twist vy"),
    f("slave.omega", "rad/s", "post-impulse slave twist ω"),
    f(
        "f_cm.x",
        "N",
        "device command after the passivity controller, x (world)",
    ),
    f(
        "f_cm.y",
        "N",
        "device command after the passivity controller, y (world)",
    ),
    f(
        "f_cm.tau",
        "N·m",
        "device command after the passivity controller, τ (world)",
    ),
    f("f_cs.x", "N", "slave drive x"),
    f("f_cs.y", "N", "slave drive y"),
    f("f_cs.tau", "N·m", "slave drive τ"),
    f("f_e.x", "N", "wrench of the slave on the environment, x"),
    f("f_e.y", "N", "wrench of the slave on the environment, y"),
    f(
        "f_e.tau",
        "N·m",
        "wrench of the slave on the environment, τ",
    ),
    f("tau1", "N·m", "motor torque 1 sent to the amplifiers"),
    f("tau2", "N·m", "motor torque 2 sent to the amplifiers"),
    f("tau3", "N·m", "motor torque 3 sent to the amplifiers"),
    f("tau4", "N·m", "motor torque 4 sent to the amplifiers"),
    f("contacts", "1", "number of contact records"),
    f("energy.kinetic", "J", "world kinetic energy after the step"),
    f(
        "energy.stored",
        "J",
        "energy stored in contact springs after the step",
    ),
    f(
        "work.applied",
        "J",
        "work done on the world by loads and drives so far",
    ),
    f(
        "po.energy",
        "J",
        "passivity-observer energy summed over the DOFs (0 when off)",
    ),
    f("po.alpha_x", "N·s/m", "passivity-controller damping, x"),
    f("po.alpha_y", "N·s/m", "passivity-controller damping, y"),
    f(
        "po.alpha_theta",
        "N·m·s/rad",
        "passivity-controller damping, θ",
    ),
    f("margin", "1", "singularity margin at the device pose"),
    f("closure_error", "m", "closure error |P2 − P1| − r_c"),
    f("flag.saturated", "1", "saturation scaled the torques (0/1)"),
    f(
        "flag.near_singular",
        "1",
        "below the singularity margin (0/1)",
    ),
    f("flag.safety", "1", "safety latch set (0/1)"),
    f("flag.passivity", "1", "passivity controller active (0/1)"),
];

/// A cell of a tick row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Val {
    /// An integer column's value.
    U(u64),
    /// A float column's value.
    F(f64),
}

impl Val {
    /// The value as `f64` (integers above 2^53 round).
    pub fn as_f64(self) -> f64 {
        match self {
            Val::U(v) => v as f64,
            Val::F(v) => v,
        }
    }
}

impl std::fmt::Display for Val {
    /// Integers in decimal; floats in Rust's shortest round-trip form (`NaN`, `inf` as Rust prints
    /// them) — the same text the CSV logger writes.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Val::U(v) => write!(f, "{v}"),
            Val::F(v) => write!(f, "{v}"),
        }
    }
}

/// A tick row: one optional cell per [`TICK_TABLE`] column (`None` = not recorded, e.g. the loop
/// columns of a row converted from a CSV log).
pub type TickRow = [Option<Val>; TICK_TABLE_LEN];

/// The CSV header of a tick log: the [`TickRecord`] columns of [`TICK_TABLE`].
pub fn csv_header() -> Vec<String> {
    TICK_TABLE[LOOP_COLUMN_COUNT..]
        .iter()
        .map(|c| c.name.to_string())
        .collect()
}

/// The encoder columns of [`TICK_TABLE`] (`encoders.q1..q4`, rad), in order.
pub const ENCODER_COLUMNS: [&str; 4] = ["encoders.q1", "encoders.q2", "encoders.q3", "encoders.q4"];

/// The CSV header of `haptic2d run --log FILE.csv`: the [`TickRecord`] columns ([`csv_header`]),
/// then [`ENCODER_COLUMNS`] — the order `log convert RUN.mcap RUN.csv` writes them in (record
/// columns first, then the loop columns present), so a run's CSV converts to MCAP and back to the
/// same text.
pub fn run_csv_header() -> Vec<String> {
    let mut h = csv_header();
    h.extend(ENCODER_COLUMNS.iter().map(|s| s.to_string()));
    h
}

/// The index of the column named `name` in [`TICK_TABLE`].
pub fn column_index(name: &str) -> Option<usize> {
    TICK_TABLE.iter().position(|c| c.name == name)
}

/// The full row of a tick: loop fields and record.
pub fn tick_row(
    index: u64,
    deadline_ns: u64,
    lateness_ns: u64,
    q: &[f64; 4],
    rec: &TickRecord,
) -> TickRow {
    let mut row: TickRow = [None; TICK_TABLE_LEN];
    row[0] = Some(Val::U(index));
    row[1] = Some(Val::U(deadline_ns));
    row[2] = Some(Val::U(lateness_ns));
    for k in 0..4 {
        row[3 + k] = Some(Val::F(q[k]));
    }
    for (k, v) in rec.values().iter().enumerate() {
        row[LOOP_COLUMN_COUNT + k] = Some(Val::F(*v));
    }
    row
}

/// Splits `object.field` into (`Some(object)`, `field`), or a top-level name into (`None`, name).
fn split(name: &str) -> (Option<&str>, &str) {
    match name.split_once('.') {
        Some((o, f)) => (Some(o), f),
        None => (None, name),
    }
}

/// Writes a JSON number in shortest round-trip form (`ryu`: e.g. `0.001`, `2.3702731755658497e-17`;
/// exact, and short for tiny values); a non-finite value (JSON has none) as the string `"NaN"`,
/// `"inf"` or `"-inf"`, so that every `f64` survives a round trip.
#[inline]
pub fn write_json_f64<W: Write>(out: &mut W, v: f64) -> std::io::Result<()> {
    if v.is_finite() {
        let mut b = ryu::Buffer::new();
        out.write_all(b.format_finite(v).as_bytes())
    } else {
        write!(out, "\"{v}\"")
    }
}

/// Writes `"key":`.
#[inline]
pub fn write_key<W: Write>(out: &mut W, key: &str) -> std::io::Result<()> {
    out.write_all(b"\"")?;
    out.write_all(key.as_bytes())?;
    out.write_all(b"\":")
}

/// Reads a float written by [`write_json_f64`] (a number, or `"NaN"`/`"inf"`/`"-inf"`).
pub fn json_f64(v: &serde_json::Value) -> Option<f64> {
    match v {
        serde_json::Value::String(s) => s.parse::<f64>().ok().filter(|x| !x.is_finite()),
        v => v.as_f64(),
    }
}

/// Writes the fields of `row` (present cells only) as the members of a JSON object, nested per
/// [`TICK_TABLE`]: `"t":0.001,"device":{"x":…},…` (no surrounding braces; `first` = no member
/// written yet). Returns whether a member was written.
pub fn write_row_members<W: Write>(
    out: &mut W,
    row: &TickRow,
    mut first: bool,
) -> std::io::Result<bool> {
    let mut open: Option<&str> = None;
    for (c, cell) in TICK_TABLE.iter().zip(row.iter()) {
        let Some(v) = cell else { continue };
        let (obj, field) = split(c.name);
        if open.is_some() && open != obj {
            out.write_all(b"}")?;
            open = None;
        }
        if open.is_none() {
            if !first {
                out.write_all(b",")?;
            }
            first = false;
            if let Some(o) = obj {
                write!(out, "\"{o}\":{{")?;
                open = Some(o);
            }
        } else {
            out.write_all(b",")?;
        }
        write_key(out, field)?;
        match v {
            Val::U(x) => write!(out, "{x}")?,
            Val::F(x) => write_json_f64(out, *x)?,
        }
    }
    if open.is_some() {
        out.write_all(b"}")?;
    }
    Ok(!first)
}

/// Reads a tick row back from a parsed `/haptic2d/tick` message (absent fields = `None`).
/// Errors name the column whose value has the wrong type.
pub fn row_from_json(msg: &serde_json::Value) -> Result<TickRow, String> {
    let mut row: TickRow = [None; TICK_TABLE_LEN];
    for (k, c) in TICK_TABLE.iter().enumerate() {
        let (obj, field) = split(c.name);
        let v = match obj {
            Some(o) => msg.get(o).and_then(|x| x.get(field)),
            None => msg.get(field),
        };
        let Some(v) = v else { continue };
        row[k] = Some(match (c.kind, v) {
            (Kind::U64, v) => Val::U(v.as_u64().ok_or_else(|| {
                format!(
                    "field `{}` is `{v}`, expected an unsigned integer ({})",
                    c.name, c.unit
                )
            })?),
            (Kind::F64, v) => Val::F(json_f64(v).ok_or_else(|| {
                format!(
                    "field `{}` is `{v}`, expected a number ({})",
                    c.name, c.unit
                )
            })?),
        });
    }
    Ok(row)
}

/// Parses a CSV cell of column `col` (the text the CSV logger writes, `NaN`/`inf` included).
pub fn parse_cell(col: &Column, text: &str) -> Result<Val, String> {
    let t = text.trim();
    match col.kind {
        Kind::U64 => t.parse::<u64>().map(Val::U).map_err(|_| {
            format!(
                "column `{}`: `{t}` is not an unsigned integer ({})",
                col.name, col.unit
            )
        }),
        Kind::F64 => t.parse::<f64>().map(Val::F).map_err(|_| {
            format!(
                "column `{}`: `{t}` is not a number ({})",
                col.name, col.unit
            )
        }),
    }
}

/// The JSON Schema (draft 2020-12) of `/haptic2d/tick`, generated from [`TICK_TABLE`]: every column
/// a property with its unit and meaning in `description`; non-finite floats are strings.
pub fn tick_json_schema() -> String {
    let mut s = String::from(
        "{\"$schema\":\"https://json-schema.org/draft/2020-12/schema\",\"title\":\"haptic2d.Tick\",\"description\":\"One haptic tick (units in each description)\",\"type\":\"object\",\"properties\":{",
    );
    let mut open: Option<&str> = None;
    let mut first = true;
    for c in TICK_TABLE.iter() {
        let (obj, field) = split(c.name);
        if open.is_some() && open != obj {
            s.push_str("}}");
            open = None;
        }
        if open.is_none() {
            if !first {
                s.push(',');
            }
            first = false;
            if let Some(o) = obj {
                s.push_str(&format!("\"{o}\":{{\"type\":\"object\",\"properties\":{{"));
                open = Some(o);
            }
        } else {
            s.push(',');
        }
        let ty = match c.kind {
            Kind::U64 => "\"integer\",\"minimum\":0",
            Kind::F64 => "[\"number\",\"string\"]",
        };
        s.push_str(&format!(
            "\"{field}\":{{\"type\":{ty},\"description\":{}}}",
            serde_json::Value::String(format!("{} ({})", c.doc, c.unit))
        ));
    }
    if open.is_some() {
        s.push_str("}}");
    }
    s.push_str("}}");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_columns_of_the_table_are_tick_columns() {
        assert_eq!(csv_header(), TICK_COLUMNS.to_vec());
    }

    #[test]
    fn run_csv_header_is_the_record_columns_then_the_encoders() {
        let h = run_csv_header();
        assert_eq!(&h[..TICK_COLUMNS.len()], &csv_header()[..]);
        assert_eq!(
            &h[TICK_COLUMNS.len()..],
            &["encoders.q1", "encoders.q2", "encoders.q3", "encoders.q4"]
        );
        // Every column maps back to the tick table (log convert CSV → MCAP), the encoders to
        // the loop columns 3..7 in order.
        let idx: Vec<usize> = h.iter().map(|n| column_index(n).unwrap()).collect();
        assert_eq!(&idx[TICK_COLUMNS.len()..], &[3, 4, 5, 6]);
    }

    #[test]
    fn objects_are_contiguous_and_names_have_at_most_one_dot() {
        let mut seen: Vec<&str> = Vec::new();
        let mut last: Option<&str> = None;
        for c in TICK_TABLE {
            assert!(c.name.matches('.').count() <= 1, "{}", c.name);
            let (o, _) = split(c.name);
            if o != last {
                if let Some(o) = o {
                    assert!(!seen.contains(&o), "object {o} split in two");
                    seen.push(o);
                }
                last = o;
            }
        }
    }

    #[test]
    fn row_json_round_trip_is_exact() {
        // -1.0408340855860843e-14 and 4.163336342344337e-14 came back one ULP off with serde_json's
        // default float parser (a CSV ↔ MCAP comparison caught it): the `float_roundtrip` feature
        // is required.
        let rec = TickRecord {
            t: 0.1 + 0.2,
            f_cm: [
                -1.0408340855860843e-14,
                4.163336342344337e-14,
                0.005443417929809624,
            ],
            x_m: [1e-300, -0.0, f64::NAN],
            v_m: [f64::INFINITY, f64::NEG_INFINITY, 5e-324],
            contacts: 3,
            flags: 5,
            ..TickRecord::default()
        };
        let row = tick_row(u64::MAX, 1 << 60, 7, &[0.5, -1.25, 3.0, 1e-17], &rec);
        let mut buf = Vec::new();
        buf.push(b'{');
        write_row_members(&mut buf, &row, true).unwrap();
        buf.push(b'}');
        let v: serde_json::Value = serde_json::from_slice(&buf).unwrap();
        let back = row_from_json(&v).unwrap();
        for k in 0..TICK_TABLE_LEN {
            let (a, b) = (row[k].unwrap(), back[k].unwrap());
            assert_eq!(a.to_string(), b.to_string(), "{}", TICK_TABLE[k].name);
        }
    }

    #[test]
    fn schema_is_json_with_every_column() {
        let v: serde_json::Value = serde_json::from_str(&tick_json_schema()).unwrap();
        let p = &v["properties"];
        for c in TICK_TABLE {
            let (o, f) = split(c.name);
            let node = match o {
                Some(o) => &p[o]["properties"][f],
                None => &p[f],
            };
            assert!(
                node["description"].as_str().unwrap().contains(c.unit),
                "{}",
                c.name
            );
        }
    }
}
