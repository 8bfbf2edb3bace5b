//! Starting the demo binary for integration tests.

#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// A running `haptic2d-view-demo`, killed on drop.
pub struct Demo {
    pub child: Child,
    /// The page URL it printed (with `?token=` when commands need one).
    pub url: String,
    /// `host:port`.
    pub addr: String,
    /// Lines the demo prints after the banner (its timing summary at exit).
    pub stdout: mpsc::Receiver<String>,
}

impl Demo {
    /// Starts the demo on a free loopback port with extra arguments; waits for its banner.
    pub fn start(extra: &[&str]) -> Demo {
        let mut child = Command::new(env!("CARGO_BIN_EXE_haptic2d-view-demo"))
            .args(["--bind", "127.0.0.1:0", "--duration", "120"])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("the demo binary starts");
        let out = child.stdout.take().expect("piped stdout");
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let banner = match rx.recv_timeout(Duration::from_secs(30)) {
            Ok(l) => l,
            Err(e) => {
                let _ = child.kill();
                panic!("the demo printed no banner within 30 s: {e}");
            }
        };
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
        Demo {
            child,
            url,
            addr,
            stdout: rx,
        }
    }
}

impl Drop for Demo {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
