//! Load client for the live display: `N` WebSocket viewers connected to a running `haptic2d run`
//! for `S` seconds, each reading every message (as a browser tab would). Prints the frames each
//! viewer received. Loopback only; bounded in time.
//!
//! Usage: `cargo run --release -p haptic2d-cli --example ws_viewers -- 127.0.0.1:8080 5 12`

use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: ws_viewers ADDR:PORT [VIEWERS=5] [SECONDS=12]";
    let Some(addr) = args.first().and_then(|a| a.parse::<SocketAddr>().ok()) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    if !addr.ip().is_loopback() {
        eprintln!("ws_viewers: loopback addresses only (got {addr})");
        std::process::exit(2);
    }
    let n: usize = args.get(1).and_then(|v| v.parse().ok()).unwrap_or(5);
    let secs: f64 = args.get(2).and_then(|v| v.parse().ok()).unwrap_or(12.0);
    let end = Instant::now() + Duration::from_secs_f64(secs);
    let viewers: Vec<_> = (0..n)
        .map(|i| {
            std::thread::spawn(move || {
                // Retry until the server is up (it may be started right after this client).
                let stream = loop {
                    match TcpStream::connect(addr) {
                        Ok(s) => break s,
                        Err(_) if Instant::now() < end => {
                            std::thread::sleep(Duration::from_millis(50))
                        }
                        Err(e) => return Err(format!("viewer {i}: {e}")),
                    }
                };
                stream
                    .set_read_timeout(Some(Duration::from_millis(500)))
                    .map_err(|e| e.to_string())?;
                let (mut ws, _) = tungstenite::client(format!("ws://{addr}/ws"), stream)
                    .map_err(|e| format!("viewer {i}: {e}"))?;
                let (mut frames, mut bytes) = (0u64, 0u64);
                while Instant::now() < end {
                    match ws.read() {
                        Ok(tungstenite::Message::Text(t)) => {
                            if t.as_str().starts_with(r#"{"type":"frame""#) {
                                frames += 1;
                            }
                            bytes += t.len() as u64;
                        }
                        Ok(_) => {}
                        Err(tungstenite::Error::Io(e))
                            if e.kind() == std::io::ErrorKind::WouldBlock
                                || e.kind() == std::io::ErrorKind::TimedOut => {}
                        Err(_) => break,
                    }
                }
                Ok((frames, bytes))
            })
        })
        .collect();
    for (i, v) in viewers.into_iter().enumerate() {
        match v.join() {
            Ok(Ok((f, b))) => println!("viewer {i}: {f} frames, {b} bytes"),
            Ok(Err(e)) => println!("{e}"),
            Err(_) => println!("viewer {i}: panicked"),
        }
    }
}
