//! Helpers shared by the CLI end-to-end tests (each test binary uses some of them).
#![allow(dead_code)]

use std::process::{Command, Output};

/// Runs the `haptic2d` binary built for these tests with `args` and waits for it.
pub fn haptic2d(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_haptic2d"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Standard output and standard error of a finished run, one after the other.
pub fn text(o: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Waits for `child` (spawned with piped stdout and stderr) at most `limit`, reading both pipes on
/// their own threads meanwhile (a child that fills a pipe nobody reads never exits). Returns the
/// exit status and stdout followed by stderr, or `None` (the child killed) if it did not exit in
/// time.
pub fn wait_with_limit(
    mut child: std::process::Child,
    limit: std::time::Duration,
) -> Option<(std::process::ExitStatus, String)> {
    use std::io::Read;
    fn drain(pipe: Option<impl Read + Send + 'static>) -> std::thread::JoinHandle<String> {
        std::thread::spawn(move || {
            let mut s = String::new();
            if let Some(mut p) = pipe {
                let mut bytes = Vec::new();
                let _ = p.read_to_end(&mut bytes);
                s = String::from_utf8_lossy(&bytes).into_owned();
            }
            s
        })
    }
    let (out, err) = (drain(child.stdout.take()), drain(child.stderr.take()));
    let t0 = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    };
    let text = out.join().unwrap() + &err.join().unwrap();
    status.map(|s| (s, text))
}

/// Serialises the tests of one binary that start emulators or devices (keeps the load down).
pub fn turn() -> std::sync::MutexGuard<'static, ()> {
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

/// The repository's root.
pub fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The shipped device file `devices/SHIPPED`, patient about a loaded machine's timing (its
/// `timeout_periods = FROM` line set to `TO`, the missed-deadline check off, the stall limit at 1000
/// periods: the CLI tests check protocols and exit paths, not timing), written as `NAME` into a
/// temp dir of its own (`TAG` tells the tests of one binary apart).
pub fn patient_device_file(
    shipped: &str,
    timeout: (&str, &str),
    tag: &str,
    name: &str,
) -> std::path::PathBuf {
    let from = format!("timeout_periods = {} ", timeout.0);
    let to = format!("timeout_periods = {}", timeout.1);
    let text = std::fs::read_to_string(root().join("devices").join(shipped))
        .unwrap()
        .replace(&from, &to)
        .replace("max_missed_deadlines = 10 ", "max_missed_deadlines = 0  ")
        .replace("max_stall_periods = 5 ", "max_stall_periods = 1000");
    assert!(text.contains(&to) && text.contains("max_missed_deadlines = 0 "));
    assert!(text.contains("max_stall_periods = 1000"));
    let dir = std::env::temp_dir().join(format!(
        "haptic2d-cli-{}-{}-{tag}",
        name.trim_end_matches(".toml"),
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The column `name` of a CSV text with a header line, as numbers.
pub fn column(csv: &str, name: &str) -> Vec<f64> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    lines
        .map(|l| l.split(',').nth(i).unwrap().parse().unwrap())
        .collect()
}
