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

use haptic2d_test_support::browser::{e2e_dir, require_prerequisites, run_script};
use haptic2d_test_support::process::Served;
use std::process::{Command, Stdio};
use std::time::Duration;

/// `haptic2d run` with its display on a free loopback port; killed on drop.
fn start_run() -> Served {
    Served::start(
        Command::new(env!("CARGO_BIN_EXE_haptic2d"))
            .args(["run", "box-in-walls", "--device", "sim", "--hand", "follow"])
            .args(["--bind", "127.0.0.1:0", "--duration", "150"])
            .stderr(Stdio::inherit()),
        Some("haptic2d"),
    )
}

#[test]
fn browser_drag_hand_target_pushes_box_into_left_wall() {
    let _m = crate::common::module_turn(module_path!());
    let e2e = e2e_dir();
    // Never reported as passed without running: a missing prerequisite is a failure that says
    // how to install it (the README's test command, `bash scripts/test.sh`, installs it).
    require_prerequisites(&e2e);
    let run = start_run();
    let end = run_script(&e2e, "view_e2e.mjs", &[&run.url], Duration::from_secs(120));
    let (stdout, stderr) = (end.stdout, end.stderr);
    let status = end.status.expect("the e2e script finished within 120 s");
    assert!(
        status.success(),
        "the browser e2e script failed ({status}):\n{stdout}\n{stderr}"
    );
    assert!(stdout.contains(r#""ok":true"#), "{stdout}");
}
