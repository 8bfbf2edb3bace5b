//! Our link's transport: `std::net::UdpSocket` on 127.0.0.1, one datagram per message, as the
//! world link sends it. Both receivers **block** in `recv` with a 100 ms timeout (so they wake as
//! soon as a datagram arrives, and look at the stop flag at least every 100 ms); the ping side
//! sends from its loop thread and receives on a second thread. Stack buffers only: no allocation
//! per message.

use std::net::UdpSocket;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use haptic2d_devices::world_link::PORT_LEN;
use haptic2d_rt::clock::now_ns;

use crate::echo::Echo;
use crate::ping::{Answers, Wire};

const TIMEOUT: Duration = Duration::from_millis(100);

/// The ping side's UDP socket, connected to the echo side.
pub struct UdpWire(UdpSocket);

impl Wire for UdpWire {
    #[inline]
    fn send(&mut self, b: &[u8; PORT_LEN]) -> bool {
        self.0.send(b).is_ok()
    }
}

/// Opens the ping side towards the echo side at `addr` and starts its receive thread, which
/// hands every datagram to `answers` until `stop` is set.
pub fn ping_side(
    addr: &str,
    answers: Arc<Answers>,
    stop: Arc<AtomicBool>,
) -> Result<(UdpWire, std::thread::JoinHandle<()>), String> {
    let s = UdpSocket::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    s.connect(addr).map_err(|e| format!("{addr}: {e}"))?;
    let r = s.try_clone().map_err(|e| e.to_string())?;
    r.set_read_timeout(Some(TIMEOUT))
        .map_err(|e| e.to_string())?;
    let t = std::thread::spawn(move || {
        let mut buf = [0u8; 512];
        while !stop.load(Ordering::Relaxed) {
            if let Ok(n) = r.recv(&mut buf) {
                answers.take(&buf[..n], now_ns());
            }
        }
    });
    Ok((UdpWire(s), t))
}

/// The echo side: binds 127.0.0.1 on a free port, calls `ready` with the address, then answers
/// every datagram (decode, verify, re-encode: [`Echo::answer`]) until the goodbye or 3 s idle,
/// and returns its report.
pub fn echo_side(n: usize, ready: impl FnOnce(&str)) -> Result<String, String> {
    let s = UdpSocket::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    s.set_read_timeout(Some(TIMEOUT))
        .map_err(|e| e.to_string())?;
    let addr = s.local_addr().map_err(|e| e.to_string())?.to_string();
    let echo = Arc::new(Echo::new(n));
    let stop = Arc::new(AtomicBool::new(false));
    let (e2, stop2) = (echo.clone(), stop.clone());
    let t = std::thread::spawn(move || {
        let mut buf = [0u8; 512];
        let mut out = [0u8; PORT_LEN];
        while !stop2.load(Ordering::Relaxed) {
            if let Ok((k, from)) = s.recv_from(&mut buf) {
                if e2.answer(&buf[..k], now_ns(), &mut out) {
                    let _ = s.send_to(&out, from);
                }
            }
        }
    });
    ready(&addr);
    echo.wait_done(IDLE, limit(n));
    stop.store(true, Ordering::Relaxed);
    let _ = t.join();
    Ok(echo.report())
}

/// The echo side ends this long after the last message if no goodbye comes.
pub const IDLE: Duration = Duration::from_secs(3);

/// The echo side gives up this long after it started: the run's length plus 60 s.
pub fn limit(n: usize) -> Duration {
    Duration::from_millis(n as u64 + 60_000)
}
