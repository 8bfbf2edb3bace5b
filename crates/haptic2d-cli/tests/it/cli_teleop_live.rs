//! `haptic2d teleop --live` (issue 41 item 4, docs/TELEOP.md "Two devices in real time"): two
//! devices in one real-time loop — two simulated twins across an impaired link, a simulated master
//! driving a Haply 2DIY board emulator (`haptic2d emulate haply` on a pty), that emulator killed
//! mid-run, and the UDP reference device (devices/udp/sim_device.py) as the master of a simulated
//! slave's wall.
//!
//! The expected forces come from statics: in steady contact the operator's hand spring, the
//! coupling (500 N/m) and the wall (2 000 N/m) are in series, so the force through them is the
//! hand's free displacement past the wall over the sum of the compliances. The device files are the
//! shipped ones made patient about a loaded machine's timing (reply timeouts of 50–100 periods, the
//! missed-deadline check off, a stall limit of 1000 periods): these tests check the loop, the
//! forces and the exit paths, not the machine's timing. Normal scheduling (`--no-rt`); the tests
//! take turns.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{
    assert_has, assert_lost_device, cmd, emulate_haply, haply_file, interrupt, patient_device_file,
    root, spawn_announced, text, turn, Killed,
};

/// The number right after `key` in the first output line starting with `line` (a unit or a
/// parenthesis may follow it).
#[track_caller]
fn number(out: &str, line: &str, key: &str) -> f64 {
    let l = out
        .lines()
        .find(|l| l.starts_with(line))
        .unwrap_or_else(|| panic!("no line `{line}…` in\n{out}"));
    let i = l.find(key).unwrap_or_else(|| panic!("no `{key}` in `{l}`"));
    let rest = l[i + key.len()..].trim_start_matches([' ', '(']);
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || "+-.e".contains(c)))
        .unwrap_or(rest.len());
    rest[..end]
        .parse()
        .unwrap_or_else(|e| panic!("`{}` after `{key}` in `{l}`: {e}", &rest[..end]))
}

/// `haptic2d teleop --live --no-rt ARGS…` run to its end: exit code and output.
fn teleop(args: &[&str]) -> (Option<i32>, String) {
    let o = cmd("teleop --live --no-rt", &[])
        .args(args)
        .output()
        .unwrap();
    (o.status.code(), text(&o))
}

/// A 3 s [`teleop`] with `device` (its device file `file`) as the `end` (`master` or `slave`),
/// the other end simulated.
fn teleop_with(end: &str, device: &str, file: &Path) -> (Option<i32>, String) {
    let (e, f) = (format!("--{end}"), format!("--{end}-device-file"));
    teleop(&[&e, device, &f, file.to_str().unwrap(), "--duration", "3"])
}

/// Two simulated twins, 25 ms each way and 5 % loss each way, TDPA on: the grip's target moves
/// 15 mm left, the slave meets its wall 5 mm left. Statics: hand 300 N/m, coupling 500 N/m and
/// wall 2 000 N/m in series over (15 − 5) mm give `0.010 / (1/300 + 1/500 + 1/2000) = 1.76 N`
/// (the joint friction aside); the master must push the hand back with the wall's force (both
/// measured in the run: the wall's on the slave's simulated plant, the master's applied force),
/// and the network must create no energy.
#[test]
fn two_simulated_devices_live_across_50_ms_and_loss_feel_the_wall_and_create_no_energy() {
    let _m = crate::common::module_turn(module_path!());
    let _t = turn();
    let (code, out) = teleop(&["--delay-ms", "25", "--loss", "0.05", "--duration", "3"]);
    assert_eq!(code, Some(0), "{out}");
    assert_has(&out, &["stopped: the duration ended; no safety stop"]);
    let contact = "slave contact (simulated wall)";
    let ticks = number(&out, contact, "last second in contact");
    let wall = number(&out, contact, "): wall force");
    let felt = number(&out, contact, "master force");
    assert!(
        ticks > 500.0,
        "the slave was in the wall {ticks} of the last ticks:\n{out}"
    );
    let statics = 0.010 / (1.0 / 300.0 + 1.0 / 500.0 + 1.0 / 2000.0);
    assert!(
        felt > 1.0 && (felt - statics).abs() < 0.35,
        "felt {felt} N, statics {statics:.3} N:\n{out}"
    );
    assert!(
        (felt - wall).abs() < 0.1 * wall,
        "felt {felt} N against the wall's {wall} N:\n{out}"
    );
    let created = number(&out, "network:", "created");
    assert!(created <= 1e-3, "the network created {created} J:\n{out}");
    // Both directions of the link lost about 5 % of ~3 000 messages.
    let lost = number(&out, "link:", "master → slave");
    assert!((60.0..300.0).contains(&lost), "{lost} lost:\n{out}");
}

/// An emulated 2DIY with its hand released (`--hand free`), on the shipped gen 3 file made
/// patient (see the module doc) in a temp dir: the dir (kept while it lives), the file, the
/// emulator (killed on drop) and the device's name, `haply:PTY`.
fn free_2diy() -> (tempfile::TempDir, PathBuf, Killed, String) {
    let dir = tempfile::tempdir().unwrap();
    let file = haply_file(dir.path(), "haply-2diy-gen3.toml", "gen3.toml", |t| t);
    let (emu, pty) = emulate_haply(&file, &["--hand", "free"]);
    (dir, file, emu, format!("haply:{pty}"))
}

/// A simulated master pushed 15 mm left drives the emulated 2DIY (its hand released): with no
/// force on the slave the coupling settles at zero deflection, so the slave's handle ends where
/// the master's does, 15 mm left of its origin (the master's grip spring has nothing to push
/// against but the slave's friction; each displacement is that device's own reading).
#[test]
fn a_simulated_master_moves_an_emulated_2diy_slave_with_its_push() {
    let _m = crate::common::module_turn(module_path!());
    let _t = turn();
    let (_dir, file, emu, slave) = free_2diy();
    let (code, out) = teleop_with("slave", &slave, &file);
    interrupt(emu);
    assert_eq!(code, Some(0), "{out}");
    assert_has(&out, &[&format!("slave {slave}: "), "no safety stop"]);
    let xs = number(&out, "slave handle:", "displacement at the end");
    let xm = number(&out, "master handle:", "displacement at the end");
    assert!((xs + 15.0).abs() < 3.0, "slave at {xs} mm:\n{out}");
    assert!(
        (xs - xm).abs() < 2.0,
        "slave {xs} mm, master {xm} mm:\n{out}"
    );
}

/// The emulated 2DIY slave killed while the loop runs: the driver's read times out (a lost
/// device), the run exits 4 naming the slave, and the master's last non-zero torques were written
/// before the stop's tick, in which it got zero torques, and nothing after.
#[test]
fn the_slave_emulator_killed_mid_run_exits_4_naming_the_slave_with_the_master_zeroed() {
    let _m = crate::common::module_turn(module_path!());
    let _t = turn();
    let (_dir, file, mut emu, slave) = free_2diy();
    // The grip pushes from 0.3 s, so that the coupling pulls the slave and the master's torques
    // are non-zero well before the cut (at rest both devices read exactly still: zero force).
    let mut run = cmd(
        "teleop --live --no-rt --duration 20 --push -0.015,0,0.05,0.3 --slave",
        &[],
    );
    run.arg(&slave).arg("--slave-device-file").arg(&file);
    let (child, reader, out) = spawn_until_looping(run);
    std::thread::sleep(Duration::from_millis(1500));
    emu.kill().unwrap();
    let _ = emu.wait();
    let t0 = Instant::now();
    let (code, out) = finish(child, reader, out);
    let took = t0.elapsed();
    assert!(took < Duration::from_secs(5), "{took:?}\n{out}");
    let says = format!("the slave ({slave}) was lost");
    assert_lost_device(code, &out, &slave, &[&says]);
    let stop = number(&out, "master torques:", "zero written at the stop at t =");
    let last = number(&out, "master torques:", "last non-zero written at t =");
    assert!(stop > 1.0, "stopped at {stop} s:\n{out}");
    assert!(
        last < stop,
        "non-zero master torques at {last} s, the stop at {stop} s:\n{out}"
    );
}

/// devices/udp/sim_device.py (a 2DIY-sized five-bar, 0.15 kg, held by a 200 N/m hand spring)
/// pushed 1.5 N left from 0.6 s, as the master of the simulated slave's wall: the hand alone would
/// take it 7.5 mm left; the slave's wall is 5 mm left, so the force in steady contact is
/// `(7.5 − 5) mm / (1/200 + 1/500 + 1/2000) m/N = 0.333 N`, felt at the UDP master.
#[test]
fn a_udp_reference_master_feels_the_simulated_slaves_wall() {
    let _m = crate::common::module_turn(module_path!());
    let _t = turn();
    let file = patient_device_file(
        "udp-pantograph.toml",
        ("3", "50"),
        "teleop-live",
        "udp.toml",
    );
    let (device, addr) = udp_reference_device(&["--push=-1.5,0", "--push-after", "0.6"]);
    let master = format!("udp:{addr}");
    let (code, out) = teleop_with("master", &master, &file);
    drop(device);
    assert_eq!(code, Some(0), "{out}");
    let contact = "slave contact (simulated wall)";
    let (wall, felt) = (
        number(&out, contact, "): wall force"),
        number(&out, contact, "master force"),
    );
    let statics = 0.0025 / (1.0 / 200.0 + 1.0 / 500.0 + 1.0 / 2000.0);
    assert!(
        (felt - statics).abs() < 0.1,
        "felt {felt} N, statics {statics:.3} N:\n{out}"
    );
    // The wall's force reaches the master less the slave twin's joint friction (0.33 N felt
    // against a 0.385 N wall in one run): both within 0.1 N of the statics.
    assert!(
        (wall - statics).abs() < 0.1,
        "wall {wall} N, statics {statics:.3} N:\n{out}"
    );
}

/// The UDP reference device on an ephemeral loopback port with `args` (killed on drop), and its
/// address; without python3 the test fails with the install hint.
fn udp_reference_device(args: &[&str]) -> (Killed, String) {
    let found = Command::new("python3")
        .arg("--version")
        .stdout(Stdio::null())
        .status();
    assert!(
        found.is_ok(),
        "python3 not found: this test needs it (bash scripts/install-test-deps.sh installs it)"
    );
    let mut c = Command::new("python3");
    c.arg(root().join("devices/udp/sim_device.py"))
        .args(["--bind", "127.0.0.1:0", "--no-rt"])
        .args(args)
        .stderr(Stdio::null());
    spawn_announced(&mut c, "listening on ")
}

/// `run` (a `haptic2d teleop --live` command) spawned with its output piped, returned once its
/// loop is about to run (its start line read, printed once both devices are open), with what it
/// printed so far.
fn spawn_until_looping(
    mut run: Command,
) -> (
    std::process::Child,
    BufReader<std::process::ChildStdout>,
    String,
) {
    let mut child = run
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut reader = BufReader::new(child.stdout.take().unwrap());
    let mut out = String::new();
    while !out.contains("teleop live:") {
        let n = reader.read_line(&mut out).unwrap();
        assert!(n > 0, "the run ended before its loop started:\n{out}");
    }
    (child, reader, out)
}

/// Two simulated twins for 10 s, spawned as [`spawn_until_looping`], sent each `(ms, SIGNAL)`
/// of `signals` in turn `ms` after the one before (the first after the start line), run to their
/// end: exit code and output.
fn two_sims_signalled(signals: &[(u64, &str)]) -> (Option<i32>, String) {
    let (child, reader, out) = spawn_until_looping(cmd("teleop --live --no-rt --duration 10", &[]));
    for (ms, sig) in signals {
        std::thread::sleep(Duration::from_millis(*ms));
        assert!(crate::common::signal(child.id(), sig), "{sig}");
    }
    finish(child, reader, out)
}

/// The rest of `child`'s output after `out` (stdout then stderr) and its exit code.
fn finish(
    mut child: std::process::Child,
    mut reader: BufReader<std::process::ChildStdout>,
    mut out: String,
) -> (Option<i32>, String) {
    reader.read_to_string(&mut out).unwrap();
    let status = child.wait().unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    out.push_str(&err);
    (status.code(), out)
}

/// The whole process stopped (SIGSTOP) for 300 ms mid-run: the loop's next tick sees a stall
/// far past the simulated devices' 40 ms limit; the latch at one end zeroes both devices in that
/// same tick (each end's zero torques written at the stop's time, its last non-zero ones before),
/// and the run exits 3 saying why.
#[test]
fn a_stalled_loop_latches_and_zeroes_both_devices_in_the_same_tick() {
    let _m = crate::common::module_turn(module_path!());
    let _t = turn();
    let (code, out) = two_sims_signalled(&[(1000, "-STOP"), (300, "-CONT")]);
    assert_eq!(code, Some(3), "{out}");
    assert_has(&out, &["latched at t =", "stalled"]);
    let at = |end: &str, key: &str| number(&out, &format!("{end} torques:"), key);
    let (zm, zs) = (
        at("master", "at the stop at t ="),
        at("slave", "at the stop at t ="),
    );
    assert_eq!(
        zm, zs,
        "the two ends were zeroed in different ticks:\n{out}"
    );
    for end in ["master", "slave"] {
        assert!(
            at(end, "last non-zero written at t =") < zm,
            "{end}:\n{out}"
        );
    }
}

/// Ctrl-C (SIGINT) mid-run: the loop ends, both devices get zero torques, exit 130.
#[test]
fn ctrl_c_ends_the_live_run_with_both_devices_at_zero() {
    let _m = crate::common::module_turn(module_path!());
    let _t = turn();
    let (code, out) = two_sims_signalled(&[(800, "-INT")]);
    assert_eq!(code, Some(130), "{out}");
    assert_has(
        &out,
        &[
            "stopped: interrupted by a signal",
            "torques of both devices set to zero",
        ],
    );
}

/// What `--live` refuses, before anything opens: four channels (no device has a force sensor at
/// its handle: exit 2 with the reason); a master that cannot be opened is a lost device (exit 4,
/// as `run`), named by its option.
#[test]
fn four_channels_are_refused_live_and_a_device_that_cannot_open_is_lost() {
    let _m = crate::common::module_turn(module_path!());
    let (code, out) = teleop(&["--architecture", "four-channel"]);
    assert_eq!(code, Some(2), "{out}");
    assert_has(&out, &["no force sensor at the handle"]);
    let (code, out) = teleop(&["--master", "haply:/dev/null"]);
    assert_eq!(code, Some(4), "{out}");
    assert_has(&out, &["--master haply:/dev/null: cannot open"]);
}
