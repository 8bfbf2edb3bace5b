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

/// Standard output and standard error of a finished run, concatenated.
pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
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
