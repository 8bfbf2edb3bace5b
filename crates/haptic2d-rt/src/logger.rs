//! The CSV logger thread: drains the telemetry ring into a CSV file.
//!
//! The logger runs on its own (non-real-time) thread. It wakes every
//! [`LoggerConfig::poll_interval`], writes every record waiting in the ring,
//! and goes back to sleep. [`CsvLogger::finish`] — called after the loop has
//! stopped, whether at the end of `--duration` or after Ctrl-C set the stop
//! flag — drains the ring completely, flushes the file and reports how many
//! records were written and how many the RT thread had to drop because the
//! ring was full. Nothing that reached the ring is lost.

use crate::drain_thread::DrainThread;
use crate::telemetry::RecordRx;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// A record type the CSV logger can write.
pub trait CsvRecord: Copy + Send + 'static {
    /// Column names, written once as the first row.
    fn header() -> Vec<String>;

    /// Writes this record's fields, in [`header`](Self::header) order, with
    /// `csv::Writer::write_field`. The logger ends the row.
    fn write_row<W: Write>(&self, out: &mut csv::Writer<W>) -> csv::Result<()>;
}

/// Logger settings.
#[derive(Debug, Clone)]
pub struct LoggerConfig {
    /// How long the logger sleeps when the ring is empty. Default 2 ms. The
    /// ring must hold at least this long of records (at 10 kHz: 20 records;
    /// size it for ≥ 1 s to ride out slow disks).
    pub poll_interval: Duration,
    /// Header to write instead of `T::header()`, for record layouts whose
    /// column names depend on the run (e.g. body names of a scene).
    pub header: Option<Vec<String>>,
}

impl Default for LoggerConfig {
    fn default() -> Self {
        Self {
            poll_interval: Duration::from_millis(2),
            header: None,
        }
    }
}

/// What the logger did, returned by [`CsvLogger::finish`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LogReport {
    /// Rows written (header excluded).
    pub written: u64,
    /// Records the producer offered to the ring.
    pub offered: u64,
    /// Records the producer dropped because the ring was full.
    pub dropped: u64,
}

impl std::fmt::Display for LogReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "log: {} rows written", self.written)?;
        if self.dropped > 0 {
            write!(
                f,
                ", {} records dropped because the telemetry ring was full (enlarge it or log less often)",
                self.dropped
            )?;
        }
        Ok(())
    }
}

/// Handle of a running CSV logger thread. A logger dropped without [`finish`](CsvLogger::finish)
/// still drains and flushes (errors are then lost).
pub struct CsvLogger {
    thread: DrainThread<LogReport>,
}

impl CsvLogger {
    /// Starts a logger thread that writes the records of `rx` to `out` as CSV
    /// (header first). `label` names the destination in error messages (e.g.
    /// the file path).
    pub fn spawn<T: CsvRecord, W: Write + Send + 'static>(
        rx: RecordRx<T>,
        out: W,
        label: &str,
        config: LoggerConfig,
    ) -> Result<Self, String> {
        let label = label.to_string();
        let thread = DrainThread::spawn("haptic2d-logger", "logger", move |stop| {
            logger_thread(rx, out, label, config, stop)
        })?;
        Ok(Self { thread })
    }

    /// Creates (truncates) the file at `path` and starts a logger writing to
    /// it through a 64 KiB buffer.
    pub fn spawn_file<T: CsvRecord>(
        rx: RecordRx<T>,
        path: &std::path::Path,
        config: LoggerConfig,
    ) -> Result<Self, String> {
        let file = std::fs::File::create(path)
            .map_err(|e| format!("cannot create the log file {}: {e}", path.display()))?;
        let out = std::io::BufWriter::with_capacity(64 * 1024, file);
        Self::spawn(rx, out, &path.display().to_string(), config)
    }

    /// Stops the logger after it has written every record still in the ring,
    /// flushes the output, and reports. Call it after the producer has
    /// stopped publishing (records published later may not be written).
    pub fn finish(self) -> Result<LogReport, String> {
        self.thread.finish("logger")
    }
}

/// Body of the logger thread.
fn logger_thread<T: CsvRecord, W: Write>(
    mut rx: RecordRx<T>,
    out: W,
    label: String,
    config: LoggerConfig,
    stop: Arc<AtomicBool>,
) -> Result<LogReport, String> {
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(out);
    let header = config.header.clone().unwrap_or_else(T::header);
    let mut first_error: Option<String> = None;
    if let Err(e) = w.write_record(&header) {
        first_error = Some(format!("cannot write the log header to {label}: {e}"));
    }
    let mut written = 0u64;
    loop {
        // Read the stop flag *before* draining: every record pushed before
        // the flag was set is then in the ring and gets drained below.
        let stopping = stop.load(Ordering::Acquire) || rx.is_producer_gone();
        while let Some(rec) = rx.pop() {
            if first_error.is_some() {
                continue; // keep draining so the RT thread never sees a full ring
            }
            let res = rec
                .write_row(&mut w)
                .and_then(|_| w.write_record(std::iter::empty::<&[u8]>()));
            match res {
                Ok(()) => written += 1,
                Err(e) => first_error = Some(format!("cannot write to the log {label}: {e}")),
            }
        }
        if stopping {
            break;
        }
        // `finish` unparks the thread, so stopping does not wait for a full interval.
        std::thread::park_timeout(config.poll_interval);
    }
    if let Err(e) = w.flush() {
        first_error.get_or_insert(format!("cannot flush the log {label}: {e}"));
    }
    match first_error {
        Some(e) => Err(e),
        None => Ok(LogReport {
            written,
            offered: rx.offered(),
            dropped: rx.dropped(),
        }),
    }
}
