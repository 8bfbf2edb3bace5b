//! Child processes for the end-to-end tests: killed on drop, started with a first-line handshake
//! (an emulator printing its port, a server printing its URL), waited for with a limit.

use std::io::{BufRead, BufReader, Read};
use std::ops::{Deref, DerefMut};
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Standard output and standard error of a finished run, one after the other.
pub fn text(o: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A child killed (and reaped) on drop: a failing test leaves no emulator behind.
pub struct Killed(pub Child);

impl Deref for Killed {
    type Target = Child;
    fn deref(&self) -> &Child {
        &self.0
    }
}

impl DerefMut for Killed {
    fn deref_mut(&mut self) -> &mut Child {
        &mut self.0
    }
}

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Sends `signal` (a `kill` option: `-INT`, `-STOP`, `-CONT`) to process `pid`; whether `kill`
/// succeeded.
pub fn signal(pid: u32, signal: &str) -> bool {
    Command::new("kill")
        .args([signal, &pid.to_string()])
        .status()
        .is_ok_and(|s| s.success())
}

/// Spawns `cmd` with stdout piped and reads its first line, which must start with `prefix`;
/// returns the child (killed on drop) and the rest of the line, trimmed. Panics naming the line
/// when it is not the expected handshake (the child killed).
pub fn spawn_announced(cmd: &mut Command, prefix: &str) -> (Killed, String) {
    let mut child = Killed(
        cmd.stdout(Stdio::piped())
            .spawn()
            .expect("the child starts"),
    );
    let mut line = String::new();
    let mut out = BufReader::new(child.stdout.take().expect("piped stdout"));
    let _ = out.read_line(&mut line);
    // The pipe stays open (a child printing to a closed pipe would fail); later lines are unread.
    child.stdout = Some(out.into_inner());
    let rest = line
        .trim()
        .strip_prefix(prefix)
        .unwrap_or_else(|| panic!("first line `{}` is not `{prefix}…`", line.trim()))
        .to_string();
    (child, rest)
}

/// A running server that printed a banner with its `http://` URL; killed on drop.
pub struct Served {
    pub child: Killed,
    /// The URL of the banner (with its path and `?token=` when it has them).
    pub url: String,
    /// `host:port` of the URL.
    pub addr: String,
    /// The lines it prints after the banner.
    pub lines: mpsc::Receiver<String>,
}

impl Served {
    /// Spawns `cmd` with stdout piped and waits at most 30 s for its first line, which must hold
    /// an `http://` URL. With `echo`, every line is also printed as `echo: LINE`.
    pub fn start(cmd: &mut Command, echo: Option<&'static str>) -> Served {
        let mut child = Killed(
            cmd.stdout(Stdio::piped())
                .spawn()
                .expect("the server starts"),
        );
        let out = child.stdout.take().expect("piped stdout");
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines() {
                let Ok(line) = line else { break };
                if let Some(label) = echo {
                    println!("{label}: {line}");
                }
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let banner = lines
            .recv_timeout(Duration::from_secs(30))
            .unwrap_or_else(|e| panic!("no banner within 30 s: {e}"));
        let url = banner
            .split_whitespace()
            .find(|w| w.starts_with("http://"))
            .unwrap_or_else(|| panic!("no URL in the banner `{banner}`"))
            .to_string();
        let addr = url
            .trim_start_matches("http://")
            .split('/')
            .next()
            .unwrap_or_default()
            .to_string();
        Served {
            child,
            url,
            addr,
            lines,
        }
    }
}

/// What a child printed, read to the end on a thread of its own.
fn drain(pipe: Option<impl Read + Send + 'static>) -> std::thread::JoinHandle<String> {
    std::thread::spawn(move || {
        let mut bytes = Vec::new();
        if let Some(mut p) = pipe {
            let _ = p.read_to_end(&mut bytes);
        }
        String::from_utf8_lossy(&bytes).into_owned()
    })
}

/// Waits for `child` (spawned with piped stdout and stderr) at most `limit`, reading both pipes on
/// their own threads meanwhile (a child that fills a pipe nobody reads never exits). Returns the
/// exit status (`None`: the child was killed at the limit), stdout and stderr.
pub fn wait_with_limit_split(
    mut child: Child,
    limit: Duration,
) -> (Option<ExitStatus>, String, String) {
    let (out, err) = (drain(child.stdout.take()), drain(child.stderr.take()));
    let deadline = Instant::now() + limit;
    let mut status = None;
    let exited = crate::wait_until(deadline, || {
        status = child.try_wait().ok().flatten();
        status.is_some()
    });
    if !exited {
        let _ = child.kill();
        let _ = child.wait();
    }
    (status, out.join().unwrap(), err.join().unwrap())
}

/// [`wait_with_limit_split`] with stdout followed by stderr, or `None` (the child killed) if it did
/// not exit in time.
pub fn wait_with_limit(child: Child, limit: Duration) -> Option<(ExitStatus, String)> {
    let (status, out, err) = wait_with_limit_split(child, limit);
    status.map(|s| (s, out + &err))
}
