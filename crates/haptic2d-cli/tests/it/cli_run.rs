//! `haptic2d run`: a short headless run prints the timing summary and logs one row per tick; bad
//! options fail with a clear message and a non-zero exit.

use crate::common::{haptic2d, run, run_ok, summary_ticks, text, turn};
use std::process::Command;

#[test]
fn run_headless_one_second_prints_the_summary_and_logs_every_tick() {
    let _m = crate::common::module_turn(module_path!());
    // One real-time loop at a time: two loops at SCHED_FIFO pinned to the same core starve
    // each other, and these tests check timing and the display.
    let _turn = turn();
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.csv");
    let o = run("run --headless --duration 1 --log {}", &[&log]);
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    for needle in [
        "timing: achieved",
        "lateness µs: p50",
        "p99.9",
        "compute  µs: p50",
        "overruns",
        "on time:",
        // Issue 42: the stages of the slowest world step (the default build times them).
        "slowest tick: tick",
    ] {
        assert!(out.contains(needle), "missing `{needle}` in:\n{out}");
    }
    // "N ticks" from the summary = data rows in the log (nothing lost at the end).
    let ticks = summary_ticks(&out) as usize;
    assert!(
        ticks > 900 && ticks <= 1000,
        "{ticks} ticks in 1 s at 1 kHz"
    );
    let csv = std::fs::read_to_string(&log).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("t,device.x,device.y,device.theta"));
    assert_eq!(lines.count(), ticks, "one CSV row per tick");
}

#[test]
fn run_rejects_bad_options_clearly() {
    let _m = crate::common::module_turn(module_path!());
    for (args, needle) in [
        (
            vec!["run", "--controller", "pid", "--duration", "1"],
            "four-channel, coupling",
        ),
        (vec!["run", "--hand", "wave", "--duration", "1"], "forms:"),
        (
            vec!["run", "--device", "serial", "--duration", "1"],
            "--device sim",
        ),
        (
            vec!["run", "--bind", "localhost", "--duration", "1"],
            "ADDRESS:PORT",
        ),
        (vec!["run", "--rate", "-5"], "--rate"),
        (vec!["run", "--duration", "0"], "--duration"),
        (
            vec!["run", "no-such-scene", "--duration", "1"],
            "built-in scenes",
        ),
        (
            vec!["run", "--device", "replay:/no/such.csv", "--duration", "1"],
            "replay file",
        ),
    ] {
        let o = haptic2d(&args);
        assert!(!o.status.success(), "{args:?} should fail");
        let out = text(&o);
        assert!(out.contains(needle), "{args:?}: `{needle}` not in:\n{out}");
        assert!(!out.contains("panicked"), "{out}");
    }
}

#[test]
fn run_replays_recorded_encoders() {
    let _m = crate::common::module_turn(module_path!());
    // One real-time loop at a time: two loops at SCHED_FIFO pinned to the same core starve
    // each other, and these tests check timing and the display.
    let _turn = turn();
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("rec.csv");
    // Record 0.2 s of the simulated device, then replay its encoder angles.
    let rec = dir.path().join("q.csv");
    run_ok("run --headless --duration 0.2 --log {}", &[&log]);
    // Build q1..q4 from the device pose with the same model the binary uses.
    let params = haptic2d::device::DeviceParams::default();
    let kin = haptic2d::device::TwinKinematics::new(&params);
    let csv = std::fs::read_to_string(&log).unwrap();
    let mut out = String::from("q1,q2,q3,q4\n");
    for line in csv.lines().skip(1) {
        let v: Vec<f64> = line
            .split(',')
            .take(4)
            .map(|s| s.parse().unwrap())
            .collect();
        let q = kin.ik(&[v[1], v[2], v[3]]).unwrap();
        out.push_str(&format!("{},{},{},{}\n", q[0], q[1], q[2], q[3]));
    }
    std::fs::write(&rec, out).unwrap();
    let o = haptic2d(&[
        "run",
        "--headless",
        "--device",
        &format!("replay:{}", rec.display()),
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("the replay ended"), "{t}");
}

/// A `haptic2d run` with the display on a free loopback port, killed on drop.
struct Running {
    child: std::process::Child,
    /// `host:port` from the banner.
    addr: String,
    /// Every stdout line after the banner.
    lines: std::sync::mpsc::Receiver<String>,
}

impl Running {
    fn start(extra: &[&str]) -> Running {
        use std::io::{BufRead, BufReader};
        let mut child = Command::new(env!("CARGO_BIN_EXE_haptic2d"))
            .args(["run", "--bind", "127.0.0.1:0"])
            .args(extra)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::inherit())
            .spawn()
            .expect("the binary runs");
        let out = child.stdout.take().expect("piped stdout");
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let banner = rx
            .recv_timeout(std::time::Duration::from_secs(30))
            .expect("a banner within 30 s");
        let addr = banner
            .split_whitespace()
            .find_map(|w| w.strip_prefix("http://"))
            .unwrap_or_else(|| panic!("no URL in `{banner}`"))
            .trim_end_matches('/')
            .to_string();
        Running {
            child,
            addr,
            lines: rx,
        }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

type Ws = tungstenite::WebSocket<std::net::TcpStream>;

fn connect(addr: &str) -> Ws {
    let stream = std::net::TcpStream::connect(addr).expect("TCP connect");
    stream
        .set_read_timeout(Some(std::time::Duration::from_secs(5)))
        .unwrap();
    let (ws, _) = tungstenite::client(format!("ws://{addr}/ws"), stream).expect("WebSocket");
    ws
}

/// The next message of type `ty` for which `pred` holds, within `secs` seconds.
fn wait_for(
    ws: &mut Ws,
    ty: &str,
    secs: f64,
    pred: impl Fn(&serde_json::Value) -> bool,
) -> serde_json::Value {
    let end = std::time::Instant::now() + std::time::Duration::from_secs_f64(secs);
    let mut last = serde_json::Value::Null;
    while std::time::Instant::now() < end {
        let msg = match ws.read() {
            Ok(m) => m,
            // SIGSTOP/SIGCONT (CI suspends its machines) interrupts a read with a timeout.
            Err(tungstenite::Error::Io(e)) if e.kind() == std::io::ErrorKind::Interrupted => {
                continue
            }
            Err(e) => panic!("a message: {e:?}"),
        };
        let tungstenite::Message::Text(t) = msg else {
            continue;
        };
        let v: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
        assert_ne!(v["type"], "error", "error frame: {v}");
        if v["type"] == ty {
            if pred(&v) {
                return v;
            }
            last = v;
        }
    }
    panic!("no `{ty}` message as expected within {secs} s; last one: {last}");
}

fn send(ws: &mut Ws, json: &str) {
    ws.send(tungstenite::Message::text(json)).expect("send");
}

fn slave_pose(f: &serde_json::Value) -> [f64; 3] {
    let i = f["slave"].as_u64().expect("a slave") as usize;
    let p = &f["bodies"][i];
    [0, 1, 2].map(|k| p[k].as_f64().unwrap())
}

/// `haptic2d run` serves the display and applies the page's commands between ticks: the hand target
/// (clamped to the device workspace) drags the box into the left wall through the simulated hand,
/// device and controller; pause freezes the world; the controller, the wall law, reset and scene
/// switches take effect. At the end of `--duration` it still prints its timing summary.
#[test]
fn run_display_serves_frames_and_applies_commands() {
    let _m = crate::common::module_turn(module_path!());
    // One real-time loop at a time: two loops at SCHED_FIFO pinned to the same core starve
    // each other, and these tests check timing and the display.
    let _turn = turn();
    let run = Running::start(&["--duration", "8"]);
    let mut ws = connect(&run.addr);
    let welcome = wait_for(&mut ws, "welcome", 5.0, |_| true);
    assert_eq!(welcome["control"], true, "loopback: control without token");
    let scene = wait_for(&mut ws, "scene", 5.0, |_| true);
    assert_eq!(scene["name"], "box-in-walls");
    let ws_box = scene["device"]["workspace"].clone();
    let x_min = ws_box[0].as_f64().expect("device workspace");
    let f0 = wait_for(&mut ws, "frame", 5.0, |_| true);
    let start = slave_pose(&f0);
    assert!(
        f0["device"]["valid"] == true,
        "device linkage: {}",
        f0["device"]
    );
    assert_eq!(f0["controller"], "four-channel");

    // Hand target 10 mm inside the left wall: clamped to the workspace edge; the box hits the wall.
    send(
        &mut ws,
        r#"{"type":"set_hand_target","x":-0.01,"y":0.0,"theta":0.0}"#,
    );
    let hit = wait_for(&mut ws, "frame", 5.0, |f| {
        f["contacts_total"].as_u64().unwrap_or(0) > 0 && slave_pose(f)[0] < 0.025
    });
    let target_x = hit["hand_target"][0].as_f64().unwrap();
    assert!(
        (target_x - x_min).abs() < 1e-9,
        "clamped: {target_x} vs {x_min}"
    );
    assert!(slave_pose(&hit)[0] < start[0] - 0.01, "{hit}");
    assert!(hit["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .any(|c| c["normal"][0].as_f64().unwrap() > 0.99));

    // Pause: the world's time stands still; resume: it runs again.
    send(&mut ws, r#"{"type":"pause"}"#);
    let p1 = wait_for(&mut ws, "frame", 5.0, |f| f["paused"] == true);
    // Frames go on while paused: the 12th after it (about 0.2 s at 60 frames a second).
    let after = p1["seq"].as_u64().unwrap() + 12;
    let p2 = wait_for(&mut ws, "frame", 5.0, |f| f["seq"].as_u64() >= Some(after));
    assert_eq!(p1["t"], p2["t"], "paused world does not advance");
    assert_eq!(p2["drive"], serde_json::json!([0.0, 0.0, 0.0]));
    send(&mut ws, r#"{"type":"resume"}"#);
    let t_p = p2["t"].as_f64().unwrap();
    wait_for(&mut ws, "frame", 5.0, |f| {
        f["paused"] == false && f["t"].as_f64().unwrap() > t_p + 0.05
    });

    // Controller and wall law.
    send(&mut ws, r#"{"type":"set_controller","name":"coupling"}"#);
    send(&mut ws, r#"{"type":"set_wall_law","name":"zoh"}"#);
    wait_for(&mut ws, "frame", 5.0, |f| {
        f["controller"] == "coupling" && f["wall_law"] == "zoh"
    });

    // Reset: the scene again, the box back at its start, the laws and controller kept.
    send(&mut ws, r#"{"type":"reset"}"#);
    let again = wait_for(&mut ws, "scene", 5.0, |_| true);
    assert_eq!(again["name"], "box-in-walls");
    assert!(again["seq"].as_u64() > scene["seq"].as_u64());
    let seq = again["seq"].clone();
    let f = wait_for(&mut ws, "frame", 5.0, |f| f["scene_seq"] == seq);
    let p = slave_pose(&f);
    assert!((p[0] - start[0]).abs() < 2e-3, "{p:?} vs {start:?}");
    assert_eq!(f["controller"], "coupling");
    assert_eq!(f["wall_law"], "zoh");

    // Switch scene.
    send(&mut ws, r#"{"type":"switch_scene","name":"peg-in-hole"}"#);
    let peg = wait_for(&mut ws, "scene", 5.0, |_| true);
    assert_eq!(peg["name"], "peg-in-hole");
    let seq = peg["seq"].clone();
    let f = wait_for(&mut ws, "frame", 5.0, |f| f["scene_seq"] == seq);
    assert_eq!(f["wall_law"], "zoh");
    assert_eq!(f["friction"], "reset-integrator");
    drop(ws);

    // The run ends by itself and prints its summary.
    let mut all = Vec::new();
    while let Ok(l) = run.lines.recv_timeout(std::time::Duration::from_secs(20)) {
        all.push(l);
    }
    let all = all.join("\n");
    assert!(all.contains("timing: achieved"), "{all}");
    assert!(all.contains("on time:"), "{all}");
}

#[test]
fn run_display_port_taken_is_a_clear_error() {
    let _m = crate::common::module_turn(module_path!());
    // One real-time loop at a time: two loops at SCHED_FIFO pinned to the same core starve
    // each other, and these tests check timing and the display.
    let _turn = turn();
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let o = haptic2d(&["run", "--bind", &addr, "--duration", "1"]);
    let out = text(&o);
    assert!(!o.status.success(), "{out}");
    assert!(out.contains("already in use"), "{out}");
    assert!(out.contains("--bind"), "{out}");
    assert!(!out.contains("panicked"), "{out}");
    // Headless ignores the display address.
    let o = haptic2d(&["run", "--headless", "--bind", &addr, "--duration", "0.1"]);
    assert!(o.status.success(), "{}", text(&o));
}

#[test]
fn run_display_on_a_non_loopback_address_prints_the_token() {
    let _m = crate::common::module_turn(module_path!());
    // One real-time loop at a time: two loops at SCHED_FIFO pinned to the same core starve
    // each other, and these tests check timing and the display.
    let _turn = turn();
    let o = haptic2d(&["run", "--bind", "0.0.0.0:0", "--duration", "0.3"]);
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    let banner = out.lines().next().unwrap_or_default();
    assert!(banner.starts_with("display: http://127.0.0.1:"), "{out}");
    assert!(banner.contains("?token="), "{out}");
    assert!(banner.contains("commands need token"), "{out}");
}

#[test]
fn run_device_file() {
    let _m = crate::common::module_turn(module_path!());
    // One real-time loop at a time: two loops at SCHED_FIFO pinned to the same core starve
    // each other, and these tests check timing and the display.
    let _turn = turn();
    let dir = tempfile::tempdir().unwrap();
    let template = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../devices/twin-pantograph.toml"
    );
    let run = |extra: &[&str]| {
        let mut args = vec!["run", "--headless", "--duration", "0.2", "--no-rt"];
        args.extend_from_slice(extra);
        haptic2d(&args)
    };
    // A clean run with `extra` whose start line names where its device parameters came from.
    let parameters_from = |extra: &[&str], source: &str| {
        let o = run(extra);
        let out = text(&o);
        assert!(o.status.success(), "{out}");
        let start = out.lines().find(|l| l.starts_with("running "));
        let want = format!("(parameters: {source})");
        assert!(start.is_some_and(|l| l.contains(&want)), "{out}");
    };

    // No device file, no [device] table: the spec defaults.
    parameters_from(&[], "spec defaults");

    // The template as a device file.
    parameters_from(
        &["--device-file", template],
        &format!("device file {template}"),
    );

    // A scene with a [device] table; a device file wins over it.
    let scene = dir.path().join("scene.toml");
    let scene_text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/box-in-walls.toml"
    ))
    .unwrap();
    std::fs::write(&scene, format!("{scene_text}\n[device]\nf_c = 0.002\n")).unwrap();
    let scene = scene.to_str().unwrap();
    parameters_from(&[scene], &format!("scene {scene}"));
    let subset = dir.path().join("subset.toml");
    std::fs::write(
        &subset,
        "tau_max = 0.4\nm_h = 0.1\nworkspace_center_y = 0.15\n",
    )
    .unwrap();
    let subset = subset.to_str().unwrap();
    let log = dir.path().join("subset.csv");
    let args = [
        scene,
        "--device-file",
        subset,
        "--log",
        log.to_str().unwrap(),
    ];
    parameters_from(&args, &format!("device file {subset}"));
    // The file's parameters reach the device: it starts at the file's workspace centre (the spec
    // default is y = 0.14 m).
    let csv = std::fs::read_to_string(&log).unwrap();
    let first: Vec<f64> = csv
        .lines()
        .nth(1)
        .expect("a logged tick")
        .split(',')
        .take(3)
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(
        (first[2] - 0.15).abs() < 1e-3,
        "device.y at start {} m, expected 0.15 m",
        first[2]
    );

    // Bad device files: non-zero exit, the file and the field named, a fix, no panic.
    for (name, body, field) in [
        (
            "unknown.toml",
            "[device]\nlink_length = 0.1\n",
            "device.link_length",
        ),
        ("negative.toml", "tau_max = -1\n", "tau_max"),
        ("type.toml", "l1 = \"long\"\n", "l1"),
    ] {
        let bad = dir.path().join(name);
        std::fs::write(&bad, body).unwrap();
        let bad = bad.to_str().unwrap();
        let o = run(&["--device-file", bad]);
        let out = text(&o);
        assert!(!o.status.success(), "{name} should fail:\n{out}");
        assert!(out.contains(bad), "{name}: file not named:\n{out}");
        assert!(
            out.contains(&format!("{field}:")),
            "{name}: `{field}` not named:\n{out}"
        );
        assert!(out.contains("fix:"), "{name}: no fix:\n{out}");
        assert!(!out.contains("running "), "{name}: nothing runs:\n{out}");
        assert!(!out.contains("panicked"), "{out}");
    }
    let missing = dir.path().join("missing.toml");
    let o = run(&["--device-file", missing.to_str().unwrap()]);
    let out = text(&o);
    assert!(!o.status.success(), "{out}");
    assert!(out.contains("cannot read device file"), "{out}");
    assert!(!out.contains("panicked"), "{out}");
}
