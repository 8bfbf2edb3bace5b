//! End-to-end test in a real browser: starts the real `haptic2d run` (default scene box-in-walls,
//! simulated device, `--hand follow`) with its display on a free loopback port, and runs
//! `crates/haptic2d-view/e2e/view_e2e.mjs` (playwright-core driving Debian's headless Chromium)
//! against it: the world is drawn, dragging the hand target pushes the box into the left wall, and
//! the state stream shows the box moving and the contact; scenes the loop cannot run at its rate
//! are greyed out; a page from another origin (`http://evil.example`) gets a view-only WebSocket,
//! its commands are refused and the loop's state does not change (docs/DISPLAY.md).
//!
//! Needs `/usr/bin/chromium` (or `CHROMIUM_PATH`), `node` and `e2e/node_modules` (run
//! `bash crates/haptic2d-view/e2e/install.sh`; the README's test command `bash scripts/test.sh`
//! runs it). When they are missing the test FAILS with that hint: it is never reported as passed
//! without running. Set `HAPTIC2D_VIEW_SCREENSHOT=/path/shot.png` to keep a screenshot of the page
//! (docs/screenshot.png is taken this way: docs/DISPLAY.md).

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// `haptic2d run` with its display on a free loopback port; killed on drop.
struct Run {
    child: Child,
    url: String,
}

impl Run {
    fn start() -> Run {
        let mut child = Command::new(env!("CARGO_BIN_EXE_haptic2d"))
            .args([
                "run",
                "box-in-walls",
                "--device",
                "sim",
                "--hand",
                "follow",
                "--bind",
                "127.0.0.1:0",
                "--duration",
                "150",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("haptic2d starts");
        let out = child.stdout.take().expect("piped stdout");
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines() {
                let Ok(line) = line else { break };
                println!("haptic2d: {line}");
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let banner = match rx.recv_timeout(Duration::from_secs(30)) {
            Ok(l) => l,
            Err(e) => {
                let _ = child.kill();
                panic!("haptic2d run printed no banner within 30 s: {e}");
            }
        };
        let url = banner
            .split_whitespace()
            .find(|w| w.starts_with("http://"))
            .unwrap_or_else(|| panic!("no URL in the banner `{banner}`"))
            .to_string();
        Run { child, url }
    }
}

impl Drop for Run {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn missing_prerequisites(e2e: &Path) -> Vec<String> {
    let mut missing = Vec::new();
    let chromium = std::env::var("CHROMIUM_PATH").unwrap_or_else(|_| "/usr/bin/chromium".into());
    if !Path::new(&chromium).exists() {
        missing.push(format!("chromium ({chromium})"));
    }
    let node_ok = Command::new("node")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !node_ok {
        missing.push("node".into());
    }
    if !e2e
        .join("node_modules/playwright-core/package.json")
        .exists()
    {
        missing.push("e2e/node_modules (npm ci)".into());
    }
    missing
}

#[test]
fn browser_drag_hand_target_pushes_box_into_left_wall() {
    let e2e = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../haptic2d-view/e2e");
    let missing = missing_prerequisites(&e2e);
    if !missing.is_empty() {
        let msg = format!(
            "browser e2e prerequisites missing: {}. Run `bash crates/haptic2d-view/e2e/install.sh`",
            missing.join(", ")
        );
        // Never reported as passed without running: a missing prerequisite is a failure that says
        // how to install it (the README's test command, `bash scripts/test.sh`, installs it).
        panic!("{msg}");
    }

    let run = Run::start();
    let mut node = Command::new("node")
        .arg(e2e.join("view_e2e.mjs"))
        .arg(&run.url)
        .current_dir(&e2e)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("node starts");
    let deadline = Instant::now() + Duration::from_secs(120);
    let status = loop {
        if let Some(s) = node.try_wait().expect("wait on node") {
            break Some(s);
        }
        if Instant::now() > deadline {
            let _ = node.kill();
            break None;
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let out = node.wait_with_output().expect("node output");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("e2e stdout: {stdout}");
    println!("e2e stderr: {stderr}");
    let status = status.expect("the e2e script finished within 120 s");
    assert!(
        status.success(),
        "the browser e2e script failed ({status}):\n{stdout}\n{stderr}"
    );
    assert!(stdout.contains(r#""ok":true"#), "{stdout}");
}
