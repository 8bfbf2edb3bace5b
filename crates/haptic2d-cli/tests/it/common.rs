//! Helpers shared by the CLI end-to-end tests (the modules of the `it` binary); the
//! crate-independent ones live in haptic2d-test-support.

pub use haptic2d_test_support::files::{repo_root as root, temp_dir, write_in};
pub use haptic2d_test_support::process::{signal, spawn_announced, text, wait_with_limit, Killed};
pub use haptic2d_test_support::{holds_for, wait_for};

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::{Condvar, Mutex};

/// The `haptic2d` binary built for these tests.
pub const BIN: &str = env!("CARGO_BIN_EXE_haptic2d");

/// Runs the `haptic2d` binary built for these tests with `args` and waits for it.
pub fn haptic2d(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .output()
        .expect("the binary runs")
}

/// A `haptic2d` command whose arguments are the words of `line`, each word `{}` replaced by the
/// next of `paths` (whole, spaces and all): `cmd("simulate box-in-walls --out {}", &[&csv])`.
pub fn cmd(line: &str, paths: &[&dyn AsRef<OsStr>]) -> Command {
    let mut c = Command::new(BIN);
    let mut next = paths.iter();
    for word in line.split_whitespace() {
        if word == "{}" {
            c.arg(next.next().expect("a path for every {}").as_ref());
        } else {
            c.arg(word);
        }
    }
    assert!(next.next().is_none(), "more paths than {{}} in `{line}`");
    c
}

/// [`cmd`] run to its end: the output.
pub fn run(line: &str, paths: &[&dyn AsRef<OsStr>]) -> Output {
    cmd(line, paths).output().expect("the binary runs")
}

/// [`run`], asserting it succeeded; stdout followed by stderr.
#[track_caller]
pub fn run_ok(line: &str, paths: &[&dyn AsRef<OsStr>]) -> String {
    let o = run(line, paths);
    let out = text(&o);
    assert!(o.status.success(), "`haptic2d {line}` failed:\n{out}");
    out
}

/// Panics unless `out` contains every one of `needles` (the message names the missing one and
/// shows `out` whole).
#[track_caller]
pub fn assert_has(out: &str, needles: &[&str]) {
    for n in needles {
        assert!(out.contains(n), "no `{n}` in:\n{out}");
    }
}

/// Panics if `out` contains any of `needles`.
#[track_caller]
pub fn assert_lacks(out: &str, needles: &[&str]) {
    for n in needles {
        assert!(!out.contains(n), "`{n}` in:\n{out}");
    }
}

/// The stdout and stderr of `o`, asserting that it exited with `code` and that they contain every
/// one of `needles`.
#[track_caller]
pub fn expect_exit(o: &Output, code: i32, needles: &[&str]) -> String {
    let out = text(o);
    assert_eq!(o.status.code(), Some(code), "{out}");
    assert_has(&out, needles);
    out
}

/// A run that lost its device (the exit code and output of [`cut_mid_run`] or a run): exit 4, the
/// output names `device` and has every one of `needles`, and nothing panicked.
#[track_caller]
pub fn assert_lost_device(code: Option<i32>, out: &str, device: &str, needles: &[&str]) {
    assert_eq!(code, Some(4), "{out}");
    assert_has(out, &[device]);
    assert_has(out, needles);
    assert_lacks(out, &["panicked"]);
}

/// Which module's tests run now, and how many of them.
static MODULE_NOW: (Mutex<(Option<&str>, usize)>, Condvar) =
    (Mutex::new((None, 0)), Condvar::new());

/// Held by a test while it runs: see [`module_turn`].
pub struct ModuleTurn;

/// Keeps the modules apart as their own binaries kept them: the tests of one module (one former
/// test file) run beside each other, never beside another module's. A clean normal-priority `run`
/// beside another file's heavy tests stalled 47 ms in CI and tripped its safety stop (the reason
/// the first merge into one binary was reverted); this keeps what each test runs beside as it was.
/// Every test takes it first: `let _m = crate::common::module_turn(module_path!());`.
pub fn module_turn(module: &'static str) -> ModuleTurn {
    let (lock, changed) = &MODULE_NOW;
    let mut now = lock.lock().unwrap_or_else(|e| e.into_inner());
    while now.0.is_some_and(|m| m != module) {
        now = changed.wait(now).unwrap_or_else(|e| e.into_inner());
    }
    now.0 = Some(module);
    now.1 += 1;
    ModuleTurn
}

impl Drop for ModuleTurn {
    fn drop(&mut self) {
        let (lock, changed) = &MODULE_NOW;
        let mut now = lock.lock().unwrap_or_else(|e| e.into_inner());
        now.1 -= 1;
        if now.1 == 0 {
            now.0 = None;
            changed.notify_all();
        }
    }
}

/// A test's [`module_turn`] and then, within its module, the one-at-a-time [`turn`] of the tests
/// that start emulators, devices or real-time loops; released in the reverse order.
pub struct LoopTurn {
    _alone: std::sync::MutexGuard<'static, ()>,
    _module: ModuleTurn,
}

/// [`LoopTurn`] for a test of `module` (`module_path!()`).
pub fn loop_turn(module: &'static str) -> LoopTurn {
    let module = module_turn(module);
    LoopTurn {
        _alone: turn(),
        _module: module,
    }
}

/// Serialises the tests that start emulators, devices or real-time loops (within a module: see
/// [`module_turn`]), to keep the load down.
pub fn turn() -> std::sync::MutexGuard<'static, ()> {
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

/// The text of the shipped device file `devices/NAME`.
pub fn shipped_text(name: &str) -> String {
    haptic2d_test_support::files::shipped_device_text(name)
}

/// The shipped device file `devices/SHIPPED`, patient about a loaded machine's timing (its
/// `timeout_periods = FROM` line set to `TO`, the missed-deadline check off, the stall limit at 1000
/// periods: the CLI tests check protocols and exit paths, not timing), written as `NAME` into a
/// temp dir of its own (`TAG` tells the tests of one binary apart).
pub fn patient_device_file(shipped: &str, timeout: (&str, &str), tag: &str, name: &str) -> PathBuf {
    let from = format!("timeout_periods = {} ", timeout.0);
    let to = format!("timeout_periods = {}", timeout.1);
    let text = shipped_text(shipped)
        .replace(&from, &to)
        .replace("max_missed_deadlines = 10 ", "max_missed_deadlines = 0  ")
        .replace("max_stall_periods = 5 ", "max_stall_periods = 1000");
    assert!(text.contains(&to) && text.contains("max_missed_deadlines = 0 "));
    assert!(text.contains("max_stall_periods = 1000"));
    let dir = temp_dir(&format!("cli-{}", name.trim_end_matches(".toml")), tag);
    write_in(&dir, name, &text)
}

/// The shipped Haply device file `file` with the emulator tests' settings (a reply timeout of 100
/// periods, the missed-deadline check off, a stall limit of 1000 periods) and `edit` applied,
/// written as `dir/name`.
pub fn haply_file(dir: &Path, file: &str, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let text = shipped_text(file)
        .replace("timeout_periods = 20 ", "timeout_periods = 100 ")
        .replace("max_missed_deadlines = 10 ", "max_missed_deadlines = 0 ")
        .replace("max_stall_periods = 5 ", "max_stall_periods = 1000 ");
    write_in(dir, name, &edit(text))
}

/// A Haply device file's text with motor 1 said to turn CW while its encoder still counts CCW: a
/// host file that disagrees with a board wired CCW (the pulse pushes that link backwards).
pub fn motor1_flipped(text: String) -> String {
    text.replacen(
        "direction = \"ccw\"",
        "direction = \"cw\"\nencoder_direction = \"ccw\"",
        1,
    )
}

/// A Haply device file's text with motor 1 and its encoder both reversed (every angle still grows
/// under a positive torque, as on a correct board).
pub fn joint1_reversed(text: String) -> String {
    text.replacen("direction = \"ccw\"", "direction = \"cw\"", 1)
}

/// `haptic2d emulate haply --device-file FILE ARGS…`, killed on drop, and its pty path (its first
/// stdout line, `pty: PATH`).
pub fn emulate_haply(file: &Path, args: &[&str]) -> (Killed, String) {
    spawn_announced(
        Command::new(BIN)
            .args(["emulate", "haply", "--device-file"])
            .arg(file)
            .args(args)
            .stderr(std::process::Stdio::null()),
        "pty: ",
    )
}

/// Stops a child as Ctrl-C does (SIGINT) and reaps it.
pub fn interrupt(mut child: Killed) {
    signal(child.id(), "-INT");
    let _ = child.wait();
}

/// Waits (at most 60 s) until the CSV log at `log` has its first rows on disk: the run's loop has
/// been ticking for a while (the logger writes through a 64 KiB buffer, hundreds of rows).
pub fn wait_for_log_rows(log: &Path) {
    wait_for(
        &format!("rows in {}", log.display()),
        std::time::Duration::from_secs(60),
        || std::fs::metadata(log).is_ok_and(|m| m.len() > 0),
    );
}

/// Spawns `run` (a `haptic2d run` command; its CSV log is set here, at `log`), waits until its log
/// has rows (the loop is ticking: no fixed sleep), calls `cut` (silences or kills the device) and
/// waits for the run. Its exit code, its stdout and stderr, and how long it took to end after the cut.
pub fn cut_mid_run(
    mut run: Command,
    log: &Path,
    cut: impl FnOnce(),
) -> (Option<i32>, String, std::time::Duration) {
    let child = run
        .arg("--log")
        .arg(log)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut child = child;
    let ticking = std::panic::catch_unwind(|| wait_for_log_rows(log));
    if let Err(e) = ticking {
        let _ = child.kill();
        let _ = child.wait();
        std::panic::resume_unwind(e);
    }
    cut();
    let t0 = std::time::Instant::now();
    let o = child.wait_with_output().unwrap();
    (o.status.code(), text(&o), t0.elapsed())
}

/// Runs `haptic2d ARGS…` with piped output and waits at most `limit`: its exit code and stdout
/// followed by stderr. Panics if it hung (it is killed) or died by a signal (an abort?).
pub fn ends_within<S: AsRef<OsStr> + std::fmt::Debug>(
    args: &[S],
    limit: std::time::Duration,
) -> (i32, String) {
    let child = Command::new(BIN)
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let Some((status, out)) = wait_with_limit(child, limit) else {
        panic!("{args:?} hung (killed after {limit:?})");
    };
    let code = status.code().unwrap_or_else(|| {
        panic!("{args:?} was killed by a signal (an abort?) ({status}):\n{out}")
    });
    (code, out)
}

/// The first whole number `N` that stands before the word `word` ("N ticks", "N samples") in `out`.
pub fn count_of(out: &str, word: &str) -> u64 {
    out.split_whitespace()
        .collect::<Vec<_>>()
        .windows(2)
        .find(|w| w[1] == word)
        .and_then(|w| w[0].parse().ok())
        .unwrap_or_else(|| panic!("no {word} count in:\n{out}"))
}

/// The "N ticks" of a run's timing summary.
pub fn summary_ticks(out: &str) -> u64 {
    count_of(out, "ticks")
}

/// A CSV log read whole: the column index of each name (panicking on a missing one) and the rows as
/// numbers (a cell that is not a number is NaN).
pub fn csv_rows(path: &Path) -> (impl Fn(&str) -> usize, Vec<Vec<f64>>) {
    let csv = std::fs::read_to_string(path).unwrap();
    let mut lines = csv.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let col = move |n: &str| {
        header
            .iter()
            .position(|h| h == n)
            .unwrap_or_else(|| panic!("no column {n} in {header:?}"))
    };
    (col, rows)
}

/// The column `name` of a CSV text with a header line, as numbers.
pub fn column(csv: &str, name: &str) -> Vec<f64> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    lines
        .map(|l| l.split(',').nth(i).unwrap().parse().unwrap())
        .collect()
}
