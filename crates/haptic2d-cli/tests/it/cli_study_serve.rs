//! `haptic2d study serve` end to end (issue 40 item 7): the real binary on the simulated device,
//! driven over TCP on loopback with JSON lines as a Python/PsychoPy client drives it. A present
//! runs on the real-time loop and comes back with the loop's measures; bad requests are answered
//! with their reasons and change nothing; `stop` exits 0; SIGINT ends the server with 130 and a
//! safety stop with 3 and a lost device with 4, each answering the pending presentation with the reason and zeroing the
//! torques; non-loopback addresses are refused before anything starts.

use crate::common::{signal, spawn_announced, Killed, BIN};
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

fn study() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../studies/stiffness-walls.toml")
}

/// A running server and a client connected to it.
struct Served {
    child: Killed,
    conn: BufReader<TcpStream>,
}

impl Served {
    /// `haptic2d study serve studies/stiffness-walls.toml --device sim --hand HAND --headless` on a
    /// free loopback port, connected.
    fn start(hand: &str, extra: &[&str]) -> Served {
        let mut args = vec!["--hand", hand];
        args.extend_from_slice(extra);
        Self::start_on("sim", &args)
    }

    /// The same on `device` with the options `extra`.
    fn start_on(device: &str, extra: &[&str]) -> Served {
        let (child, addr) = spawn_announced(
            Command::new(BIN)
                .args(["study", "serve"])
                .arg(study())
                .args(["--device", device, "--listen", "127.0.0.1:0"])
                .args(["--headless", "--no-rt"])
                .args(extra),
            "study server: listening on ",
        );
        let stream = TcpStream::connect(&addr).expect("the server accepts");
        stream
            .set_read_timeout(Some(Duration::from_secs(120)))
            .unwrap();
        Served {
            child,
            conn: BufReader::new(stream),
        }
    }

    fn send_line(&mut self, line: &str) {
        let s = self.conn.get_mut();
        s.write_all(line.as_bytes()).unwrap();
        s.write_all(b"\n").unwrap();
    }

    fn reply(&mut self) -> Value {
        let mut line = String::new();
        let n = self.conn.read_line(&mut line).expect("a reply in time");
        assert!(n > 0, "the server closed the connection");
        serde_json::from_str(&line).unwrap_or_else(|e| panic!("not JSON ({e}): {line}"))
    }

    fn ask(&mut self, req: Value) -> Value {
        self.send_line(&req.to_string());
        self.reply()
    }

    /// Waits for the server to exit: its code and the rest of its stdout.
    fn exit(mut self) -> (Option<i32>, String) {
        let t0 = std::time::Instant::now();
        let status = loop {
            if let Some(st) = self.child.try_wait().unwrap() {
                break st.code();
            }
            assert!(
                t0.elapsed() < Duration::from_secs(60),
                "the server did not exit"
            );
            std::thread::sleep(Duration::from_millis(20));
        };
        let mut out = String::new();
        if let Some(mut o) = self.child.stdout.take() {
            let _ = o.read_to_string(&mut out);
        }
        (status, out)
    }
}

fn error_of(v: &Value) -> String {
    assert_eq!(v["ok"], json!(false), "expected an error reply: {v}");
    v["error"].as_str().expect("a reason").to_string()
}

/// Bad requests get JSON errors with their reasons (and the server keeps serving); a timed
/// present runs on the loop and returns its measures; an open-ended one blocks a second present
/// until `end`; `stop` answers, zeroes the torques and exits 0.
#[test]
fn requests_are_answered_bad_ones_with_reasons_and_stop_exits_0() {
    let _m = crate::common::module_turn(module_path!());
    let mut s = Served::start("follow", &[]);
    for (line, why) in [
        ("this is not json", "not JSON"),
        ("[1, 2]", "a JSON object"),
        (r#"{"cmd": "dance"}"#, "unknown command `dance`"),
        (r#"{"condition": "spring-1000"}"#, "no `cmd`"),
        (r#"{"cmd": "present"}"#, "`condition`"),
        (
            r#"{"cmd": "present", "condition": "nope"}"#,
            "unknown condition `nope`; the study's: spring-1000",
        ),
        (
            r#"{"cmd": "present", "condition": "spring-1000", "delta": "NaN"}"#,
            "`delta` must be a finite number",
        ),
        (
            r#"{"cmd": "present", "condition": "spring-1000", "duration_s": -1}"#,
            "duration_s = -1",
        ),
        (
            r#"{"cmd": "present", "condition": "spring-1000", "delta": -5000.0, "duration_s": 1}"#,
            "the stimulus is invalid",
        ),
        (r#"{"cmd": "end"}"#, "no open-ended presentation"),
    ] {
        s.send_line(line);
        let r = s.reply();
        let e = error_of(&r);
        assert!(e.contains(why), "`{line}` → {e} (expected `{why}`)");
    }
    let st = s.ask(json!({"cmd": "status"}));
    assert_eq!(
        (st["ok"].clone(), st["state"].clone()),
        (json!(true), json!("idle"))
    );
    assert_eq!(
        st["presented"],
        json!(0),
        "a refused request presents nothing"
    );

    // A timed present: the loop's measures, 0.3 s of loop time (the scene's 500 Hz: 150 ticks).
    let r = s.ask(
        json!({"cmd": "present", "condition": "spring-1000", "delta": 100.0, "duration_s": 0.3}),
    );
    assert_eq!(r["ok"], json!(true), "{r}");
    assert_eq!(
        (r["id"].clone(), r["delta"].clone()),
        (json!(1), json!(100.0))
    );
    // The interval counts executed ticks; its start and end are deadline times, which also count
    // the deadlines a late loop skipped (a loaded machine, --no-rt): at least 0.3 s apart.
    let (t0, t1) = (r["start_s"].as_f64().unwrap(), r["end_s"].as_f64().unwrap());
    assert_eq!(r["ticks"], json!(150), "{r}");
    assert!(t1 - t0 > 0.3 - 1e-9, "{r}");
    // The follow hand holds the box at rest in free space: nothing is touched.
    assert_eq!(r["peak_force_n"], json!(0.0));
    assert_eq!(r["mcap"], Value::Null, "no --out, no log");

    // An open-ended present: acknowledged, a second one refused, `end` returns the measures.
    let a = s.ask(json!({"cmd": "present", "condition": "spring-1000"}));
    assert_eq!(
        (a["ok"].clone(), a["until"].clone(), a["id"].clone()),
        (json!(true), json!("end"), json!(2))
    );
    let busy = s.ask(json!({"cmd": "present", "condition": "spring-1000", "duration_s": 1}));
    assert!(error_of(&busy).contains("presentation 2 is still running"));
    std::thread::sleep(Duration::from_millis(200));
    let st = s.ask(json!({"cmd": "status"}));
    assert_eq!(
        (st["state"].clone(), st["current"].clone()),
        (json!("presenting"), json!(2))
    );
    let e = s.ask(json!({"cmd": "end"}));
    assert_eq!(
        (e["ok"].clone(), e["cmd"].clone(), e["id"].clone()),
        (json!(true), json!("end"), json!(2))
    );
    assert!(
        e["end_s"].as_f64().unwrap() - e["start_s"].as_f64().unwrap() > 0.1,
        "{e}"
    );

    let stop = s.ask(json!({"cmd": "stop"}));
    assert_eq!(stop, json!({"ok": true, "cmd": "stop"}));
    let (code, out) = s.exit();
    assert_eq!(code, Some(0), "{out}");
    assert!(
        out.contains("stopped: stopped by the client; torques were set to zero"),
        "{out}"
    );
}

/// SIGINT while a presentation runs: the server answers it with the reason (torques zeroed), ends
/// with exit 130, and the presentation's MCAP log is finished (`--out`).
#[test]
fn sigint_answers_the_pending_presentation_zeroes_the_torques_and_exits_130() {
    let _m = crate::common::module_turn(module_path!());
    let out_dir = crate::common::temp_dir("cli-study-serve", "sigint");
    let out_arg = out_dir.display().to_string();
    let mut s = Served::start("follow", &["--out", &out_arg]);
    let a = s.ask(json!({"cmd": "present", "condition": "spring-1000", "delta": null}));
    assert_eq!(a["ok"], json!(true), "{a}");
    std::thread::sleep(Duration::from_millis(300));
    assert!(signal(s.child.id(), "-INT"));
    let r = s.reply();
    let e = error_of(&r);
    assert_eq!(r["cmd"], json!("present"));
    assert!(
        e.contains("interrupted by a signal") && e.contains("torques were set to zero"),
        "{e}"
    );
    let last = s.reply();
    assert_eq!(last["cmd"], json!("server"), "{last}");
    let (code, out) = s.exit();
    assert_eq!(code, Some(130), "{out}");
    assert!(out.contains("1 interrupted trial(s)"), "{out}");
    assert!(out_dir.join("trials/trial-0001.mcap").is_file());
}

/// One client at a time: a second connection is told so and closed. A client that goes away ends
/// its open-ended presentation, and the server serves the next client.
#[test]
fn a_second_client_is_refused_and_a_lost_clients_presentation_is_ended() {
    let _m = crate::common::module_turn(module_path!());
    let mut s = Served::start("follow", &[]);
    let addr = s.conn.get_ref().peer_addr().unwrap();
    let a = s.ask(json!({"cmd": "present", "condition": "spring-1000"}));
    assert_eq!(a["until"], json!("end"), "{a}");
    let mut second = BufReader::new(TcpStream::connect(addr).unwrap());
    let mut line = String::new();
    second.read_line(&mut line).unwrap();
    assert!(line.contains("another client is connected"), "{line}");
    line.clear();
    assert_eq!(second.read_line(&mut line).unwrap(), 0, "then closed");
    // The first client goes away mid-presentation; the next one finds it ended.
    let Served { child, conn } = s;
    drop(conn);
    let stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    let mut s = Served {
        child,
        conn: BufReader::new(stream),
    };
    let t0 = std::time::Instant::now();
    loop {
        let st = s.ask(json!({"cmd": "status"}));
        if st["state"] == json!("idle") {
            assert_eq!(st["presented"], json!(1), "{st}");
            break;
        }
        assert!(t0.elapsed() < Duration::from_secs(30), "still {st}");
        std::thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(s.ask(json!({"cmd": "stop"}))["ok"], json!(true));
    assert_eq!(s.exit().0, Some(0));
}

/// A safety stop (here a scripted 50 N push, after 3 s of holding, drives the handle past the
/// workspace edge: the latch trips) ends the server with exit 3; the pending presentation is
/// answered with the trip's reason, and a last line says why the server ended.
#[test]
fn a_safety_stop_answers_the_pending_presentation_with_the_trip_and_exits_3() {
    let _m = crate::common::module_turn(module_path!());
    let mut s = Served::start("script:3.0,-50,0,0,10", &[]);
    let r = s.ask(json!({"cmd": "present", "condition": "spring-1000", "duration_s": 20}));
    let e = error_of(&r);
    assert_eq!(r["cmd"], json!("present"));
    assert!(
        e.contains("safety stop")
            && e.contains("past the workspace edge")
            && e.contains("torques were set to zero"),
        "{e}"
    );
    let last = s.reply();
    assert_eq!(last["cmd"], json!("server"), "{last}");
    let (code, out) = s.exit();
    assert_eq!(code, Some(3), "{out}");
}

/// A lost device (the UDP reference device, devices/udp/sim_device.py, killed mid-presentation)
/// ends the server as `haptic2d run`: exit 4, the pending presentation answered with the reason.
#[test]
fn a_lost_device_answers_the_pending_presentation_and_exits_4() {
    let _m = crate::common::module_turn(module_path!());
    let (mut dev, dev_addr) = spawn_announced(
        Command::new("python3")
            .arg(crate::common::root().join("devices/udp/sim_device.py"))
            .args(["--bind", "127.0.0.1:0"]),
        "listening on ",
    );
    let file =
        crate::common::patient_device_file("udp-pantograph.toml", ("3", "50"), "serve", "udp.toml");
    let device = format!("udp:{dev_addr}");
    let file_arg = file.display().to_string();
    let mut s = Served::start_on(&device, &["--device-file", &file_arg]);
    let a = s.ask(json!({"cmd": "present", "condition": "spring-1000"}));
    assert_eq!(a["ok"], json!(true), "{a}");
    std::thread::sleep(Duration::from_millis(300));
    dev.kill().unwrap();
    let r = s.reply();
    let e = error_of(&r);
    assert!(e.contains("torques were set to zero"), "{e}");
    let (code, out) = s.exit();
    assert_eq!(code, Some(4), "{out}");
}

/// The server has no key: any address beyond loopback is refused before the device is opened.
#[test]
fn a_listen_address_beyond_loopback_is_refused() {
    let _m = crate::common::module_turn(module_path!());
    let o = Command::new(BIN)
        .args(["study", "serve"])
        .arg(study())
        .args(["--headless", "--listen", "0.0.0.0:7341"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("loopback only"), "{err}");
    let o = Command::new(BIN)
        .args(["study", "serve"])
        .arg(study())
        .args(["--headless", "--device", "sim", "--hand", "bogus"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}
