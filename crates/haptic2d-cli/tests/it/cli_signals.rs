//! Issue 10, item 6: SIGINT and SIGTERM end `run` and `simulate` cleanly — the summary printed,
//! every log ending on a whole row, exit status 130 (interrupted). Signals are sent with
//! `libc::kill` to the spawned binary.

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

/// `haptic2d ARGS…` signalled with `sig` once `file` holds `bytes` bytes (it is under way): its
/// exit code and output, as [`signal_and_wait`].
fn signalled_while_writing(
    args: &[&str],
    file: &Path,
    bytes: u64,
    sig: libc::c_int,
) -> (Option<i32>, String) {
    let mut child = spawn(args);
    wait_for_file(file, bytes, &mut child);
    signal_and_wait(child, sig)
}

/// Sends `sig`, waits (at most 30 s: no hang) and returns (exit code, stdout + stderr).
fn signal_and_wait(child: Child, sig: libc::c_int) -> (Option<i32>, String) {
    let pid = child.id() as libc::pid_t;
    // SAFETY: kill(2) on the pid of a child we spawned and have not reaped.
    assert_eq!(unsafe { libc::kill(pid, sig) }, 0);
    let Some((status, out)) = crate::common::wait_with_limit(child, Duration::from_secs(30)) else {
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
    crate::common::summary_ticks(out) as usize
}

fn run_log_then(sig: libc::c_int) {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.csv");
    let args = [
        "run",
        "--headless",
        "--no-rt",
        "--log",
        log.to_str().unwrap(),
    ];
    // Once ~100 rows are written (the logger flushes its 64 KiB buffer as it goes).
    let (code, out) = signalled_while_writing(&args, &log, 70_000, sig);
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
    let _m = crate::common::module_turn(module_path!());
    run_log_then(libc::SIGTERM);
}

#[test]
fn sigint_on_run_log_ends_on_a_whole_row_and_prints_the_summary() {
    let _m = crate::common::module_turn(module_path!());
    run_log_then(libc::SIGINT);
}

fn simulate_then(sig: libc::c_int) {
    let dir = tempfile::tempdir().unwrap();
    let out_csv = dir.path().join("sim.csv");
    // pile:100 for 1000 s: far longer than the test; the signal ends it, once the 1 MiB CSV
    // buffer has been flushed at least once.
    let path = out_csv.to_str().unwrap();
    let args = ["simulate", "pile:100", "--duration", "1000", "--out", path];
    let (code, out) = signalled_while_writing(&args, &out_csv, 1 << 20, sig);
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
    let _m = crate::common::module_turn(module_path!());
    simulate_then(libc::SIGTERM);
}

#[test]
fn sigint_on_simulate_flushes_whole_rows_and_prints_the_summary() {
    let _m = crate::common::module_turn(module_path!());
    simulate_then(libc::SIGINT);
}

/// A CSV tick log of `rows` rows (big enough that converting it takes a while), in `dir`.
fn big_tick_csv(dir: &Path, rows: usize) -> std::path::PathBuf {
    use std::io::Write;
    let p = dir.join("big.csv");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&p).unwrap());
    writeln!(f, "t,device.x,device.y,tau1").unwrap();
    for i in 0..rows {
        writeln!(f, "{},{},0.5,0.25", i as f64 * 1e-3, i as f64 * 1e-6).unwrap();
    }
    f.flush().unwrap();
    p
}

/// The temporary file `log convert` writes `out` under (`.NAME.partial-PID`), once it holds at
/// least `bytes` bytes; at most 60 s.
fn wait_for_partial(out: &Path, bytes: u64, child: &mut Child) -> std::path::PathBuf {
    let prefix = format!(".{}.partial-", out.file_name().unwrap().to_string_lossy());
    let t0 = Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            panic!("log convert exited with {s} before it was signalled");
        }
        let found = std::fs::read_dir(out.parent().unwrap())
            .unwrap()
            .filter_map(|e| e.ok())
            .find(|e| e.file_name().to_string_lossy().starts_with(&prefix));
        if let Some(e) = found {
            if e.metadata().map_or(0, |m| m.len()) >= bytes {
                return e.path();
            }
        }
        assert!(t0.elapsed() < Duration::from_secs(60), "no partial output");
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// `log convert big.csv out.mcap` (an older `out.mcap` in place) signalled with `sig` while it
/// writes: returns (exit code, output, the directory's entries after it ended, out.mcap's content).
fn convert_then(sig: libc::c_int) -> (Option<i32>, Option<i32>, String, Vec<String>, Vec<u8>) {
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    let csv = big_tick_csv(dir.path(), 600_000);
    let out = dir.path().join("out.mcap");
    std::fs::write(&out, b"the previous output").unwrap();
    let mut child = spawn(&[
        "log",
        "convert",
        csv.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    wait_for_partial(&out, 1 << 20, &mut child);
    let pid = child.id() as libc::pid_t;
    // SAFETY: kill(2) on the pid of a child we spawned and have not reaped.
    assert_eq!(unsafe { libc::kill(pid, sig) }, 0);
    let Some((status, text)) = crate::common::wait_with_limit(child, Duration::from_secs(30))
    else {
        panic!("log convert did not exit within 30 s of the signal");
    };
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let content = std::fs::read(&out).unwrap();
    (status.code(), status.signal(), text, names, content)
}

/// Issue 38 item 3: a conversion stopped by SIGTERM or SIGINT removes its partial output and
/// leaves the older file of the output's name as it was; exit 130 with the reason.
#[test]
fn sigterm_during_log_convert_leaves_no_partial_file_and_the_old_output_untouched() {
    let _m = crate::common::module_turn(module_path!());
    for sig in [libc::SIGTERM, libc::SIGINT] {
        let (code, _, text, names, content) = convert_then(sig);
        assert_eq!(code, Some(130), "signal {sig}:\n{text}");
        assert!(text.contains("interrupted by a signal"), "{text}");
        assert_eq!(names, ["big.csv", "out.mcap"], "no partial file left");
        assert_eq!(content, b"the previous output");
    }
}

/// SIGPIPE (its reader gone, or `kill -PIPE`): the partial file is removed, the output's name
/// untouched, and the process then ends of SIGPIPE (shell status 141) as a closed pipe says.
#[test]
fn sigpipe_during_log_convert_leaves_no_partial_file_then_ends_of_sigpipe() {
    let _m = crate::common::module_turn(module_path!());
    let (code, signal, text, names, content) = convert_then(libc::SIGPIPE);
    assert_eq!((code, signal), (None, Some(libc::SIGPIPE)), "{text}");
    assert_eq!(names, ["big.csv", "out.mcap"], "no partial file left");
    assert_eq!(content, b"the previous output");
}

/// SIGKILL cannot be caught: the temporary file stays, but nothing under the output's name is
/// half-written (the rename is the last step).
#[test]
fn sigkill_during_log_convert_never_leaves_a_half_file_under_the_output_name() {
    let _m = crate::common::module_turn(module_path!());
    let (_, signal, text, names, content) = convert_then(libc::SIGKILL);
    assert_eq!(signal, Some(libc::SIGKILL), "{text}");
    assert_eq!(content, b"the previous output");
    assert!(
        names.iter().any(|n| n.starts_with(".out.mcap.partial-")),
        "{names:?}"
    );
}

/// A conversion that is not interrupted renames its output into place and leaves no temporary
/// file; the result is a complete MCAP.
#[test]
fn log_convert_renames_its_complete_output_into_place() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let csv = big_tick_csv(dir.path(), 1000);
    let out = dir.path().join("out.mcap");
    let o = crate::common::run("log convert {} {}", &[&csv, &out]);
    assert!(o.status.success(), "{}", crate::common::text(&o));
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["big.csv", "out.mcap"]);
    let bytes = haptic2d_rt::mcap::reader::read_file(&out).unwrap();
    let info = haptic2d_rt::mcap::reader::read_info(&bytes, "out.mcap").unwrap();
    assert!(info.complete && info.messages >= 1000, "{info:?}");
}

/// An output that is not a regular file (a named pipe, `/dev/stdout`) is written in place, never
/// replaced by a rename: `log convert in.mcap FIFO` streams the CSV into the pipe.
#[test]
fn log_convert_into_a_named_pipe_writes_the_pipe_and_keeps_it() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let csv = big_tick_csv(dir.path(), 100);
    let mcap = dir.path().join("x.mcap");
    let o = crate::common::run("log convert {} {}", &[&csv, &mcap]);
    assert!(o.status.success(), "{}", crate::common::text(&o));
    let fifo = dir.path().join("pipe");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo(3) with a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let o = crate::common::run("log convert {} {}", &[&mcap, &fifo]);
    assert!(o.status.success(), "{}", crate::common::text(&o));
    // (Checked before joining the reader: had the pipe been renamed over, the reader would wait
    // for a writer forever.)
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::metadata(&fifo).unwrap().file_type().is_fifo(),
        "the named pipe was replaced"
    );
    let text = reader.join().unwrap();
    assert_eq!(
        text.lines().count(),
        101,
        "header + 100 rows through the pipe"
    );
}
