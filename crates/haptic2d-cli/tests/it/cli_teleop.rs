//! The haptic loop split at the network (issue 41, docs/TELEOP.md): `haptic2d serve-world` and
//! `haptic2d run --world udp:…` (or its alias `remote-device`) as two processes over loopback,
//! authenticated with a shared key.
//!
//! The acceptance test: 50 ms round trip (25 ms injected on each side) and 5 % loss on each side,
//! the simulated hand pushes the handle so that the world's box goes into a stiff wall; with
//! TDPA the network creates no energy (≤ 1 mJ, summed over both processes' port ledgers) and no
//! safety stop trips; without TDPA the same run creates energy (the test proves TDPA is needed).
//!
//! Timing on a shared machine: the world side runs at normal priority (it drives no motor), so it
//! never competes with a real-time device loop pinned to a core; the stall limit is 100 periods and
//! the link timeout 300 ms (the tests check the link and the energy, not the machine's timing);
//! the tests take turns.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use crate::common::{assert_has, wait_with_limit};

const BIN: &str = env!("CARGO_BIN_EXE_haptic2d");

/// A fresh key file (mode 600) in a temp dir of its own.
pub(crate) fn key_file(tag: &str, byte: u8) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let dir = std::env::temp_dir().join(format!("haptic2d-teleop-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("key");
    std::fs::write(&p, format!("{byte:02x}").repeat(32)).unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o600)).unwrap();
    p
}

/// The wall scene of the acceptance test (docs/TELEOP.md): box-in-walls with the box 3 mm from
/// the left wall and a stiffer contact (5 000 N/m per corner, 10 000 N/m on a face), so that the
/// wall is reached well inside the device's workspace.
pub(crate) const NEAR_WALL: &str = r#"name = "box-near-wall"
description = "a 0.5 kg box 3 mm from a stiff wall (the world link's acceptance test)"
[world]
rate = 1000
proximity_every = 10
integration = "semi-implicit"
[contact]
impacts = true
restitution = 0.5
v_c = 0.02
[normal]
model = "paper"
kc = 5000.0
bc = 5.0
[friction]
model = "none"
[[body]]
name = "walls"
kind = "fixed"
pieces = [
  [[-0.1, -0.2], [0.0, -0.2], [0.0, 0.2], [-0.1, 0.2]],
  [[0.3, -0.2], [0.4, -0.2], [0.4, 0.2], [0.3, 0.2]],
  [[0.0, -0.2], [0.3, -0.2], [0.3, -0.1], [0.0, -0.1]],
  [[0.0, 0.1], [0.3, 0.1], [0.3, 0.2], [0.0, 0.2]],
]
[[body]]
name = "box"
mass = 0.5
box = [0.04, 0.02]
position = [0.023, 0.0]
"#;

/// A running `serve-world`, its address, and its output so far (the rest is read on a thread).
pub(crate) struct World {
    child: Child,
    pub(crate) addr: String,
    lines: mpsc::Receiver<String>,
}

impl Drop for World {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `haptic2d ARGS… --key KEY EXTRA…` started with its output piped: either end of the split loop.
pub(crate) fn spawn_keyed(args: &[&str], key: &Path, extra: &[&str]) -> Child {
    Command::new(BIN)
        .args(args)
        .arg("--key")
        .arg(key)
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

impl World {
    pub(crate) fn start(key: &Path, extra: &[&str]) -> World {
        let scene = key.with_file_name("near-wall.toml");
        std::fs::write(&scene, NEAR_WALL).unwrap();
        let scene = scene.to_str().unwrap();
        World::start_as(&["serve-world", scene, "--bind", "127.0.0.1:0"], key, extra)
    }

    /// A world side started as `command` (`serve-world SCENE …` or `serve-world --device …`).
    pub(crate) fn start_as(command: &[&str], key: &Path, extra: &[&str]) -> World {
        let mut child = spawn_keyed(command, key, extra);
        let (tx, lines) = mpsc::channel();
        let out = child.stdout.take().unwrap();
        std::thread::spawn(move || {
            for l in BufReader::new(out).lines().map_while(Result::ok) {
                let _ = tx.send(l);
            }
        });
        let mut err = child.stderr.take().unwrap();
        std::thread::spawn(move || {
            let mut s = String::new();
            let _ = err.read_to_string(&mut s);
            if !s.is_empty() {
                eprintln!("serve-world stderr: {s}");
            }
        });
        let mut addr = None;
        while addr.is_none() {
            let l = lines
                .recv_timeout(Duration::from_secs(30))
                .expect("serve-world prints its address");
            addr = l
                .strip_prefix("serve-world: listening on ")
                .map(str::to_string);
        }
        World {
            child,
            addr: addr.unwrap(),
            lines,
        }
    }

    /// Waits for the world side to end (at most `limit`) and returns the rest of its output.
    pub(crate) fn finish(mut self, limit: Duration) -> String {
        let t0 = std::time::Instant::now();
        while self.child.try_wait().unwrap().is_none() && t0.elapsed() < limit {
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let mut s = String::new();
        while let Ok(l) = self.lines.recv_timeout(Duration::from_secs(2)) {
            s.push_str(&l);
            s.push('\n');
        }
        s
    }
}

/// The device side as `run --device sim --world udp:…`.
fn device(world: &World, key: &Path, extra: &[&str]) -> (i32, String) {
    device_as(&["run", "--device", "sim"], world, key, extra)
}

/// The device side started as `command` (`run …` or the alias `remote-device`).
fn device_as(command: &[&str], world: &World, key: &Path, extra: &[&str]) -> (i32, String) {
    let addr = format!("udp:{}", world.addr);
    let child = spawn_keyed(&[command, &["--world", &addr]].concat(), key, extra);
    let (status, text) =
        wait_with_limit(child, Duration::from_secs(60)).expect("remote-device ends in time");
    (status.code().unwrap_or(-1), text)
}

/// The number after `prefix` in the line starting with `line_start`.
pub(crate) fn number(text: &str, line_start: &str, prefix: &str) -> f64 {
    let line = text
        .lines()
        .find(|l| l.starts_with(line_start))
        .unwrap_or_else(|| panic!("no line `{line_start}` in:\n{text}"));
    let rest = &line[line
        .find(prefix)
        .unwrap_or_else(|| panic!("{prefix} in {line}"))
        + prefix.len()..];
    rest.split_whitespace()
        .next()
        .unwrap()
        .trim_end_matches(',')
        .parse()
        .unwrap()
}

/// (energy in, energy out) of a port's ledger line (J).
pub(crate) fn port(text: &str, line_start: &str) -> (f64, f64) {
    (
        number(text, line_start, "energy in "),
        number(text, line_start, ", out "),
    )
}

struct Pushed {
    status: i32,
    device: String,
    world: String,
    /// By the ports' books (J).
    created: f64,
    /// As the simulated handle and the world's body really received it: the applied forces times
    /// their true displacements (J).
    plants_created: f64,
}

impl Pushed {
    /// Both processes' output, for the failure messages.
    fn all(&self) -> String {
        format!("{}\n{}", self.device, self.world)
    }

    /// What every passive link must show on the acceptance run: a clean exit with no safety stop,
    /// no energy created (≤ 1 mJ) by the ports' books nor as the plants received it, the delay and
    /// the loss really there (round trip p50 in 49–80 ms, over 20 datagrams dropped), and the
    /// session closed by the device side. Both processes' output.
    #[track_caller]
    fn assert_passive(&self) -> String {
        let all = self.all();
        assert_eq!(self.status, 0, "{all}");
        assert!(self.device.contains("no safety stop"), "{all}");
        assert!(
            self.created <= 1e-3,
            "books: created {} J\n{all}",
            self.created
        );
        assert!(
            self.plants_created <= 1e-3,
            "plants: created {} J\n{all}",
            self.plants_created
        );
        let rtt = number(&self.device, "link: round trip", "p50 ");
        assert!(
            (49.0..80.0).contains(&rtt),
            "round trip p50 {rtt} ms\n{all}"
        );
        assert!(
            number(&self.device, "link: ", "send errors, ") > 20.0,
            "{all}"
        );
        assert!(
            self.world.contains("the device side closed the session"),
            "{all}"
        );
        all
    }
}

/// The acceptance run: 25 ms each way, 5 % loss each way; the gripping hand (300 N/m, 5 N·s/m)
/// holds still for 0.6 s (the ramp), then its target moves 15 mm to the left at 50 mm/s: the box,
/// 3 mm from the wall, is pushed into it, with about 2.3 N at rest (hand and coupling springs in
/// series against the wall); 3 s in all.
fn pushed_into_the_wall(link: &str, tag: &str) -> Pushed {
    pushed_into_the_wall_as(link, link, tag)
}

/// As [`pushed_into_the_wall`], the world side with `--link world_link`, the device side with
/// `--link device_link` (`tdpa`, `wave`, or `none`: the same as --no-tdpa).
fn pushed_into_the_wall_as(world_link: &str, device_link: &str, tag: &str) -> Pushed {
    let key = key_file(tag, 0x5a);
    let common = vec![
        "--delay-ms",
        "25",
        "--loss",
        "0.05",
        "--link-timeout-ms",
        "300",
    ];
    let mut w_args = common.clone();
    w_args.extend(["--link", world_link]);
    w_args.extend(["--seed", "2"]);
    let world = World::start(&key, &w_args);
    let mut d_args = common;
    d_args.extend(["--link", device_link]);
    d_args.extend([
        "--seed",
        "3",
        "--duration",
        "3",
        "--push",
        "-0.015,0,0.05,0.6",
        "--max-stall-periods",
        "100",
    ]);
    let (status, device) = device(&world, &key, &d_args);
    let world = world.finish(Duration::from_secs(10));
    if world_link != device_link {
        return Pushed {
            status,
            created: f64::NAN,
            plants_created: f64::NAN,
            device,
            world,
        };
    }
    let (mi, mo) = port(&device, "master port (device):");
    let (si, so) = port(&world, "world port (slave):");
    let (pi, po) = port(&device, "master port (plant, true displacement):");
    let (bi, bo) = port(&world, "world port (body, true displacement):");
    Pushed {
        status,
        created: (mo + so) - (mi + si),
        plants_created: (po + bo) - (pi + bi),
        device,
        world,
    }
}

#[test]
fn with_tdpa_a_50_ms_round_trip_with_5_percent_loss_creates_no_energy_pushing_into_a_wall_and_the_world_books_the_body(
) {
    let _turn = crate::common::loop_turn(module_path!());
    let r = pushed_into_the_wall("tdpa", "tdpa");
    // Not only by the books: the plants really received no energy from the network (measured
    // −2.2 mJ; docs/TELEOP.md).
    let all = r.assert_passive();
    // The world port books what the body really received (the force held over the world step ×
    // the body's displacement over it): its books are the body's ledger.
    assert_eq!(
        port(&r.world, "world port (slave):"),
        port(&r.world, "world port (body, true displacement):"),
        "{all}"
    );
    // The run did what it claims: the wall was felt.
    let f = number(&r.device, "link: ", "largest force on the handle ");
    assert!(f > 2.0, "the wall was not felt: {f} N\n{all}");
    // Transparency: in contact, the coupling force on the slave follows the wall's (issue 41
    // item 5 reports it; 10 % of the wall force here).
    let wall = number(&r.world, "contact: ", "mean wall force ");
    let diff = number(&r.world, "contact: ", "mean |difference| ");
    assert!(
        wall > 1.5 && diff < 0.1 * wall,
        "wall {wall} N, error {diff} N\n{all}"
    );
}

#[test]
fn without_tdpa_the_same_run_creates_energy() {
    let _turn = crate::common::loop_turn(module_path!());
    let r = pushed_into_the_wall("none", "none");
    let all = r.all();
    assert!(
        r.created > 0.02 && r.plants_created > 0.02,
        "created {} J (books), {} J (plants): the delayed link should create energy without TDPA\n{all}",
        r.created,
        r.plants_created
    );
}

/// Issue 41, wave variables across the two processes: the same acceptance run with `--link wave`
/// on both ends (the waves, the wave energy each sender has put on the link, and the handle's
/// position for the drift compensation cross in the authenticated message). No energy created —
/// by the plants' ledger (applied forces × true displacements) and by the ports' books — and no
/// safety stop. Measured (docs/TELEOP.md): plants −7.5 mJ, books −6.3 mJ, wall 1.6 N.
#[test]
fn with_waves_a_50_ms_round_trip_with_5_percent_loss_creates_no_energy_pushing_into_a_wall() {
    let _turn = crate::common::loop_turn(module_path!());
    let r = pushed_into_the_wall("wave", "wave");
    let all = r.assert_passive();
    assert!(r.device.contains("link wave (b 20, 20, 0.04"), "{all}");
    // The waves did the work: each end used wave energy the other sent, and the wall is felt.
    let used = number(&r.world, "waves: ", "used ");
    assert!(used > 0.01, "{all}");
    let wall = number(&r.world, "contact: ", "mean wall force ");
    assert!(wall > 1.0, "the wall was not felt: {wall} N\n{all}");
}

/// A device side running waves against a world side running TDPA latches zero torques at the
/// first message and says why (the two ends would read each other's fields wrongly).
#[test]
fn a_wave_device_side_against_a_tdpa_world_latches_and_says_link_mismatch() {
    let _turn = crate::common::loop_turn(module_path!());
    let r = pushed_into_the_wall_as("tdpa", "wave", "mismatch");
    assert_eq!(r.status, 3, "{}", r.all());
    let says = [
        "link mismatch: the world side runs force/velocity",
        "torques set to zero and latched",
    ];
    assert_has(&r.device, &says);
}

/// The same mismatch when the world side stops before any of its own (delayed) messages has left
/// its impairment queue: its goodbye carries its link kind, so the device side still says
/// "link mismatch" rather than waiting out a lost link. Pinned deterministically by a world whose
/// outgoing delay (400 ms) is far longer than the device side's first message takes to arrive.
#[test]
fn a_world_that_stops_on_a_mismatch_before_sending_says_goodbye_with_its_link_kind() {
    let _turn = crate::common::loop_turn(module_path!());
    let key = key_file("mismatch-early", 0x5b);
    let world = World::start(
        &key,
        &[
            "--link",
            "tdpa",
            "--delay-ms",
            "400",
            "--link-timeout-ms",
            "300",
        ],
    );
    let (status, text) = device(
        &world,
        &key,
        &[
            "--link",
            "wave",
            "--link-timeout-ms",
            "300",
            "--duration",
            "3",
            "--no-rt",
            "--max-stall-periods",
            "100",
        ],
    );
    let w = world.finish(Duration::from_secs(10));
    assert_eq!(status, 3, "{text}\n{w}");
    let says = [
        "link mismatch: the world side runs force/velocity",
        "torques set to zero and latched",
    ];
    assert_has(&text, &says);
}

#[test]
fn a_silent_world_latches_zero_torques_and_says_lost_link() {
    let _turn = crate::common::loop_turn(module_path!());
    let key = key_file("silent", 0x33);
    // The world side stops after 1 s without a goodbye; the device side must notice.
    let world = World::start(&key, &["--duration", "1"]);
    let (status, text) = device(
        &world,
        &key,
        &["--duration", "10", "--no-rt", "--max-stall-periods", "100"],
    );
    assert_eq!(status, 3, "{text}");
    assert!(
        text.contains("lost link: no datagram from the world"),
        "{text}"
    );
    assert!(text.contains("torques set to zero and latched"), "{text}");
}

#[test]
fn a_device_side_with_another_key_gets_no_session() {
    let _turn = crate::common::loop_turn(module_path!());
    let world = World::start(&key_file("k1", 0x11), &["--accept-timeout", "3"]);
    // Through the alias `remote-device`, which runs the same device side.
    let (status, text) = device_as(
        &["remote-device"],
        &world,
        &key_file("k2", 0x22),
        &["--duration", "1", "--connect-timeout", "0.5"],
    );
    assert_eq!(status, 1, "{text}");
    assert!(text.contains("no WELCOME"), "{text}");
    let w = world.finish(Duration::from_secs(10));
    assert!(!w.contains("session "), "{w}");
}

/// `run`'s split-loop options need `--world`, and across a network `run` refuses what belongs to a
/// local world or a device not built for it yet, each with the fix (exit 2, before any socket).
#[test]
fn run_refuses_split_loop_options_without_world_and_local_world_options_with_it() {
    let _m = crate::common::module_turn(module_path!());
    let key = key_file("refuse", 0x44);
    let k = key.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["run", "--key", k, "--duration", "1"], "need --world"),
        (&["run", "--push", "-0.01,0,0.05,0.5"], "need --world"),
        (
            &[
                "run",
                "--world",
                "udp:127.0.0.1:9",
                "--key",
                k,
                "--device",
                "replay:x.csv",
            ],
            "a replay renders no force",
        ),
        (
            &[
                "run",
                "--world",
                "udp:127.0.0.1:9",
                "--key",
                k,
                "--device",
                "haply:auto",
                "--push",
                "-0.01,0,0.05,0.5",
            ],
            "the hand is yours",
        ),
        (
            &[
                "run",
                "--world",
                "udp:127.0.0.1:9",
                "--key",
                k,
                "--log",
                "x.mcap",
            ],
            "--log does not apply",
        ),
        (
            &[
                "run",
                "--world",
                "udp:127.0.0.1:9",
                "--key",
                k,
                "--passivity",
            ],
            "does not apply",
        ),
        (&["run", "--world", "udp:127.0.0.1:9"], "needs --key FILE"),
        (
            &[
                "run",
                "--world",
                "udp:127.0.0.1:9",
                "--key",
                k,
                "--link",
                "wave",
                "--no-tdpa",
            ],
            "--no-tdpa means --link none",
        ),
        (
            &["serve-world", "box-in-walls", "--key", k, "--link", "waves"],
            "expected tdpa, wave or none",
        ),
        (
            &["run", "--world", "127.0.0.1:9", "--key", k],
            "expected udp:HOST:PORT",
        ),
    ];
    for (args, what) in cases {
        let o = crate::common::haptic2d(args);
        let t = crate::common::text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {t}");
        assert!(t.contains(what) && t.contains("fix:"), "{args:?}: {t}");
    }
}

/// `haptic2d teleop ARGS…`, which must succeed: its output, and the last second of contact's mean
/// wall force on the slave and force of the master on the hand (N).
#[track_caller]
fn teleop_contact(args: &[&str]) -> (String, f64, f64) {
    let o = crate::common::haptic2d(&[&["teleop"], args].concat());
    let t = crate::common::text(&o);
    assert!(o.status.success(), "{t}");
    let contact = "contact (last second):";
    let wall = number(&t, contact, "wall force on the slave ");
    let felt = number(&t, contact, "force of the master on the hand ");
    (t, wall, felt)
}

/// `haptic2d teleop` with two simulated devices: the slave's wall contact is felt at the master
/// (static force `(15 − 5) mm / (1/300 + 1/500 + 1/2000) m/N = 1.76 N`, device friction aside),
/// and at a 50 ms round trip with 5 % loss the link creates no energy.
#[test]
fn teleop_of_two_simulated_devices_reproduces_the_wall_contact_at_the_master() {
    let _m = crate::common::module_turn(module_path!());
    let args = [
        "--master",
        "sim",
        "--slave",
        "sim",
        "--delay-ms",
        "25",
        "--loss",
        "0.05",
    ];
    let (t, wall, felt) = teleop_contact(&args);
    assert!((1.4..2.1).contains(&wall), "{t}");
    assert!((felt - wall).abs() < 0.1 * wall, "{t}");
    assert!(number(&t, "network:", "created ") <= 1e-3, "{t}");
}

/// `haptic2d teleop --architecture four-channel`: the four channels hold master and slave
/// together, so the hand spring (300 N/m) meets the wall (2 000 N/m) with no coupling between:
/// `(15 − 5) mm / (1/300 + 1/2000) m/N = 2.61 N` (±0.35 N for joint friction), felt at the master,
/// with a separation well under the position–force coupling's 3.5 mm; stable without TDPA at a
/// 50 ms round trip, where position–force runs away (docs/TELEOP.md).
#[test]
fn teleop_four_channel_feels_the_wall_with_master_and_slave_together_even_at_50_ms_without_tdpa() {
    let _m = crate::common::module_turn(module_path!());
    let args = [
        "--architecture",
        "four-channel",
        "--delay-ms",
        "25",
        "--no-tdpa",
    ];
    let (t, wall, felt) = teleop_contact(&args);
    assert!(t.contains("four-channel"), "{t}");
    assert!((2.26..2.96).contains(&wall), "{t}");
    assert!((felt - wall).abs() < 0.1 * wall, "{t}");
    assert!(
        number(&t, "largest master force", "separation at the end ") < 1.0,
        "{t}"
    );
    assert!(number(&t, "plants:", "created ") < 1e-2, "{t}");
}

/// `haptic2d teleop --stability` prints a finite delay margin for position–force between 10 and
/// 50 ms (the runs of this page: stable at 10 ms, running away at 50 ms without TDPA) and
/// writes the margin plot where asked.
#[test]
fn teleop_stability_prints_the_delay_margin_and_writes_the_plot() {
    let _m = crate::common::module_turn(module_path!());
    let dir = key_file("margin", 0x02).with_file_name("margin");
    let o = crate::common::haptic2d(&[
        "teleop",
        "--stability",
        "--stability-plot",
        dir.to_str().unwrap(),
    ]);
    let t = crate::common::text(&o);
    assert!(o.status.success(), "{t}");
    let ms = number(&t, "position-force (chosen):", "round trip of ");
    assert!((10.0..50.0).contains(&ms), "{t}");
    assert!(
        t.contains("four-channel: stable at every round trip"),
        "{t}"
    );
    assert!(dir.join("teleop-margin.svg").exists(), "{t}");
}

/// `haptic2d teleop --figures DIR` writes the delay table (Markdown, CSV) and one plot per round
/// trip into the directory the user gives, and prints the table (docs/TELEOP.md).
#[test]
fn teleop_figures_writes_the_table_and_a_plot_per_round_trip_into_the_given_dir() {
    let _m = crate::common::module_turn(module_path!());
    let dir = key_file("figures", 0x01).with_file_name("figs");
    let o = crate::common::haptic2d(&["teleop", "--figures", dir.to_str().unwrap()]);
    let t = crate::common::text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("| 50 ms | 5 % | wave |"), "{t}");
    for f in ["teleop-delays.md", "teleop-delays.csv"] {
        assert!(dir.join(f).exists(), "{f}: {t}");
    }
    for rt in [0, 10, 50, 200] {
        assert!(dir.join(format!("teleop-delay-{rt}ms.svg")).exists(), "{t}");
    }
}

/// The acceptance run through Linux netem instead of the built-in impairment (issue 41 item 3):
/// both processes in a network namespace of their own whose loopback delays every datagram by
/// 25 ms and drops 5 % (so 50 ms round trip, 5 % loss each way). Ignored, so that it is never
/// reported as passed where it cannot run: it needs `unshare -n`, the privilege to make a network
/// namespace and a kernel with the netem qdisc (`sch_netem`; the VM this was written on lacks it,
/// so this path has not run there). Run where they exist:
/// `cargo test -p haptic2d-cli --test it cli_teleop::netem -- --ignored`; without them it fails and
/// says which is missing.
#[test]
#[ignore = "needs a network namespace with the netem qdisc (root, sch_netem): cargo test -p haptic2d-cli --test it cli_teleop::netem -- --ignored"]
fn netem_in_a_namespace_at_50_ms_and_5_percent_with_tdpa_creates_no_energy() {
    let _turn = crate::common::loop_turn(module_path!());
    let netem = "ip link set lo up && tc qdisc add dev lo root netem delay 25ms loss 5%";
    match Command::new("unshare")
        .args(["-n", "sh", "-c", netem])
        .output()
    {
        Err(e) => panic!("cannot run unshare (util-linux): {e}"),
        Ok(o) if !o.status.success() => panic!(
            "no netem in a network namespace here (needs root and the sch_netem kernel module): {}",
            String::from_utf8_lossy(&o.stderr).trim()
        ),
        Ok(_) => {}
    }
    let key = key_file("netem", 0x6b);
    let scene = key.with_file_name("near-wall.toml");
    std::fs::write(&scene, NEAR_WALL).unwrap();
    let wout = key.with_file_name("world.txt");
    let script = format!(
        "{netem} && ({BIN} serve-world {s} --bind 127.0.0.1:7420 --key {k} --link-timeout-ms 300 > {w} 2>&1 &) \
         && sleep 0.5 && {BIN} remote-device --world udp:127.0.0.1:7420 --key {k} --duration 3 \
         --push -0.015,0,0.05,0.6 --link-timeout-ms 300 --max-stall-periods 100; echo \"device exit $?\"; sleep 1",
        s = scene.display(),
        k = key.display(),
        w = wout.display()
    );
    let child = Command::new("unshare")
        .args(["-n", "sh", "-c", &script])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (_, device) = wait_with_limit(child, Duration::from_secs(60)).expect("ends in time");
    let world = std::fs::read_to_string(&wout).unwrap_or_default();
    let all = format!("{device}\n{world}");
    assert!(device.contains("device exit 0"), "{all}");
    assert!(device.contains("no safety stop"), "{all}");
    let (mi, mo) = port(&device, "master port (device):");
    let (si, so) = port(&world, "world port (slave):");
    assert!((mo + so) - (mi + si) <= 1e-3, "{all}");
    let rtt = number(&device, "link: round trip", "p50 ");
    assert!(
        (49.0..80.0).contains(&rtt),
        "round trip p50 {rtt} ms\n{all}"
    );
}
