//! `haptic2d log info FILE` and `haptic2d log convert IN OUT`: what a log holds, and tick logs
//! between CSV and MCAP (format by extension). The conversion is lossless for the tick columns: a
//! CSV tick log converted to MCAP and back is the same text; an MCAP log converted to CSV keeps
//! every tick column it has (the loop columns too) in `OUT`, and writes each world channel the log
//! has (bodies, contacts, energy) as its own CSV next to it: `OUT.bodies.csv`, `OUT.contacts.csv`,
//! `OUT.energy.csv` (`OUT` without its `.csv`; layout in [`haptic2d_rt::mcap::world_csv`]).
//!
//! **Signals** (issue 38 item 3): every output is written under a temporary name in its own
//! directory (`.NAME.partial-PID`) and renamed to its name only once it is complete (an MCAP with
//! its summary and footer), so a conversion killed by any signal never leaves a half file under
//! the output's name — an older file of that name stays as it was. SIGINT, SIGTERM and SIGPIPE stop
//! the conversion, remove the temporary files and end it (exit 130; SIGPIPE: the process ends of
//! it, shell status 141). A signal that cannot be caught (SIGKILL) or a second SIGINT/SIGTERM
//! leaves the temporary file behind, never a damaged output.

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
use haptic2d_rt::signal::install_stop_signals;
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

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
        LogCmd::Convert { input, output } => {
            let stop = install_stop_signals().map_err(Failure::error)?;
            let r = convert(input, output, &Stop(stop));
            // Every output is renamed or removed: a SIGPIPE ends the process now (status 141);
            // otherwise SIGPIPE gets its default action back for the report line.
            crate::pipe::restore_after_output();
            if let Ok(lines) = &r {
                for l in lines {
                    println!("{l}");
                }
            }
            r.map(|_| Status::Clean)
        }
    }
}

/// The stop signals of a conversion: SIGINT/SIGTERM (the flag) or SIGPIPE ([`crate::pipe`]).
struct Stop(Arc<AtomicBool>);

impl Stop {
    /// `Err` (exit 130) once a stop signal arrived; the staged outputs are then removed as they drop.
    fn check(&self, outl: &str) -> Result<(), Failure> {
        if self.0.load(Ordering::Relaxed) || crate::pipe::sigpipe_seen() {
            return Err(Failure {
                status: Status::Interrupted,
                message: format!(
                    "log convert interrupted by a signal: {outl} was not written (nothing of it is left)"
                ),
            });
        }
        Ok(())
    }
}

/// An output written under a temporary name next to its final one (`.NAME.partial-PID`) and renamed
/// to it by [`Staged::commit`]; dropped uncommitted (an error, a signal), it removes the temporary
/// file.
pub struct Staged {
    tmp: PathBuf,
    dest: PathBuf,
    committed: bool,
}

impl Staged {
    /// Stages `dest`; the caller creates and writes [`Staged::path`]. An existing `dest` that is
    /// not a regular file (`/dev/stdout`, a named pipe) is written directly: renaming over it would
    /// replace the device or pipe.
    pub fn new(dest: &Path) -> Self {
        if std::fs::metadata(dest).is_ok_and(|m| !m.is_file()) {
            return Self {
                tmp: dest.to_path_buf(),
                dest: dest.to_path_buf(),
                committed: true,
            };
        }
        let name = dest
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        Self {
            tmp: dest.with_file_name(format!(".{name}.partial-{}", std::process::id())),
            dest: dest.to_path_buf(),
            committed: false,
        }
    }

    /// The temporary file to write.
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// Renames the complete temporary file to the output's name (atomic on one file system).
    pub fn commit(mut self) -> Result<(), Failure> {
        if self.tmp == self.dest {
            return Ok(()); // written directly (not a regular file)
        }
        std::fs::rename(&self.tmp, &self.dest).map_err(|e| {
            Failure::error(format!(
                "cannot rename {} to {}: {e}",
                self.tmp.display(),
                self.dest.display()
            ))
        })?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Rows between two checks of the stop signals.
const CHECK_EVERY: usize = 4096;

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

/// Converts `input` to `output`; returns the report lines (printed once every output is in place).
fn convert(input: &Path, output: &Path, stop: &Stop) -> Result<Vec<String>, Failure> {
    let (inl, outl) = (input.display().to_string(), output.display().to_string());
    match (is_mcap(input), is_mcap(output)) {
        (false, true) => {
            let (cols, rows) = read_csv(input)?;
            stop.check(&outl)?;
            let staged = Staged::new(output);
            let file = std::fs::File::create(staged.path())
                .map_err(|e| Failure::error(format!("cannot create {outl}: {e}")))?;
            let mut scene = BTreeMap::new();
            scene.insert("converted_from".to_string(), inl.clone());
            let mut sink = McapSink::new(BufWriter::with_capacity(1 << 20, file), McapSetup::ticks_only(scene))
                .map_err(|e| Failure::error(format!("cannot write {outl}: {e}")))?;
            let (ki, kd, kt) = (column_index("index"), column_index("deadline_ns"), column_index("t"));
            for (i, r) in rows.iter().enumerate() {
                if i % CHECK_EVERY == 0 {
                    stop.check(&outl)?;
                }
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
            stop.check(&outl)?;
            staged.commit()?;
            Ok(vec![format!("{inl} → {outl}: {} ticks, {} columns", stats.count(TOPIC_TICK), cols.len())])
        }
        (true, false) => {
            let bytes = read_file(input)?;
            let (rows, info) = read_ticks(&bytes, &inl)?;
            let (tables, _) = read_world_tables(&bytes, &inl)?;
            stop.check(&outl)?;
            if let Some(cut) = &info.damage {
                eprintln!("warning: {inl} was cut short ({cut}): converting the records before the cut");
            }
            if rows.is_empty() {
                if tables.iter().all(|t| t.messages == 0) {
                    return Err(format!("{inl} has no {TOPIC_TICK}, bodies, contacts or energy messages: nothing to convert to CSV").into());
                }
                // A world recording (`simulate --out FILE.mcap`): the world channels only.
                let (written, staged) = write_world_tables(output, &tables, stop)?;
                stop.check(&outl)?;
                for s in staged {
                    s.commit()?;
                }
                return Ok(vec![format!("{inl} → {}: no {TOPIC_TICK} messages (a world recording), so no tick CSV", written.join(", "))]);
            }
            let present: Vec<usize> = (0..TICK_TABLE_LEN).filter(|&k| rows[0][k].is_some()).collect();
            let staged = Staged::new(output);
            let mut w = csv::Writer::from_path(staged.path())
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
                if i % CHECK_EVERY == 0 {
                    stop.check(&outl)?;
                }
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
            drop(w);
            let (written, world_staged) = write_world_tables(output, &tables, stop)?;
            stop.check(&outl)?;
            for s in world_staged {
                s.commit()?;
            }
            staged.commit()?;
            let world: u64 = tables.iter().map(|t| t.messages).sum();
            let skipped = info.messages.saturating_sub(rows.len() as u64 + world);
            Ok(vec![format!(
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
            )])
        }
        _ => Err(format!(
                "log convert {inl} {outl}: converts between CSV and MCAP (one of the two must end in .mcap, the other not)"
            )
            .into()),
    }
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

/// Writes every world table with messages next to `output`, each staged under a temporary name;
/// returns the paths to be written and the staged files (the caller commits them).
fn write_world_tables(
    output: &Path,
    tables: &[WorldTable],
    stop: &Stop,
) -> Result<(Vec<String>, Vec<Staged>), Failure> {
    let mut written = Vec::new();
    let mut staged = Vec::new();
    for t in tables.iter().filter(|t| t.messages > 0) {
        let path = world_csv_path(output, t.channel.suffix);
        let label = path.display().to_string();
        let s = Staged::new(&path);
        let wr = |e: csv::Error| Failure::error(format!("cannot write {label}: {e}"));
        let mut w = csv::Writer::from_path(s.path())
            .map_err(|e| Failure::error(format!("cannot create {label}: {e}")))?;
        staged.push(s);
        w.write_record(t.channel.header()).map_err(wr)?;
        for (i, r) in t.rows.iter().enumerate() {
            if i % CHECK_EVERY == 0 {
                stop.check(&label)?;
            }
            w.write_record(r).map_err(wr)?;
        }
        w.flush()
            .map_err(|e| Failure::error(format!("cannot write {label}: {e}")))?;
        written.push(label);
    }
    Ok((written, staged))
}
