//! `haptic2d run`: a short headless run prints the timing summary and logs one row per tick; bad
//! options fail with a clear message and a non-zero exit.

use std::process::{Command, Output};

fn haptic2d(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_haptic2d"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn run_headless_one_second_prints_the_summary_and_logs_every_tick() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.csv");
    let o = haptic2d(&[
        "run",
        "--headless",
        "--duration",
        "1",
        "--log",
        log.to_str().unwrap(),
    ]);
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    for needle in [
        "timing: achieved",
        "lateness µs: p50",
        "p99.9",
        "compute  µs: p50",
        "overruns",
        "on time:",
    ] {
        assert!(out.contains(needle), "missing `{needle}` in:\n{out}");
    }
    // "N ticks" from the summary = data rows in the log (nothing lost at the end).
    let ticks: usize = out
        .split_whitespace()
        .collect::<Vec<_>>()
        .windows(2)
        .find(|w| w[1] == "ticks")
        .and_then(|w| w[0].parse().ok())
        .expect("tick count in the summary");
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
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("rec.csv");
    // Record 0.2 s of the simulated device, then replay its encoder angles.
    let rec = dir.path().join("q.csv");
    let o = haptic2d(&[
        "run",
        "--headless",
        "--duration",
        "0.2",
        "--log",
        log.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
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
