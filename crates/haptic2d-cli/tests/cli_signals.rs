//! Issue 10, item 6: SIGINT and SIGTERM end `run` and `simulate` cleanly — the summary printed,
//! every log ending on a whole row, exit status 130 (interrupted). Signals are sent with
//! `libc::kill` to the spawned binary.

mod common;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_haptic2d"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts")
}

/// Waits until `path` holds at least `bytes` bytes (the run is under way), at most 60 s.
fn wait_for_file(path: &Path, bytes: u64, child: &mut Child) {
    let t0 = Instant::now();
    while std::fs::metadata(path).map_or(0, |m| m.len()) < bytes {
        if let Some(s) = child.try_wait().unwrap() {
            panic!("exited early with {s}");
        }
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "no output after 60 s"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Sends `sig`, waits (at most 30 s: no hang) and returns (exit code, stdout + stderr).
fn signal_and_wait(child: Child, sig: libc::c_int) -> (Option<i32>, String) {
    let pid = child.id() as libc::pid_t;
    // SAFETY: kill(2) on the pid of a child we spawned and have not reaped.
    assert_eq!(unsafe { libc::kill(pid, sig) }, 0);
    let Some((status, out)) = common::wait_with_limit(child, Duration::from_secs(30)) else {
        panic!("did not exit within 30 s of the signal");
    };
    (status.code(), out)
}

/// Every line of the CSV at `path` has the header's number of fields and the file ends on a newline.
fn assert_whole_rows(path: &Path) -> usize {
    let csv = std::fs::read_to_string(path).unwrap();
    assert!(
        csv.ends_with('\n'),
        "the log ends mid-row: …{}",
        &csv[csv.len().saturating_sub(200)..]
    );
    let mut lines = csv.lines();
    let fields = lines.next().unwrap().split(',').count();
    let mut rows = 0;
    for (i, l) in lines.enumerate() {
        assert_eq!(l.split(',').count(), fields, "row {} is cut: {l}", i + 1);
        rows += 1;
    }
    rows
}

/// The "N ticks" of the run summary.
fn ticks_in(out: &str) -> usize {
    out.split_whitespace()
        .collect::<Vec<_>>()
        .windows(2)
        .find(|w| w[1] == "ticks")
        .and_then(|w| w[0].parse().ok())
        .unwrap_or_else(|| panic!("no tick count in:\n{out}"))
}

fn run_log_then(sig: libc::c_int) {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.csv");
    let mut child = spawn(&[
        "run",
        "--headless",
        "--no-rt",
        "--log",
        log.to_str().unwrap(),
    ]);
    // ~100 rows written (the logger flushes its 64 KiB buffer as it goes).
    wait_for_file(&log, 70_000, &mut child);
    let (code, out) = signal_and_wait(child, sig);
    assert_eq!(
        code,
        Some(130),
        "exit status (None = killed by the signal):\n{out}"
    );
    assert!(out.contains("on time:"), "summary printed:\n{out}");
    assert!(out.contains("stopped: interrupted by a signal"), "{out}");
    assert!(out.contains("rows written"), "log report printed:\n{out}");
    let rows = assert_whole_rows(&log);
    assert_eq!(rows, ticks_in(&out), "every tick logged");
}

#[test]
fn sigterm_on_run_log_ends_on_a_whole_row_and_prints_the_summary() {
    run_log_then(libc::SIGTERM);
}

#[test]
fn sigint_on_run_log_ends_on_a_whole_row_and_prints_the_summary() {
    run_log_then(libc::SIGINT);
}

fn simulate_then(sig: libc::c_int) {
    let dir = tempfile::tempdir().unwrap();
    let out_csv = dir.path().join("sim.csv");
    // pile:100 for 1000 s: far longer than the test; the signal ends it.
    let mut child = spawn(&[
        "simulate",
        "pile:100",
        "--duration",
        "1000",
        "--out",
        out_csv.to_str().unwrap(),
    ]);
    // The 1 MiB CSV buffer has been flushed at least once.
    wait_for_file(&out_csv, 1 << 20, &mut child);
    let (code, out) = signal_and_wait(child, sig);
    assert_eq!(code, Some(130), "exit status:\n{out}");
    assert!(out.contains("interrupted by a signal"), "{out}");
    assert!(out.contains("energy: initial"), "summary printed:\n{out}");
    let rows = assert_whole_rows(&out_csv);
    // The summary's sample count matches the rows (t = 0 row + one per sample).
    let done: usize = out
        .lines()
        .find_map(|l| l.strip_prefix("pile:100: "))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no sample count in:\n{out}"));
    assert_eq!(rows, done + 1, "{out}");
}

#[test]
fn sigterm_on_simulate_flushes_whole_rows_and_prints_the_summary() {
    simulate_then(libc::SIGTERM);
}

#[test]
fn sigint_on_simulate_flushes_whole_rows_and_prints_the_summary() {
    simulate_then(libc::SIGINT);
}
