//! The zenoh transport (zenoh 1.x, the synchronous `.wait()` API; zenoh runs its own tokio
//! runtime inside): two sessions in **peer** mode connected directly, the echo side listening on
//! one endpoint (`tcp/127.0.0.1:PORT` or `udp/127.0.0.1:PORT`), the ping side connecting to it,
//! multicast and gossip scouting off (the machine has no network; nothing else is discovered).
//!
//! The ping side publishes each message on [`KEY_TO_WORLD`]; the echo side's subscriber
//! **callback** (on zenoh's receive thread) decodes, verifies and re-encodes it and puts the
//! answer on [`KEY_TO_DEVICE`], where the ping side's subscriber callback records it. Publishers
//! are `express` (no batching). zenoh allocates per message: `put` copies the 252 bytes into a
//! fresh `ZBytes`, and the transport builds a sample per delivery.

use std::sync::Arc;

use haptic2d_devices::world_link::PORT_LEN;
use haptic2d_rt::clock::now_ns;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::{Config, Session, Wait};

use crate::echo::Echo;
use crate::ping::{Answers, Wire};
use crate::udp::{limit, IDLE};

/// Key of the device → world messages.
pub const KEY_TO_WORLD: &str = "haptic2d/bench/to_world";
/// Key of the world → device messages.
pub const KEY_TO_DEVICE: &str = "haptic2d/bench/to_device";

/// A peer-mode configuration without scouting that listens on `listen` and connects to
/// `connect` (zenoh endpoints; empty: none). `lowlatency`: zenoh's LowLatency unicast transport
/// (which needs QoS off).
pub fn config(listen: &[&str], connect: &[&str], lowlatency: bool) -> Result<Config, String> {
    let list = |v: &[&str]| {
        let q: Vec<String> = v.iter().map(|e| format!("\"{e}\"")).collect();
        format!("[{}]", q.join(","))
    };
    let mut c = Config::default();
    let mut set = |k: &str, v: &str| {
        c.insert_json5(k, v)
            .map_err(|e| format!("zenoh config {k}: {e}"))
    };
    set("mode", "\"peer\"")?;
    set("scouting/multicast/enabled", "false")?;
    set("scouting/gossip/enabled", "false")?;
    set("listen/endpoints", &list(listen))?;
    set("connect/endpoints", &list(connect))?;
    if lowlatency {
        set("transport/unicast/lowlatency", "true")?;
        set("transport/unicast/qos/enabled", "false")?;
    }
    Ok(c)
}

fn open(c: Config) -> Result<Session, String> {
    zenoh::open(c)
        .wait()
        .map_err(|e| format!("zenoh open: {e}"))
}

/// The ping side's publisher.
pub struct ZenohWire(Publisher<'static>);

impl Wire for ZenohWire {
    #[inline]
    fn send(&mut self, b: &[u8; PORT_LEN]) -> bool {
        self.0.put(b).wait().is_ok()
    }
}

/// The ping side: a session connected to `endpoint`, its publisher, and the subscriber whose
/// callback hands every answer to `answers` (keep all three alive for the run).
pub fn ping_side(
    endpoint: &str,
    lowlatency: bool,
    answers: Arc<Answers>,
) -> Result<(Session, ZenohWire, Subscriber<()>), String> {
    let session = open(config(&[], &[endpoint], lowlatency)?)?;
    let publisher = session
        .declare_publisher(KEY_TO_WORLD)
        .express(true)
        .wait()
        .map_err(|e| format!("zenoh publisher: {e}"))?;
    let sub = session
        .declare_subscriber(KEY_TO_DEVICE)
        .callback(move |sample| {
            let now = now_ns();
            answers.take(&sample.payload().to_bytes(), now);
        })
        .wait()
        .map_err(|e| format!("zenoh subscriber: {e}"))?;
    Ok((session, ZenohWire(publisher), sub))
}

/// The echo side: listens on `endpoint`, answers every message from its subscriber callback,
/// calls `ready` once both declarations are made, and returns its report after the goodbye.
pub fn echo_side(
    endpoint: &str,
    lowlatency: bool,
    n: usize,
    ready: impl FnOnce(&str),
) -> Result<String, String> {
    let session = open(config(&[endpoint], &[], lowlatency)?)?;
    let publisher = session
        .declare_publisher(KEY_TO_DEVICE)
        .express(true)
        .wait()
        .map_err(|e| format!("zenoh publisher: {e}"))?;
    let echo = Arc::new(Echo::new(n));
    let e2 = echo.clone();
    let sub = session
        .declare_subscriber(KEY_TO_WORLD)
        .callback(move |sample| {
            let now = now_ns();
            let mut out = [0u8; PORT_LEN];
            if e2.answer(&sample.payload().to_bytes(), now, &mut out) {
                let _ = publisher.put(out).wait();
            }
        })
        .wait()
        .map_err(|e| format!("zenoh subscriber: {e}"))?;
    ready(endpoint);
    echo.wait_done(IDLE, limit(n));
    let _ = sub.undeclare().wait();
    let _ = session.close().wait();
    Ok(echo.report())
}
