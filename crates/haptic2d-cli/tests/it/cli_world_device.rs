//! Real devices at either end of the split loop (issue 41), three processes over loopback each:
//! - the device side on a real device: `haptic2d run --device haply:PTY --world udp:…` against
//!   `haptic2d emulate haply` (a 2DIY with Haply's stock firmware on a pseudo-terminal, as
//!   DEVICES.md describes it), or `--device udp:…` against the reference UDP device, and a
//!   `haptic2d serve-world` of a scene;
//! - two devices in bilateral teleoperation across the network: `haptic2d serve-world --device
//!   udp:…` (the slave) and `haptic2d run --device sim --world udp:…` (the master).
//!
//! Either end runs its device as a `DeviceEnd`, the same safety stage as every device's in `run`.
//! The tests take turns (`common::turn`): each starts devices at real-time priority (the emulator,
//! the reference UDP device), and two such sets on a 2-core machine starve the unprivileged loops
//! beside them (a 2DIY reply 100 ms late, measured).
//!
//! The world side's coupling is softened for the 2DIY (100 N/m, 0.5 N·s/m: its handle is about
//! 0.03 kg, against the twin's 0.4 kg for which the defaults are set; docs/TELEOP.md). Timing
//! settings are patient, as in the other device tests: the tests check the link, the energy and
//! the exit paths, not the machine's timing.

use std::path::Path;
use std::process::{Child, Command};
use std::time::Duration;

use crate::cli_teleop::{key_file, number, World};
use crate::common::{assert_has, assert_lost_device, emulate_haply, haply_file, wait_with_limit};

const BIN: &str = env!("CARGO_BIN_EXE_haptic2d");

/// The world side's coupling softened for the 2DIY and the UDP five-bar, and the patient link
/// timeout of the tests.
const SOFT: [&str; 10] = [
    "--coupling-k",
    "100",
    "100",
    "1",
    "--coupling-b",
    "0.5",
    "0.5",
    "0.01",
    "--link-timeout-ms",
    "300",
];

/// A world side on the near-wall scene with the softer coupling.
fn world(key: &Path) -> World {
    World::start(key, &SOFT)
}

/// `haptic2d run DEVICE… --world udp:… --key KEY --duration SECS` with the tests' patient timing,
/// `extra` appended: a device side.
fn run_side(device: &[&str], world: &World, key: &Path, secs: &str, extra: &[&str]) -> Child {
    Command::new(BIN)
        .arg("run")
        .args(device)
        .args(["--world", &format!("udp:{}", world.addr), "--key"])
        .arg(key)
        .args(["--duration", secs, "--no-rt", "--link-timeout-ms", "300"])
        .args(["--max-stall-periods", "100"])
        .args(extra)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// The device side on `device` (`haply:PTY`, `udp:ADDR:PORT`; device file `file`) for `secs` seconds.
fn device_side(device: &str, file: &Path, world: &World, key: &Path, secs: &str) -> Child {
    let file = file.to_str().unwrap();
    run_side(
        &["--device", device, "--device-file", file],
        world,
        key,
        secs,
        &[],
    )
}

/// What every device side must show: a clean exit with no safety stop, no energy created, the
/// plant's ledger said to be unknown (a real device), the session closed by the device side.
#[track_caller]
fn assert_clean_and_passive(status: std::process::ExitStatus, out: &str, world_out: &str) {
    let all = format!("{out}\n{world_out}");
    assert_eq!(status.code(), Some(0), "{all}");
    assert_has(out, &["no safety stop"]);
    let created = number(out, "network: energy created", "created ");
    assert!(created <= 1e-3, "network created {created} J\n{all}");
    assert_has(out, &["master port (plant, true displacement): not known"]);
    assert!(
        world_out.contains("the device side closed the session"),
        "{all}"
    );
}

/// What a device side pushed by its hand must show besides: the handle moved, the world's body
/// followed and the coupling's reaction came back and was rendered by the device's motors.
#[track_caller]
fn assert_rendered(out: &str, world_out: &str) {
    let all = format!("{out}\n{world_out}");
    let excursion = number(out, "handle: largest excursion", "excursion ");
    assert!(excursion > 3.0, "excursion {excursion} mm\n{all}");
    let felt = number(out, "link: ", "largest force on the handle ");
    assert!(felt > 0.2, "largest force on the handle {felt} N\n{all}");
    let coupling = number(world_out, "link: ", "largest coupling force ");
    assert!(coupling > 0.2, "{all}");
}

#[test]
fn a_udp_device_on_the_device_side_renders_the_world_and_the_link_stays_passive() {
    let _m = crate::common::module_turn(module_path!());
    let _t = crate::common::turn();
    let file = crate::cli_udp::device_file("world-side");
    // The reference five-bar's hand pushes 1 N along +y from 0.6 s after the first command.
    let dev = crate::cli_udp::sim_device(&["--push", "0,1", "--push-after", "0.6"]);
    let key = key_file("udp-device", 0x3e);
    let w = world(&key);
    let name = format!("udp:{}", dev.1);
    let child = device_side(&name, &file, &w, &key, "3");
    let (status, out) = wait_with_limit(child, Duration::from_secs(60)).expect("ends in time");
    drop(dev);
    let world_out = w.finish(Duration::from_secs(10));
    assert_has(&out, &["device side: session", &name]);
    assert_clean_and_passive(status, &out, &world_out);
    assert_rendered(&out, &world_out);
}

#[test]
fn a_2diy_board_on_the_device_side_runs_clean_and_the_link_stays_passive() {
    let _m = crate::common::module_turn(module_path!());
    let _t = crate::common::turn();
    let dir = tempfile::tempdir().unwrap();
    let file = haply_file(dir.path(), "haply-2diy-gen3.toml", "gen3.toml", |t| t);
    // The emulated hand holds the handle at its rest pose (where the board is set up). A scripted
    // push is left out here: on the emulated 2DIY it also ends in safety stops with a local world
    // (docs/TELEOP.md, "Choose the coupling for the device"); the UDP test above pushes.
    let (emu, pty) = emulate_haply(&file, &[]);
    let key = key_file("board", 0x3c);
    let w = world(&key);
    let child = device_side(&format!("haply:{pty}"), &file, &w, &key, "3");
    let (status, out) = wait_with_limit(child, Duration::from_secs(60)).expect("ends in time");
    drop(emu);
    let world_out = w.finish(Duration::from_secs(10));
    assert_has(&out, &[&format!("haply:{pty}"), "2DIY"]);
    assert_clean_and_passive(status, &out, &world_out);
}

#[test]
fn a_2diy_board_lost_mid_run_latches_zero_torques_and_exits_4_naming_it() {
    let _m = crate::common::module_turn(module_path!());
    let _t = crate::common::turn();
    let dir = tempfile::tempdir().unwrap();
    let file = haply_file(dir.path(), "haply-2diy-gen3.toml", "gen3.toml", |t| t);
    let (mut emu, pty) = emulate_haply(&file, &[]);
    let key = key_file("board-lost", 0x3d);
    let w = world(&key);
    let child = device_side(&format!("haply:{pty}"), &file, &w, &key, "20");
    // The loop is ticking once the world side has a session; then the board goes.
    let t0 = std::time::Instant::now();
    std::thread::sleep(Duration::from_millis(1500));
    emu.kill().unwrap();
    let _ = emu.wait();
    let (status, out) = wait_with_limit(child, Duration::from_secs(30)).expect("ends in time");
    let world_out = w.finish(Duration::from_secs(10));
    let all = format!("{out}\n{world_out}");
    assert!(t0.elapsed() < Duration::from_secs(10), "{all}");
    assert_lost_device(
        status.code(),
        &all,
        &format!("haply:{pty}"),
        &["torques set to zero and latched"],
    );
    assert_has(&out, &["device lost"]);
    // The world hears of it: the device side says goodbye with the latch flag.
    assert!(
        world_out.contains("the device side closed the session"),
        "{all}"
    );
}

/// The reference UDP five-bar as the slave of a `serve-world --device` (the 2DIY's soft coupling,
/// `extra` appended), and the key.
fn slave_world(
    dev: &crate::cli_udp::Device,
    tag: &str,
    extra: &[&str],
) -> (World, std::path::PathBuf) {
    let file = crate::cli_udp::device_file(tag);
    let key = key_file(tag, 0x3f);
    let device = format!("udp:{}", dev.1);
    let file = file.to_str().unwrap();
    let served = [
        "serve-world",
        "--device",
        &device,
        "--device-file",
        file,
        "--bind",
    ];
    let command = [&served[..], &["127.0.0.1:0", "--no-rt"], &SOFT[..]].concat();
    (World::start_as(&command, &key, extra), key)
}

/// The simulated master of a slave world: the grip pushes 15 mm left from 0.6 s; `extra` appended.
fn master(w: &World, key: &Path, secs: &str, extra: &[&str]) -> Child {
    let sim = ["--device", "sim", "--push", "-0.015,0,0.05,0.6"];
    run_side(&sim, w, key, secs, extra)
}

#[test]
fn a_udp_slave_device_follows_a_simulated_master_at_50_ms_and_5_percent_and_its_hand_is_felt() {
    let _m = crate::common::module_turn(module_path!());
    let _t = crate::common::turn();
    // The slave's own (simulated) hand holds it at its start with a spring: what the master feels.
    let dev = crate::cli_udp::sim_device(&[]);
    let impaired = ["--delay-ms", "25", "--loss", "0.05"];
    let (w, key) = slave_world(&dev, "teleop-slave", &impaired);
    let child = master(&w, &key, "3", &impaired);
    let (status, out) = wait_with_limit(child, Duration::from_secs(60)).expect("ends in time");
    let world_out = w.finish(Duration::from_secs(10));
    drop(dev);
    let all = format!("{out}\n{world_out}");
    assert_eq!(status.code(), Some(0), "{all}");
    assert_has(&out, &["no safety stop"]);
    assert_has(&world_out, &["contact: not measured"]);
    // The network created nothing, by both ports' books (the slave's are its encoders') and by
    // the master's plant.
    let created = number(&out, "network: energy created", "created ");
    assert!(created <= 1e-3, "network created {created} J\n{all}");
    let plant_in = number(&out, "master port (plant, true displacement)", "energy in ");
    let plant_out = number(&out, "master port (plant, true displacement)", ", out ");
    assert!(plant_out - plant_in <= 1e-3, "{all}");
    // The slave was pulled and its hand's resistance came back to the master.
    let felt = number(&out, "link: ", "largest force on the handle ");
    assert!(felt > 0.3, "largest force on the handle {felt} N\n{all}");
    let pulled = number(&world_out, "link: ", "largest coupling force ");
    assert!(pulled > 0.3, "{all}");
    assert!(number(&out, "link: round trip", "p50 ") >= 49.0, "{all}");
}

#[test]
fn a_slave_device_lost_mid_run_latches_its_own_and_its_masters_torques() {
    let _m = crate::common::module_turn(module_path!());
    let _t = crate::common::turn();
    let mut dev = crate::cli_udp::sim_device(&[]);
    let (w, key) = slave_world(&dev, "teleop-slave-lost", &[]);
    let child = master(&w, &key, "20", &[]);
    std::thread::sleep(Duration::from_millis(1500));
    dev.0.kill().unwrap();
    let _ = dev.0.wait();
    let (status, out) = wait_with_limit(child, Duration::from_secs(30)).expect("ends in time");
    let world_out = w.finish(Duration::from_secs(10));
    let all = format!("{out}\n{world_out}");
    // The slave side: its device lost, torques latched at zero, the master told.
    assert_has(
        &world_out,
        &["device lost", "the slave's torques set to zero and latched"],
    );
    // The master: stopped by the slave side's goodbye (not by its own link timeout), exit 3.
    assert_eq!(status.code(), Some(3), "{all}");
    assert_has(
        &out,
        &[
            "the world side closed the session",
            "torques set to zero and latched",
        ],
    );
}

#[test]
fn serve_world_refuses_a_simulated_slave_device_and_a_scene_beside_a_device() {
    let _m = crate::common::module_turn(module_path!());
    let _t = crate::common::turn();
    let key = key_file("refuse-slave", 0x40);
    let k = key.to_str().unwrap();
    let o = crate::common::haptic2d(&["serve-world", "--device", "sim", "--key", k]);
    crate::common::expect_exit(&o, 2, &["teleop --live", "fix: --device haply:PATH"]);
    let o =
        crate::common::haptic2d(&["serve-world", "box-in-walls", "--device", "udp:127.0.0.1:9"]);
    crate::common::expect_exit(&o, 2, &["cannot be used with"]);
}
