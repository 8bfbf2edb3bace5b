//! The browser tests' launcher: `crates/haptic2d-view/e2e/*.mjs` scripts run by `node` with
//! playwright-core driving Debian's headless Chromium. A missing prerequisite is a FAILURE that says
//! how to install it (`bash crates/haptic2d-view/e2e/install.sh`): never a test reported as passed
//! without running.

use crate::process::wait_with_limit_split;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::Duration;

/// The e2e directory (`crates/haptic2d-view/e2e`: the scripts and their `node_modules`).
pub fn e2e_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../haptic2d-view/e2e")
}

/// What the browser tests need and this machine lacks: Chromium (`/usr/bin/chromium` or
/// `CHROMIUM_PATH`), `node`, and `e2e/node_modules` with playwright-core.
pub fn missing_prerequisites(e2e: &Path) -> Vec<String> {
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

/// Panics, naming what is missing and the install command, unless every prerequisite is there.
pub fn require_prerequisites(e2e: &Path) {
    let missing = missing_prerequisites(e2e);
    assert!(
        missing.is_empty(),
        "browser e2e prerequisites missing: {}. Run `bash crates/haptic2d-view/e2e/install.sh`",
        missing.join(", ")
    );
}

/// The end of one e2e script.
pub struct ScriptRun {
    /// `None`: killed at the limit.
    pub status: Option<ExitStatus>,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `node e2e/SCRIPT ARGS…` in the e2e directory, at most `limit`; its output is printed (as
/// `e2e stdout:` / `e2e stderr:`) for the test log.
pub fn run_script(e2e: &Path, script: &str, args: &[&str], limit: Duration) -> ScriptRun {
    let node = Command::new("node")
        .arg(e2e.join(script))
        .args(args)
        .current_dir(e2e)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("node starts");
    let (status, stdout, stderr) = wait_with_limit_split(node, limit);
    println!("e2e stdout: {stdout}");
    println!("e2e stderr: {stderr}");
    ScriptRun {
        status,
        stdout,
        stderr,
    }
}
