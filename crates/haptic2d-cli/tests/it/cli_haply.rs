//! `haptic2d emulate haply` in one process and `haptic2d run --device haply:PTY` (or `device check`)
//! in another, over a real pseudo-terminal (issue 12).
//!
//! The device files used here are the shipped gen 3 file with a reply timeout of 100 periods: the
//! tests run on machines shared with compilers, and what they check is the protocol and the exit
//! paths, not the timing (the default 3 periods is exercised by the driver tests), with the
//! watchdog's missed-deadline check off (`max_missed_deadlines = 0`) and a stall limit of 1000
//! periods for the same reason (an unprivileged loop on a loaded machine can sleep 10 ms past a
//! deadline; the stall check itself is tested in `run_rig`'s unit tests on synthetic tick times). The tests
//! take turns (one emulator at a time) to keep the load down.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use crate::common::{
    assert_has, assert_lacks, assert_lost_device, cmd, column, cut_mid_run, emulate_haply,
    expect_exit, haply_file, interrupt, joint1_reversed, motor1_flipped, run, run_ok, signal, text,
    turn,
};

/// The gen 3 file with the test settings and `edit` applied, written into `dir`.
fn device_file(dir: &Path, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
    haply_file(dir, "haply-2diy-gen3.toml", name, edit)
}

/// The twin's shipped file with the test settings, written into `dir` as `name`.
fn twin_file(dir: &Path, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
    haply_file(dir, "haply-twin.toml", name, edit)
}

/// `haptic2d run` on the emulated board at `pty` with device file `file`, headless, normal
/// scheduling, for `duration` seconds; callers add their own options.
fn haply_run(pty: &str, file: &Path, duration: &str) -> Command {
    let device = format!("haply:{pty}");
    let mut c = cmd("run --device {} --device-file {}", &[&device, &file]);
    c.args(["--headless", "--duration", duration, "--no-rt"]);
    c
}

/// A `haptic2d run` of `secs` seconds against the emulator started on `file` with `emu_args`,
/// logged to `dir/run.csv`, which must end clean: the pty, the run's output and the log's text.
#[track_caller]
fn clean_logged_run(
    dir: &Path,
    file: &Path,
    emu_args: &[&str],
    secs: &str,
) -> (String, String, String) {
    let (emu, pty) = emulate_haply(file, emu_args);
    let log = dir.join("run.csv");
    let o = haply_run(&pty, file, secs)
        .arg("--log")
        .arg(&log)
        .output()
        .unwrap();
    interrupt(emu);
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    (pty, out, std::fs::read_to_string(&log).unwrap())
}

#[test]
fn run_against_the_emulator_for_3_s_logs_and_exits_clean() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let file = device_file(dir.path(), "gen3.toml", |t| t);
    let (pty, out, csv) = clean_logged_run(dir.path(), &file, &[], "3");
    assert_has(&out, &[&format!("device haply:{pty}"), "on time:"]);
    // The stock firmware has no watchdog: said once, at start (issue 34 finding 3).
    assert_eq!(
        out.matches("warning: this board's firmware has no watchdog")
            .count(),
        1,
        "{out}"
    );
    let rows = csv.lines().count() - 1;
    assert!(rows > 500, "only {rows} rows logged:\n{out}");
}

/// A 20 s run against the emulated gen 3 board, cut once its loop is ticking (its log has rows):
/// `cut` silences the emulator. The pty, the run's exit code and its output; the run ends within 5 s
/// of the cut (asserted).
fn run_then_cut(cut: impl FnOnce(&mut crate::common::Killed)) -> (String, Option<i32>, String) {
    let _turn = turn();
    let dir = tempfile::tempdir().unwrap();
    let file = device_file(dir.path(), "gen3.toml", |t| t);
    let (mut emu, pty) = emulate_haply(&file, &[]);
    let log = dir.path().join("cut.csv");
    let (code, out, took) = cut_mid_run(haply_run(&pty, &file, "20"), &log, || cut(&mut emu));
    assert!(took < Duration::from_secs(5), "took {took:?}\n{out}");
    (pty, code, out)
}

#[test]
fn emulator_killed_mid_run_exits_4_naming_the_device() {
    let _m = crate::common::module_turn(module_path!());
    let (pty, code, out) = run_then_cut(|emu| {
        emu.kill().unwrap();
        let _ = emu.wait();
    });
    let device = format!("haply:{pty}");
    assert_lost_device(code, &out, &device, &["check", "torques were set to zero"]);
    // The lost reading is not reported as a second fault.
    assert_lacks(&out, &["non-finite device input"]);
}

/// `device check FILE --pulse` against an emulator of `board` (started for it, at the rest pose),
/// which must exit with `code` and say every one of `needles`: its output.
#[track_caller]
fn device_check(board: &Path, file: &Path, code: i32, needles: &[&str]) -> String {
    let (emu, pty) = emulate_haply(board, &[]);
    let device = format!("haply:{pty}");
    let o = run(
        "device check --device {} --pulse --device-file {}",
        &[&device, &file],
    );
    interrupt(emu);
    expect_exit(&o, code, needles)
}

/// Issue 34 finding 1: against a board that sets its encoders at setup, `device check` said "far
/// outside the workspace" (exit 2) on every correctly wired board. Held at the rest pose (the
/// emulator's default start), a correct board now passes, and the check says which firmware it is.
#[test]
fn device_check_passes_on_a_correct_board_held_at_rest_and_finds_a_flipped_motor() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let good = device_file(dir.path(), "gen3.toml", |t| t);
    let passes = [
        "rest pose: end point (0.0190 m, 0.0357 m)",
        "ok:",
        "stock firmware",
        "no watchdog",
    ];
    device_check(&good, &good, 0, &passes);
    // The host's file says motor 1 turns CW (its encoder still CCW): the emulated board (a fresh
    // one, at the rest pose), wired CCW, pushes that link backwards.
    let flipped = device_file(dir.path(), "flipped.toml", motor1_flipped);
    let fix = [
        "fix: motor[0] turns its link clockwise",
        "flip motor[0].direction",
    ];
    device_check(&good, &flipped, 2, &fix);
}

/// Issue 34 finding 8: a joint whose motor AND encoder are both reversed read "+" like a correct
/// one. The other joint's motion under the pulse (the five-bar's coupling) now tells them apart.
#[test]
fn device_check_tells_a_reversed_motor_and_encoder_from_a_correct_joint() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let good = device_file(dir.path(), "gen3.toml", |t| t);
    // The emulated board is wired with motor 1 and its encoder both reversed against the file.
    let board = device_file(dir.path(), "board.toml", joint1_reversed);
    let both = ["motor[0]'s motor AND encoder are both reversed"];
    let out = device_check(&board, &good, 2, &both);
    // Both joints' angles still grow under a positive torque, as on a correct board.
    assert_eq!(out.matches("angle +").count(), 2, "{out}");
}

/// The twin's pulse check: a correct board passes; with q11's motor and encoder both reversed every
/// angle still grows, and the closure of the readings under the pulses gives it away.
#[test]
fn device_check_on_the_twin_finds_a_joint_with_motor_and_encoder_reversed() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let good = twin_file(dir.path(), "twin.toml", |t| t);
    device_check(&good, &good, 0, &[]);
    let board = twin_file(dir.path(), "board.toml", joint1_reversed);
    let closure = [
        "no longer describe one rigid handle",
        "under motor[0]'s pulse",
    ];
    let out = device_check(&board, &good, 2, &closure);
    assert_eq!(out.matches("angle +").count(), 4, "{out}");
}

/// Issue 34 finding 4 / item 7: the twin on an M0 ended with "check the USB cable" although the
/// board answered. It is refused at open, naming the port count, before any torque.
#[test]
fn twin_on_an_m0_board_is_refused_naming_the_port_count() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let file = twin_file(dir.path(), "twin.toml", |t| t);
    let (emu, pty) = emulate_haply(&file, &["--board", "m0"]);
    let o = haply_run(&pty, &file, "1").output().unwrap();
    interrupt(emu);
    let out = expect_exit(&o, 4, &["M0 board has 2 ports", "ports 1–4"]);
    assert_lacks(&out, &["USB cable"]);
}

#[test]
fn missing_port_and_bad_device_file_are_clear_errors() {
    let _m = crate::common::module_turn(module_path!());
    let o = run(
        "run --device haply:/dev/no-such-board --headless --duration 1",
        &[],
    );
    let out = text(&o);
    assert!(
        !o.status.success() && out.contains("/dev/no-such-board") && out.contains("check"),
        "{out}"
    );
    let dir = tempfile::tempdir().unwrap();
    let bad = device_file(dir.path(), "bad.toml", |t| {
        t.replace("torque_limit = 0.123", "torque_limit = 0.4")
    });
    let o = run(
        "run --device haply:/dev/null --headless --device-file {}",
        &[&bad],
    );
    let out = expect_exit(&o, 2, &["board.torque_limit", "N·m"]);
    assert_lacks(&out, &["panicked"]);
}

#[test]
fn devices_lists_ports_without_failing() {
    let _m = crate::common::module_turn(module_path!());
    run_ok("devices", &[]);
}

/// Task L item 1: the Haply board runs in the one loop of `run` — its CSV log has the same columns
/// as the simulated device's, the torques start at exactly zero and ramp in (a hand push on the
/// emulated handle after the ramp makes them grow), and every torque stays within the device file's
/// limit.
#[test]
fn haply_run_is_the_normal_loop_torques_start_at_zero_ramp_in_and_stay_clamped() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let file = device_file(dir.path(), "gen3.toml", |t| t);
    let (_, out, csv) = clean_logged_run(
        dir.path(),
        &file,
        &[
            // The user holds the handle at the rest pose while the board is set up (docs/DEVICES.md
            // §7) and through the 0.5 s ramp, then pushes 0.5 N along x: a push from t = 0 would move
            // the handle during the setup (refused by the rest-pose check) or run the free handle past
            // the workspace edge while the wall's torques are still ramping in (a safety stop).
            "--hand",
            "script:0.8,0.5,0,0,5",
        ],
        "1.5",
    );
    let header = csv.lines().next().unwrap();
    assert!(
        header.starts_with("t,") && header.contains("tau1"),
        "{header}"
    );
    let (t1, t2) = (column(&csv, "tau1"), column(&csv, "tau2"));
    assert_eq!((t1[0], t2[0]), (0.0, 0.0), "first tick's torques");
    let peak = |a: &[f64], b: &[f64]| a.iter().chain(b).fold(0.0f64, |m, v| m.max(v.abs()));
    // Every torque within the limit; the 2DIY's τ3, τ4 are zero.
    assert!(peak(&t1, &t2) <= 0.123 + 1e-9, "{}", peak(&t1, &t2));
    assert_eq!(peak(&column(&csv, "tau3"), &column(&csv, "tau4")), 0.0);
    // The ramp: the first 50 ms carry far less torque than the time after the 0.5 s ramp.
    let n = t1.len();
    assert!(n > 600, "only {n} rows:\n{out}");
    let early = peak(&t1[..50], &t2[..50]);
    let late = peak(&t1[600..], &t2[600..]);
    assert!(
        late > 0.0 && early < 0.25 * late,
        "early {early}, late {late}"
    );
}

/// Task L item 2: a silent device (the emulator stopped with SIGSTOP: the port stays open, nothing
/// answers) is the driver's read timeout → zero torques, exit 4, a message naming the device and
/// what to check — not a stall.
#[test]
fn a_silent_emulated_device_exits_4_with_the_reason() {
    let _m = crate::common::module_turn(module_path!());
    let (pty, code, out) = run_then_cut(|emu| {
        // Stopped, then resumed and killed when the guard drops.
        signal(emu.id(), "-STOP");
    });
    let device = format!("haply:{pty}");
    let says = [
        "emulator on a pseudo-terminal (no USB cable)",
        "the device was late",
        "torques were set to zero",
    ];
    assert_lost_device(code, &out, &device, &says);
    assert_lacks(&out, &["stalled"]);
}

/// Task L items 1 and 3: the twin pantograph of two 2DIY linkages (4 ports) through the one loop of
/// `run`, against the emulated twin pushed by a constant hand: a clean run, all four motors driven,
/// every torque within the limit.
#[test]
fn twin_runs_through_the_normal_loop_against_the_emulator() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let file = twin_file(dir.path(), "twin.toml", |t| t);
    let hand = ["--hand", "script:0.8,0.3,0,0,100"];
    let (_, out, csv) = clean_logged_run(dir.path(), &file, &hand, "1.5");
    assert_has(&out, &["twin pantograph"]);
    let taus: Vec<Vec<f64>> = ["tau1", "tau2", "tau3", "tau4"]
        .iter()
        .map(|c| column(&csv, c))
        .collect();
    for (i, t) in taus.iter().enumerate() {
        assert_eq!(t[0], 0.0, "tau{} of the first tick", i + 1);
        let peak = t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            peak > 0.0 && peak <= 0.123 + 1e-9,
            "tau{}: peak {peak}",
            i + 1
        );
    }
}

/// Task L item 4: `haptic2d stability` on a 2DIY device file gives the x and y verdicts of the 2-DOF
/// device (no θ axis): the default four-channel controller is stable, the paper's gains are not
/// with the hand released.
#[test]
fn stability_of_the_2diy_is_per_axis_x_and_y() {
    let _m = crate::common::module_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let file = crate::common::root().join("devices/haply-2diy-gen3.toml");
    let run = |controller: &str| {
        let line = format!("stability --device-file {{}} --controller {controller} --out {{}}");
        run_ok(&line, &[&file, &dir.path()])
    };
    let out = run("four-channel");
    assert_has(&out, &["2-DOF device", "axis x", "axis y"]);
    assert_lacks(&out, &["axis theta"]);
    assert_eq!(out.matches("verdict: stable").count(), 2, "{out}");
    let out = run("four-channel-spec");
    assert_eq!(
        out.matches("UNSTABLE with the hand released").count(),
        2,
        "{out}"
    );
}

/// Task L item 4: `run` refuses to drive a real 2DIY with a configuration that is unstable with the
/// hand released (exit 2, nothing opened), unless `--allow-unstable`.
#[test]
fn run_refuses_an_unstable_released_configuration_on_a_haply_board() {
    let _turn = crate::common::loop_turn(module_path!());
    let dir = tempfile::tempdir().unwrap();
    let file = device_file(dir.path(), "gen3.toml", |t| t);
    let (emu, pty) = emulate_haply(&file, &[]);
    let args = |extra: &[&str]| {
        haply_run(&pty, &file, "0.5")
            .args(["--controller", "four-channel-spec"])
            .args(extra)
            .output()
            .unwrap()
    };
    expect_exit(&args(&[]), 2, &["unstable on axis", "--allow-unstable"]);
    let o = args(&["--allow-unstable"]);
    interrupt(emu);
    let out = text(&o);
    assert!(out.contains("running box-in-walls"), "{out}");
}
