//! A printing command whose reader has gone (`haptic2d simulate … | head -1`) ends quietly of
//! `SIGPIPE`, as `cat` does, instead of panicking in `println!` (found in session 4).

use std::os::unix::process::ExitStatusExt;
use std::process::{Command, Stdio};

/// Runs `haptic2d args` with stdout on a pipe whose read end is already closed, so the first write
/// fails with `EPIPE`; returns (signal that ended it, stderr).
fn run_into_closed_pipe(args: &[&str]) -> (Option<i32>, Option<i32>, String) {
    // Both ends are close-on-exec (`std::io::pipe`): a child that another test of this binary
    // spawns meanwhile inherits neither, so no other process holds a read end open.
    let (reader, writer) = std::io::pipe().expect("pipe(2)");
    drop(reader);
    let stdout = Stdio::from(writer);
    let out = Command::new(env!("CARGO_BIN_EXE_haptic2d"))
        .args(args)
        .stdout(stdout)
        .stderr(Stdio::piped())
        .output()
        .expect("haptic2d runs");
    (
        out.status.signal(),
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn printing_commands_end_quietly_when_the_reader_closes_the_pipe() {
    let _m = crate::common::module_turn(module_path!());
    for args in [
        &["scenes"][..],
        &["simulate", "box-in-walls", "--duration", "0.1"][..],
        &["check", "box-in-walls"][..],
    ] {
        let (signal, code, stderr) = run_into_closed_pipe(args);
        assert!(!stderr.contains("panicked"), "{args:?} panicked:\n{stderr}");
        assert_eq!(
            signal,
            Some(libc::SIGPIPE),
            "{args:?}: expected to end of SIGPIPE, got exit code {code:?}\n{stderr}"
        );
    }
}

#[test]
fn run_ends_quietly_of_sigpipe_after_finishing_its_log_when_the_reader_is_gone() {
    let _m = crate::common::module_turn(module_path!());
    // `haptic2d run … | head -1` panicked with exit 101 (issue 39); the run now finishes as it
    // would (torques zeroed, the MCAP log's footer written), then ends of SIGPIPE (shell 141).
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.mcap");
    let (signal, code, stderr) = run_into_closed_pipe(&[
        "run",
        "--headless",
        "--no-rt",
        "--duration",
        "0.3",
        "--log",
        log.to_str().unwrap(),
    ]);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(signal, Some(libc::SIGPIPE), "exit code {code:?}\n{stderr}");
    let bytes = haptic2d_rt::mcap::reader::read_file(&log).unwrap();
    let info = haptic2d_rt::mcap::reader::read_info(&bytes, "run.mcap").unwrap();
    assert!(info.complete, "the log has its footer: {info:?}");
    assert!(
        info.metadata("haptic2d.timing").is_some(),
        "and the timing summary"
    );
}
