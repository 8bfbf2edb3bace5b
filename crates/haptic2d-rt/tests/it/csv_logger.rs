//! The CSV logger: every record that reaches the ring is written, at the end
//! of a run and after a stop flag (Ctrl-C); drops are counted, never blocking.

use haptic2d_rt::{
    run_loop, telemetry_channel, CsvLogger, CsvRecord, LoggerConfig, LoopConfig, TickControl,
};
use haptic2d_test_support::stop::raise_after;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Rec {
    tick: u64,
    t: f64,
    tau: [f64; 4],
}

impl CsvRecord for Rec {
    fn header() -> Vec<String> {
        ["tick", "t", "tau1", "tau2", "tau3", "tau4"]
            .map(String::from)
            .to_vec()
    }
    fn write_row<W: std::io::Write>(&self, out: &mut csv::Writer<W>) -> csv::Result<()> {
        out.write_field(self.tick.to_string())?;
        out.write_field(self.t.to_string())?;
        for v in self.tau {
            out.write_field(v.to_string())?;
        }
        Ok(())
    }
}

fn rec(k: u64) -> Rec {
    let x = k as f64;
    Rec {
        tick: k,
        t: x * 1e-3,
        tau: [x.sin(), -x * 0.1, 1.0 / (x + 1.0), 1e-7 * x],
    }
}

/// Reads a log back as records.
fn read_back(path: &std::path::Path) -> (Vec<String>, Vec<Rec>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|row| {
            let row = row.unwrap();
            let f = |i: usize| row[i].parse::<f64>().unwrap();
            Rec {
                tick: row[0].parse().unwrap(),
                t: f(1),
                tau: [f(2), f(3), f(4), f(5)],
            }
        })
        .collect();
    (header, rows)
}

#[test]
fn logger_writes_every_record_of_a_loop_run() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.csv");
    let (mut tx, rx, _snap) = telemetry_channel(4096, Rec::default()).unwrap();
    let logger = CsvLogger::spawn_file(rx, &path, LoggerConfig::default()).unwrap();
    let stop = AtomicBool::new(false);
    let config = LoopConfig {
        rate_hz: 10_000.0,
        duration: Some(Duration::from_millis(100)),
        ..LoopConfig::default()
    };
    let s = run_loop(&config, &stop, |info| {
        tx.publish(rec(info.index));
        TickControl::Continue
    })
    .unwrap();
    let produced = tx.offered();
    drop(tx);
    let report = logger.finish().unwrap();
    assert_eq!(produced, s.ticks);
    assert_eq!(report.dropped, 0);
    assert_eq!(report.offered, produced);
    assert_eq!(report.written, produced);
    let (header, rows) = read_back(&path);
    assert_eq!(header, Rec::header());
    assert_eq!(rows.len() as u64, produced);
    for (k, r) in rows.iter().enumerate() {
        // Rust's float formatting round-trips exactly.
        assert_eq!(*r, rec(k as u64));
    }
}

#[test]
fn logger_drains_everything_after_a_stop_flag_mid_run() {
    // Ctrl-C sets the stop flag; the loop returns; `finish` drains the ring.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ctrlc.csv");
    let (mut tx, rx, _snap) = telemetry_channel(1 << 16, Rec::default()).unwrap();
    let logger = CsvLogger::spawn_file(
        rx,
        &path,
        LoggerConfig {
            // A slow logger: most records are still in the ring at the stop.
            poll_interval: Duration::from_millis(500),
            header: None,
        },
    )
    .unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let setter = raise_after(&stop, Duration::from_millis(40));
    let s = run_loop(&LoopConfig::default(), &stop, |info| {
        tx.publish(rec(info.index));
        TickControl::Continue
    })
    .unwrap();
    setter.join().unwrap();
    let report = logger.finish().unwrap();
    assert_eq!(report.written, s.ticks);
    assert_eq!(report.dropped, 0);
    let (_, rows) = read_back(&path);
    assert_eq!(rows.len() as u64, s.ticks);
    assert_eq!(rows.last().map(|r| r.tick), s.ticks.checked_sub(1));
}

#[test]
fn full_ring_drops_are_counted_and_written_plus_dropped_equals_offered() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("small.csv");
    let (mut tx, rx, mut snap) = telemetry_channel(16, Rec::default()).unwrap();
    // Fill before the logger starts: 16 fit, 984 are dropped, none block.
    for k in 0..1000 {
        tx.publish(rec(k));
    }
    assert_eq!(snap.latest(), rec(999));
    let logger = CsvLogger::spawn_file(rx, &path, LoggerConfig::default()).unwrap();
    drop(tx);
    let report = logger.finish().unwrap();
    assert_eq!(report.offered, 1000);
    assert_eq!(report.dropped, 984);
    assert_eq!(report.written + report.dropped, report.offered);
    assert!(report.to_string().contains("984 records dropped"));
    let (_, rows) = read_back(&path);
    assert_eq!(rows, (0..16).map(rec).collect::<Vec<_>>());
}

#[test]
fn custom_header_replaces_the_record_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("hdr.csv");
    let (mut tx, rx, _snap) = telemetry_channel(8, Rec::default()).unwrap();
    let header: Vec<String> = ["k", "time", "a", "b", "c", "d"].map(String::from).to_vec();
    let logger = CsvLogger::spawn_file(
        rx,
        &path,
        LoggerConfig {
            header: Some(header.clone()),
            ..LoggerConfig::default()
        },
    )
    .unwrap();
    tx.publish(rec(1));
    drop(tx);
    assert_eq!(logger.finish().unwrap().written, 1);
    let (h, rows) = read_back(&path);
    assert_eq!(h, header);
    assert_eq!(rows, vec![rec(1)]);
}

#[test]
fn unwritable_log_path_is_a_clear_error() {
    let (_tx, rx, _snap) = telemetry_channel(8, Rec::default()).unwrap();
    let path = std::path::Path::new("/nonexistent-dir/x/run.csv");
    let e = CsvLogger::spawn_file(rx, path, LoggerConfig::default())
        .err()
        .unwrap();
    assert!(e.contains("/nonexistent-dir/x/run.csv"), "{e}");
}
