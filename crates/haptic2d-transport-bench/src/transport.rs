//! The transports measured, and one measurement: spawn the echo side as a second process of this
//! binary (`transport-bench echo TRANSPORT ENDPOINT N`), wait for its `ready` line, run the ping
//! side here, and collect both sides' reports.

use std::io::{BufRead, BufReader, Read};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use crate::ping::{self, Answers, PingRun};
use crate::{report, udp, zenoh_link};

/// A transport under measurement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// Our link: one UDP datagram per message (std::net::UdpSocket, blocking receive).
    Udp,
    /// zenoh, peer to peer over TCP on loopback.
    ZenohTcp,
    /// zenoh, peer to peer over UDP on loopback.
    ZenohUdp,
    /// zenoh over TCP with its LowLatency unicast transport (QoS off).
    ZenohTcpLowLatency,
}

/// Every transport, in the order of the report.
pub const ALL: [Transport; 4] = [
    Transport::Udp,
    Transport::ZenohTcp,
    Transport::ZenohUdp,
    Transport::ZenohTcpLowLatency,
];

impl Transport {
    /// The transport's name on the command line and in the report.
    pub fn name(self) -> &'static str {
        match self {
            Self::Udp => "udp",
            Self::ZenohTcp => "zenoh-tcp",
            Self::ZenohUdp => "zenoh-udp",
            Self::ZenohTcpLowLatency => "zenoh-tcp-lowlatency",
        }
    }

    /// The transport named `s`.
    pub fn parse(s: &str) -> Result<Self, String> {
        ALL.into_iter().find(|t| t.name() == s).ok_or_else(|| {
            let names: Vec<&str> = ALL.iter().map(|t| t.name()).collect();
            format!("unknown transport {s:?}: one of {}", names.join(", "))
        })
    }

    /// The endpoint the echo side listens on: UDP picks its own port; for zenoh a port that was
    /// free a moment ago.
    fn endpoint(self) -> Result<String, String> {
        let port = |tcp: bool| -> Result<u16, String> {
            let a = if tcp {
                std::net::TcpListener::bind("127.0.0.1:0").and_then(|l| l.local_addr())
            } else {
                std::net::UdpSocket::bind("127.0.0.1:0").and_then(|s| s.local_addr())
            };
            a.map(|a| a.port()).map_err(|e| e.to_string())
        };
        Ok(match self {
            Self::Udp => "127.0.0.1:0".into(),
            Self::ZenohTcp | Self::ZenohTcpLowLatency => format!("tcp/127.0.0.1:{}", port(true)?),
            Self::ZenohUdp => format!("udp/127.0.0.1:{}", port(false)?),
        })
    }
}

/// The echo role: serves `n` messages on `endpoint`, printing `ready ADDR` once it listens and
/// its report at the end (stdout, read by the ping process).
pub fn echo(t: Transport, endpoint: &str, n: usize) -> Result<(), String> {
    let ready = |addr: &str| println!("ready {addr}");
    let text = match t {
        Transport::Udp => udp::echo_side(n, ready)?,
        _ => zenoh_link::echo_side(endpoint, t == Transport::ZenohTcpLowLatency, n, ready)?,
    };
    println!("{text}");
    Ok(())
}

/// One measurement of `t` over `n` messages: the report's text.
pub fn measure(t: Transport, n: u32) -> Result<String, String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let (endpoint, count) = (t.endpoint()?, n.to_string());
    let mut child = Command::new(exe)
        .args(["echo", t.name(), endpoint.as_str(), count.as_str()])
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start the echo process: {e}"))?;
    let mut out = BufReader::new(child.stdout.take().ok_or("no stdout")?);
    let mut line = String::new();
    out.read_line(&mut line).map_err(|e| e.to_string())?;
    let Some(addr) = line.trim().strip_prefix("ready ") else {
        let _ = child.kill();
        return Err(format!("echo process did not get ready: {line:?}"));
    };
    let answers = Arc::new(Answers::new(n as usize));
    let run = ping_with(t, addr, n, answers.clone());
    if run.is_err() {
        let _ = child.kill();
    }
    let run = run?;
    let mut echo_text = String::new();
    out.read_to_string(&mut echo_text)
        .map_err(|e| e.to_string())?;
    let _ = child.wait();
    Ok(report::text(t.name(), n, &run, &answers, &echo_text))
}

fn ping_with(t: Transport, addr: &str, n: u32, answers: Arc<Answers>) -> Result<PingRun, String> {
    match t {
        Transport::Udp => {
            let stop = Arc::new(AtomicBool::new(false));
            let (mut wire, rx) = udp::ping_side(addr, answers.clone(), stop.clone())?;
            let run = ping::run(&mut wire, &answers, n);
            stop.store(true, Ordering::Relaxed);
            let _ = rx.join();
            run
        }
        _ => {
            let ll = t == Transport::ZenohTcpLowLatency;
            let (session, mut wire, sub) = zenoh_link::ping_side(addr, ll, answers.clone())?;
            let run = ping::run(&mut wire, &answers, n);
            drop(sub);
            drop(wire);
            let _ = zenoh::Wait::wait(session.close());
            run
        }
    }
}
