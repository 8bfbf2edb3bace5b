//! `haptic2d log info FILE` and `haptic2d log convert IN OUT`: what a log holds, and tick logs
//! between CSV and MCAP (format by extension). The conversion is lossless for the tick columns: a
//! CSV tick log converted to MCAP and back is the same text; an MCAP log converted to CSV keeps
//! every tick column it has (the loop columns too) in `OUT`, and writes each world channel the log
//! has (bodies, contacts, energy) as its own CSV next to it: `OUT.bodies.csv`, `OUT.contacts.csv`,
//! `OUT.energy.csv` (`OUT` without its `.csv`; layout in [`haptic2d_rt::mcap::world_csv`]).

use crate::exit::{Failure, Status};
use crate::run_log::is_mcap;
use haptic2d_rt::mcap::columns::{
    column_index, TickRow, Val, LOOP_COLUMN_COUNT, TICK_TABLE, TICK_TABLE_LEN,
};
use haptic2d_rt::mcap::reader::{read_file, read_info, read_ticks, LogInfo};
use haptic2d_rt::mcap::schemas::TOPIC_TICK;
use haptic2d_rt::mcap::tick_csv::read_tick_csv;
use haptic2d_rt::mcap::world_csv::{read_world_tables, WorldTable};
use haptic2d_rt::mcap::{McapSetup, McapSink};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// `haptic2d log` subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum LogCmd {
    /// Print what a log holds: channels, message counts, duration, the run's scene and timing
    /// summary (MCAP), or rows and columns (CSV).
    Info {
        /// The log file (.mcap or .csv).
        file: std::path::PathBuf,
    },
    /// Convert a tick log between CSV and MCAP (format by extension: .mcap, else CSV).
    Convert {
        /// Input log.
        input: std::path::PathBuf,
        /// Output log (overwritten).
        output: std::path::PathBuf,
    },
}

/// Runs a `log` subcommand.
pub fn run(cmd: &LogCmd) -> Result<Status, Failure> {
    match cmd {
        LogCmd::Info { file } => info(file),
        LogCmd::Convert { input, output } => convert(input, output),
    }
}

fn secs(ns: u64) -> f64 {
    ns as f64 * 1e-9
}

fn info(path: &Path) -> Result<Status, Failure> {
    let label = path.display().to_string();
    if !is_mcap(path) {
        let rows = read_csv(path)?;
        println!(
            "{label}: CSV tick log, {} rows, {} columns",
            rows.1.len(),
            rows.0.len()
        );
        let t = column_index("t").and_then(|k| rows.0.iter().position(|&c| c == k));
        if let (Some(t), Some(first), Some(last)) = (t, rows.1.first(), rows.1.last()) {
            let (a, b) = (first[t].as_f64(), last[t].as_f64());
            println!("time: t = {a} s to {b} s ({:.6} s)", b - a);
        }
        return Ok(Status::Clean);
    }
    let bytes = read_file(path)?;
    let info = read_info(&bytes, &label)?;
    print_info(&label, bytes.len(), &info);
    Ok(Status::Clean)
}

fn print_info(label: &str, size: usize, info: &LogInfo) {
    println!(
        "{label}: MCAP, {:.1} KiB, {}",
        size as f64 / 1024.0,
        if info.complete {
            "complete (summary and index written)".to_string()
        } else {
            format!(
                "NOT finished: no footer ({}); the messages before the damage are counted",
                info.damage.as_deref().unwrap_or("the file ends early")
            )
        }
    );
    match info.time_range_ns {
        Some((a, b)) => println!(
            "messages: {} over {:.6} s (log_time {} ns to {} ns)",
            info.messages,
            secs(b - a),
            a,
            b
        ),
        None => println!("messages: none"),
    }
    println!("channels:");
    for c in &info.channels {
        println!(
            "  {:<24} {:>9} messages  schema {} ({}), encoding {}",
            c.topic, c.count, c.schema, c.schema_encoding, c.message_encoding
        );
    }
    if let Some(s) = info.metadata("haptic2d.scene") {
        let get = |k: &str| s.get(k).map_or("-", |v| v.as_str());
        println!(
            "scene: {} ({}), device {}, controller {}, {} Hz, hand {}{}",
            get("scene_name"),
            get("scene"),
            get("device"),
            get("controller"),
            get("rate_hz"),
            get("hand"),
            s.get("device_file")
                .map_or(String::new(), |d| format!(", device file {d}"))
        );
        if let Some(src) = s.get("converted_from") {
            println!("converted from {src}");
        }
    }
    match info.metadata("haptic2d.timing") {
        Some(t) => {
            if let Some(s) = t.get("summary") {
                println!("{s}");
            }
        }
        None if info.count(TOPIC_TICK) > 0 => {
            println!("timing: no timing summary in the log (it was not finished by haptic2d run)")
        }
        None => {}
    }
}

/// A CSV tick log: the table column of each CSV column, and the rows (bounded: 1 GiB, 1 MiB a line).
fn read_csv(path: &Path) -> Result<(Vec<usize>, Vec<Vec<Val>>), Failure> {
    Ok(read_tick_csv(path)?)
}

fn convert(input: &Path, output: &Path) -> Result<Status, Failure> {
    let (inl, outl) = (input.display().to_string(), output.display().to_string());
    match (is_mcap(input), is_mcap(output)) {
        (false, true) => {
            let (cols, rows) = read_csv(input)?;
            let file = std::fs::File::create(output)
                .map_err(|e| Failure::error(format!("cannot create {outl}: {e}")))?;
            let mut scene = BTreeMap::new();
            scene.insert("converted_from".to_string(), inl.clone());
            let mut sink = McapSink::new(BufWriter::with_capacity(1 << 20, file), McapSetup::ticks_only(scene))
                .map_err(|e| Failure::error(format!("cannot write {outl}: {e}")))?;
            let (ki, kd, kt) = (column_index("index"), column_index("deadline_ns"), column_index("t"));
            for (i, r) in rows.iter().enumerate() {
                let mut row: TickRow = [None; TICK_TABLE_LEN];
                for (&k, v) in cols.iter().zip(r) {
                    row[k] = Some(*v);
                }
                let get = |k: Option<usize>| k.and_then(|k| row[k]);
                // log_time: the recorded deadline, else the tick time t, else the row number (ns).
                let log_time = match (get(kd), get(kt)) {
                    (Some(Val::U(d)), _) => d,
                    (_, Some(t)) if t.as_f64().is_finite() && t.as_f64() >= 0.0 => (t.as_f64() * 1e9).round() as u64,
                    _ => i as u64,
                };
                let seq = match get(ki) {
                    Some(Val::U(s)) => s,
                    _ => i as u64,
                };
                sink.write_tick_row(seq, log_time, &row)
                    .map_err(|e| Failure::error(format!("cannot write {outl}: {e}")))?;
            }
            let stats = sink
                .finish(&[])
                .map_err(|e| Failure::error(format!("cannot finish {outl}: {e}")))?;
            println!("{inl} → {outl}: {} ticks, {} columns", stats.count(TOPIC_TICK), cols.len());
        }
        (true, false) => {
            let bytes = read_file(input)?;
            let (rows, info) = read_ticks(&bytes, &inl)?;
            let (tables, _) = read_world_tables(&bytes, &inl)?;
            if let Some(cut) = &info.damage {
                eprintln!("warning: {inl} was cut short ({cut}): converting the records before the cut");
            }
            if rows.is_empty() {
                if tables.iter().all(|t| t.messages == 0) {
                    return Err(format!("{inl} has no {TOPIC_TICK}, bodies, contacts or energy messages: nothing to convert to CSV").into());
                }
                // A world recording (`simulate --out FILE.mcap`): the world channels only.
                let written = write_world_tables(output, &tables)?;
                println!("{inl} → {}: no {TOPIC_TICK} messages (a world recording), so no tick CSV", written.join(", "));
                return Ok(Status::Clean);
            }
            let present: Vec<usize> = (0..TICK_TABLE_LEN).filter(|&k| rows[0][k].is_some()).collect();
            let mut w = csv::Writer::from_path(output)
                .map_err(|e| Failure::error(format!("cannot create {outl}: {e}")))?;
            let wr = |e: csv::Error| Failure::error(format!("cannot write {outl}: {e}"));
            // Loop columns last: the tick columns first keep the CSV logger's layout.
            let order: Vec<usize> = present
                .iter()
                .copied()
                .filter(|&k| k >= LOOP_COLUMN_COUNT)
                .chain(present.iter().copied().filter(|&k| k < LOOP_COLUMN_COUNT))
                .collect();
            w.write_record(order.iter().map(|&k| TICK_TABLE[k].name)).map_err(wr)?;
            for (i, r) in rows.iter().enumerate() {
                let mut fields = Vec::with_capacity(order.len());
                for &k in &order {
                    let v = r[k].ok_or_else(|| {
                        Failure::from(format!(
                            "{inl}: tick message {i} has no `{}` though the first one has: the ticks do not share one layout",
                            TICK_TABLE[k].name
                        ))
                    })?;
                    fields.push(v.to_string());
                }
                w.write_record(&fields).map_err(wr)?;
            }
            w.flush().map_err(|e| Failure::error(format!("cannot write {outl}: {e}")))?;
            let written = write_world_tables(output, &tables)?;
            let world: u64 = tables.iter().map(|t| t.messages).sum();
            let skipped = info.messages.saturating_sub(rows.len() as u64 + world);
            println!(
                "{inl} → {outl}: {} ticks, {} columns{}{}",
                rows.len(),
                order.len(),
                if written.is_empty() {
                    String::new()
                } else {
                    format!("; world channels → {}", written.join(", "))
                },
                if skipped > 0 {
                    format!(" ({skipped} messages of the scene and scene-update channels not converted)")
                } else {
                    String::new()
                }
            );
        }
        _ => {
            return Err(format!(
                "log convert {inl} {outl}: converts between CSV and MCAP (one of the two must end in .mcap, the other not)"
            )
            .into())
        }
    }
    Ok(Status::Clean)
}

/// The CSV of world channel `suffix` next to the tick CSV `output`: `OUT.csv` → `OUT.bodies.csv`
/// (an output without `.csv` gets the suffix appended).
pub fn world_csv_path(output: &Path, suffix: &str) -> PathBuf {
    let name = output
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = name.strip_suffix(".csv").unwrap_or(&name);
    output.with_file_name(format!("{stem}{suffix}"))
}

/// Writes every world table with messages next to `output`; returns the paths written.
fn write_world_tables(output: &Path, tables: &[WorldTable]) -> Result<Vec<String>, Failure> {
    let mut written = Vec::new();
    for t in tables.iter().filter(|t| t.messages > 0) {
        let path = world_csv_path(output, t.channel.suffix);
        let label = path.display().to_string();
        let wr = |e: csv::Error| Failure::error(format!("cannot write {label}: {e}"));
        let mut w = csv::Writer::from_path(&path)
            .map_err(|e| Failure::error(format!("cannot create {label}: {e}")))?;
        w.write_record(t.channel.header()).map_err(wr)?;
        for r in &t.rows {
            w.write_record(r).map_err(wr)?;
        }
        w.flush()
            .map_err(|e| Failure::error(format!("cannot write {label}: {e}")))?;
        written.push(label);
    }
    Ok(written)
}
