//! [`McapLogger`]: the MCAP logger thread, parallel to the CSV logger
//! ([`CsvLogger`](crate::logger::CsvLogger)): it drains the telemetry ring of [`LoggedTick`]s into
//! an [`McapSink`] and, on [`finish`](McapLogger::finish) — at the end of `--duration` or after
//! Ctrl-C set the stop flag — drains the ring completely, writes the final metadata (the run's
//! timing summary), the summary section and the index. Nothing that reached the ring is lost; the
//! [`LogReport`] says how many ticks were written and how many the RT thread dropped.

use crate::drain_thread::DrainThread;
use crate::logger::LogReport;
use crate::mcap::record::LoggedTick;
use crate::mcap::writer::{McapSetup, McapSink, McapStats};
use crate::telemetry::RecordRx;
use ::mcap::records::Metadata;
use std::io::{BufWriter, Seek, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// What the MCAP logger did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct McapReport {
    /// Ticks written, offered and dropped.
    pub log: LogReport,
    /// What the file holds (from the writer's summary).
    pub stats: McapStats,
}

impl std::fmt::Display for McapReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "log: {} ticks written ({} MCAP messages on {} channels)",
            self.log.written,
            self.stats.messages,
            self.stats.per_topic.len()
        )?;
        if self.log.dropped > 0 {
            write!(
                f,
                ", {} records dropped because the telemetry ring was full (enlarge it or log less often)",
                self.log.dropped
            )?;
        }
        Ok(())
    }
}

type Shared = Arc<Mutex<Vec<Metadata>>>;

/// Handle of a running MCAP logger thread. A logger dropped without
/// [`finish`](McapLogger::finish) still drains and writes a complete file (errors are then lost).
pub struct McapLogger {
    last_metadata: Shared,
    thread: DrainThread<McapReport>,
}

impl McapLogger {
    /// Starts a logger thread writing the records of `rx` to `out` (`label` names it in errors);
    /// it sleeps `poll` when the ring is empty.
    pub fn spawn<W: Write + Seek + Send + 'static>(
        rx: RecordRx<LoggedTick>,
        out: W,
        label: &str,
        setup: McapSetup,
        poll: Duration,
    ) -> Result<Self, String> {
        let label = label.to_string();
        let sink = McapSink::new(out, setup)
            .map_err(|e| format!("cannot start the MCAP log {label}: {e}"))?;
        let last_metadata: Shared = Arc::default();
        let m = last_metadata.clone();
        let thread = DrainThread::spawn("haptic2d-mcap", "logger", move |stop| {
            logger_thread(rx, sink, label, poll, stop, m)
        })?;
        Ok(Self {
            last_metadata,
            thread,
        })
    }

    /// Creates (truncates) `path` and starts a logger writing to it through a 1 MiB buffer.
    pub fn spawn_file(
        rx: RecordRx<LoggedTick>,
        path: &std::path::Path,
        setup: McapSetup,
    ) -> Result<Self, String> {
        let file = std::fs::File::create(path)
            .map_err(|e| format!("cannot create the log file {}: {e}", path.display()))?;
        let out = BufWriter::with_capacity(1 << 20, file);
        Self::spawn(
            rx,
            out,
            &path.display().to_string(),
            setup,
            Duration::from_millis(2),
        )
    }

    /// Stops the logger after it has written every record still in the ring, writes `metadata`
    /// (e.g. the timing summary) and the summary section, and reports. Call it after the producer
    /// stopped publishing.
    pub fn finish(self, metadata: Vec<Metadata>) -> Result<McapReport, String> {
        if let Ok(mut m) = self.last_metadata.lock() {
            *m = metadata;
        }
        self.thread.finish("MCAP logger")
    }
}

fn logger_thread<W: Write + Seek>(
    mut rx: RecordRx<LoggedTick>,
    mut sink: McapSink<W>,
    label: String,
    poll: Duration,
    stop: Arc<AtomicBool>,
    last_metadata: Shared,
) -> Result<McapReport, String> {
    let mut first_error: Option<String> = None;
    let mut written = 0u64;
    loop {
        // Read the stop flag before draining: every record pushed before it was set is drained.
        // Only `finish` (or drop) ends the thread — not the producer going away, which happens
        // first, before `finish` has handed over the final metadata.
        let stopping = stop.load(Ordering::Acquire);
        while let Some(rec) = rx.pop() {
            if first_error.is_some() {
                continue; // keep draining so the RT thread never sees a full ring
            }
            match sink.write_tick(&rec) {
                Ok(()) => written += 1,
                Err(e) => first_error = Some(format!("cannot write to the log {label}: {e}")),
            }
        }
        if stopping {
            break;
        }
        std::thread::park_timeout(poll);
    }
    let metadata = last_metadata
        .lock()
        .map(|mut m| std::mem::take(&mut *m))
        .unwrap_or_default();
    let stats = sink
        .finish(&metadata)
        .map_err(|e| format!("cannot finish the log {label}: {e}"));
    if let Some(e) = first_error {
        return Err(e);
    }
    Ok(McapReport {
        log: LogReport {
            written,
            offered: rx.offered(),
            dropped: rx.dropped(),
        },
        stats: stats?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcap::reader::{read_file, read_info};
    use crate::telemetry::telemetry_channel;
    use std::collections::BTreeMap;

    /// The loop drops the producer before `finish` hands over the timing summary; the logger used
    /// to end on "producer gone" and lose it (seen as "no timing summary" in `log info`).
    #[test]
    fn final_metadata_is_written_when_the_producer_is_gone_before_finish() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.mcap");
        let (mut tx, rx, _) = telemetry_channel(64, LoggedTick::default()).unwrap();
        let setup = McapSetup {
            ticks: true,
            ..McapSetup::default()
        };
        let logger = McapLogger::spawn_file(rx, &path, setup).unwrap();
        for i in 0..10 {
            let t = LoggedTick {
                index: i,
                deadline_ns: 1000 + i,
                ..LoggedTick::default()
            };
            assert!(tx.push(t));
        }
        drop(tx);
        std::thread::sleep(Duration::from_millis(50));
        let mut m = BTreeMap::new();
        m.insert("ticks".to_string(), "10".to_string());
        let report = logger
            .finish(vec![Metadata {
                name: "haptic2d.timing".into(),
                metadata: m,
            }])
            .unwrap();
        assert_eq!(report.log.written, 10);
        let bytes = read_file(&path).unwrap();
        let info = read_info(&bytes, "m.mcap").unwrap();
        assert!(info.complete);
        assert_eq!(info.count(crate::mcap::schemas::TOPIC_TICK), 10);
        assert_eq!(info.metadata("haptic2d.timing").unwrap()["ticks"], "10");
    }
}
