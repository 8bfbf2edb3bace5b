//! `haptic2d run --device inverse3:URL` against `haptic2d emulate inverse3` in another process, on
//! loopback (issue 15): a clean 3 s run with the box pushed into the wall, the emulator killed
//! mid-run (exit 4, a message naming the device and what to check, no panic), and clear errors for
//! a bad URL and no service.
//!
//! The device file is the shipped one with the missed-deadline check off and the stall limit at
//! 1000 periods: the tests run on machines shared with compilers and check the protocol and the
//! exit paths, not the timing (the timeout is exercised by the driver tests in haptic2d-devices).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use crate::common::{
    assert_has, assert_lacks, assert_lost_device, cmd, column, cut_mid_run, expect_exit,
    patient_device_file, spawn_announced, text, Killed,
};

/// The shipped file, patient about the machine's timing, in a temp dir.
fn device_file(tag: &str) -> PathBuf {
    patient_device_file("inverse3.toml", ("20", "100"), tag, "inverse3.toml")
}

/// `haptic2d emulate inverse3` on an ephemeral loopback port (killed on drop); its service URL.
fn emulator(extra: &[&str]) -> (Killed, String) {
    let (child, url) = spawn_announced(
        cmd("emulate inverse3 --bind 127.0.0.1:0", &[])
            .args(extra)
            .stderr(Stdio::null()),
        "listening: ",
    );
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");
    (child, url)
}

fn run(url: &str, file: &Path, duration: &str) -> Command {
    let device = format!("inverse3:{url}");
    let mut c = cmd("run --device {} --device-file {}", &[&device, &file]);
    c.args(["--headless", "--no-rt", "--duration", duration]);
    c
}

/// A 3 s `run --controller coupling` against an emulator started with `emu_args` (killed after),
/// logged into the temp dir of the device file `tag`: the run's output (asserted to exit 0) and the
/// log's path.
#[track_caller]
fn coupling_run(emu_args: &[&str], tag: &str) -> (String, PathBuf) {
    let emu = emulator(emu_args);
    let file = device_file(tag);
    let log = file.with_file_name("run.csv");
    let o = run(&emu.1, &file, "3")
        .args(["--controller", "coupling", "--log"])
        .arg(&log)
        .output()
        .unwrap();
    (expect_exit(&o, 0, &[]), log)
}

/// The VerseGrip's orientation turns the slave (issue 15: "θ comes from the handle's orientation
/// where the service reports one"): the emulated grip turns at 0.3 rad/s while the hand holds the
/// cursor still, the loop makes the grip's turn since the first reading the slave's twist target, and
/// the free box (no contact: it starts 0.02 m from the wall) follows it through the torsion spring.
/// After 3 s the grip has turned about 0.9 rad; the box, behind it by the spring's lag and the
/// start-up ramp, has turned more than half of that and not past it.
#[test]
fn a_turning_versegrip_turns_the_slave() {
    let _turn = crate::common::loop_turn(module_path!());
    let (_, log) = coupling_run(&["--grip-rate", "0.3"], "grip");
    let theta = column(&std::fs::read_to_string(&log).unwrap(), "slave.theta");
    let end = *theta.last().unwrap();
    assert!(theta[0].abs() < 1e-6, "starts at {}", theta[0]);
    assert!(
        (0.45..0.95).contains(&end),
        "slave angle {end} rad after 3 s"
    );
    // It turned steadily one way: never back by more than 0.05 rad.
    let mut top = f64::MIN;
    for &t in &theta {
        top = top.max(t);
        assert!(t > top - 0.05, "turned back: {t} after {top}");
    }
    let _ = std::fs::remove_dir_all(log.parent().unwrap());
}

#[test]
fn run_against_the_emulated_service_for_3_s_drives_the_box_into_the_wall() {
    let _turn = crate::common::loop_turn(module_path!());
    // The hand holds for 0.5 s, then pushes 0.8 N towards the left wall (the box starts 0.02 m
    // from it, grasped at its centre: the cursor must travel 0.02 m to the contact).
    let (out, log) = coupling_run(&["--hand", "push:-0.8,0,0,0.5"], "clean");
    assert_has(&out, &["planar: world x = device x"]);
    assert_lacks(&out, &["panicked"]);
    let (col, rows) = crate::common::csv_rows(&log);
    let (xs, contacts) = (col("slave.x"), col("contacts"));
    assert!(rows.len() > 1500, "{} rows", rows.len());
    let last = &rows[rows.len() - 300..];
    assert!(
        last.iter().all(|r| r[contacts] > 0.0),
        "the box is not at the wall at the end"
    );
    let slave = last.iter().map(|r| r[xs]).sum::<f64>() / last.len() as f64;
    assert!((slave - 0.02).abs() < 2e-3, "box centre at {slave} m");
    let _ = std::fs::remove_dir_all(log.parent().unwrap());
}

#[test]
fn service_killed_mid_run_exits_4_naming_the_device() {
    let _turn = crate::common::loop_turn(module_path!());
    let mut emu = emulator(&[]);
    let file = device_file("kill");
    let log = file.with_file_name("kill.csv");
    let (code, out, _) = cut_mid_run(run(&emu.1, &file, "10"), &log, || emu.0.kill().unwrap());
    let device = format!("inverse3:{}", emu.1);
    assert_lost_device(code, &out, &device, &["check:", "Inverse Service"]);
}

/// Regression (issue 34, finding 9): a service state without a cursor position was read as
/// (0, 0, 0), the handle jumped 20 mm and the run exited 0. It is a lost device: exit 4, the
/// message names the missing field.
#[test]
fn a_state_without_a_cursor_position_exits_4_naming_the_field() {
    let _turn = crate::common::loop_turn(module_path!());
    let emu = emulator(&["--drop-position-after", "1500"]);
    let file = device_file("noposition");
    let o = run(&emu.1, &file, "10").output().unwrap();
    let out = expect_exit(&o, 4, &["state.cursor_position", "zero force latched"]);
    assert!(!out.contains("panicked"), "{out}");
}

#[test]
fn no_service_and_bad_urls_are_clear_errors() {
    let _turn = crate::common::loop_turn(module_path!());
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let file = device_file("none");
    let o = run(&format!("http://127.0.0.1:{port}"), &file, "1")
        .output()
        .unwrap();
    let out = text(&o);
    // A device that cannot be opened is the device-lost exit code, as for every driver.
    assert_eq!(o.status.code(), Some(4), "{out}");
    assert!(out.contains("haptic2d emulate inverse3"), "{out}");
    assert!(!out.contains("panicked"), "{out}");
    let o = crate::common::run(
        "run --device inverse3:nonsense --headless --duration 1",
        &[],
    );
    expect_exit(&o, 2, &["inverse3:http://HOST:PORT"]);
    let o = crate::common::run("emulate inverse3 --bind nowhere", &[]);
    expect_exit(&o, 2, &["--bind"]);
}
