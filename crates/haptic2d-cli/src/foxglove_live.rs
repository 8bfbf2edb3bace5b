//! `haptic2d run --foxglove ADDR:PORT`: a Foxglove WebSocket live server (protocol
//! `foxglove.websocket.v1`: Foxglove's "Foxglove WebSocket" connection).
//!
//! It runs on its own thread and reads the loop's **latest** telemetry snapshot (the triple buffer
//! of the telemetry channel) at its own rate (default 60 Hz): the haptic loop never waits for it, and
//! a slow or silent client only fills its own bounded send buffer (then it is dropped). Each frame
//! it sends the channels a client subscribed to, encoded exactly as in an MCAP log (the same
//! encoders), so the same Foxglove layout works live and on a recording.
//!
//! Protocol subset: the server sends `serverInfo` and `advertise` (channels with their JSON
//! Schemas) on connect, accepts `subscribe` / `unsubscribe`, answers anything else with a `status`
//! warning, and sends message data as binary frames `[0x01][subscription id u32 LE][log time u64
//! LE][JSON payload]`.

use haptic2d_rt::mcap::columns::tick_json_schema;
use haptic2d_rt::mcap::encode::{
    encode_bodies, encode_contacts, encode_energy, encode_scene_update, encode_tick,
};
use haptic2d_rt::mcap::schemas::*;
use haptic2d_rt::mcap::{LoggedTick, McapSetup};
use haptic2d_rt::SnapshotRx;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::io::ErrorKind;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tungstenite::protocol::WebSocketConfig;
use tungstenite::{Message, WebSocket};

/// The WebSocket subprotocol of the Foxglove WebSocket protocol.
pub const SUBPROTOCOL: &str = "foxglove.websocket.v1";

/// Default rate of the live frames (Hz).
pub const DEFAULT_LIVE_RATE_HZ: f64 = 60.0;

/// Bytes a client may have queued before it is dropped as too slow.
const MAX_CLIENT_BUFFER: usize = 8 << 20;

/// Channel ids advertised (1-based, in this order).
const CHANNELS: [(&str, &str); 5] = [
    (TOPIC_TICK, SCHEMA_TICK),
    (TOPIC_BODIES, SCHEMA_BODIES),
    (TOPIC_CONTACTS, SCHEMA_CONTACTS),
    (TOPIC_ENERGY, SCHEMA_ENERGY),
    (TOPIC_SCENE_UPDATE, SCHEMA_SCENE_UPDATE),
];

/// The running server; dropping it (or [`shutdown`](Self::shutdown)) stops it.
pub struct FoxgloveServer {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl FoxgloveServer {
    /// Binds `addr` (an error now if the port is taken) and starts serving the snapshots of
    /// `latest` at `rate_hz`, describing the world of `setup`.
    pub fn start(
        addr: SocketAddr,
        latest: SnapshotRx<LoggedTick>,
        setup: McapSetup,
        rate_hz: f64,
    ) -> Result<Self, String> {
        if !(rate_hz.is_finite() && rate_hz > 0.0 && rate_hz <= 1000.0) {
            return Err(format!(
                "--foxglove-rate must be in (0, 1000] Hz, got {rate_hz}\n    fix: e.g. --foxglove-rate 60"
            ));
        }
        let listener = TcpListener::bind(addr).map_err(|e| {
            format!("--foxglove {addr}: cannot listen there ({e})\n    fix: choose a free port, e.g. --foxglove 127.0.0.1:8765")
        })?;
        let addr = listener
            .local_addr()
            .map_err(|e| format!("--foxglove {addr}: {e}"))?;
        listener
            .set_nonblocking(true)
            .map_err(|e| format!("--foxglove {addr}: {e}"))?;
        let stop = Arc::new(AtomicBool::new(false));
        let s = stop.clone();
        let period = Duration::from_secs_f64(1.0 / rate_hz);
        let thread = std::thread::Builder::new()
            .name("haptic2d-foxglove".into())
            .spawn(move || Server::new(listener, latest, setup).serve(period, &s))
            .map_err(|e| format!("cannot start the Foxglove server thread: {e}"))?;
        Ok(Self {
            addr,
            stop,
            thread: Some(thread),
        })
    }

    /// The line printed at startup.
    pub fn banner(&self) -> String {
        format!(
            "Foxglove live view: open Foxglove, \"Open connection\" → Foxglove WebSocket → ws://{}",
            self.addr
        )
    }

    /// Stops the server and closes every connection.
    pub fn shutdown(mut self) {
        self.stop_thread();
    }

    fn stop_thread(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            t.thread().unpark();
            let _ = t.join();
        }
    }
}

impl Drop for FoxgloveServer {
    fn drop(&mut self) {
        self.stop_thread();
    }
}

struct Client {
    ws: WebSocket<TcpStream>,
    /// Subscription id → channel id.
    subs: HashMap<u32, u32>,
}

struct Server {
    listener: TcpListener,
    latest: SnapshotRx<LoggedTick>,
    setup: McapSetup,
    names: Vec<String>,
    clients: Vec<Client>,
    advertise: String,
    buf: Vec<u8>,
}

impl Server {
    fn new(listener: TcpListener, latest: SnapshotRx<LoggedTick>, setup: McapSetup) -> Self {
        let tick_schema = tick_json_schema();
        let schemas = [
            tick_schema.as_str(),
            BODIES_SCHEMA,
            CONTACTS_SCHEMA,
            ENERGY_SCHEMA,
            SCENE_UPDATE_SCHEMA,
        ];
        let channels: Vec<Value> = CHANNELS
            .iter()
            .zip(schemas)
            .enumerate()
            .map(|(i, ((topic, name), schema))| {
                json!({"id": i + 1, "topic": topic, "encoding": "json", "schemaName": name,
                       "schema": schema, "schemaEncoding": "jsonschema"})
            })
            .collect();
        let names = setup
            .bodies
            .iter()
            .map(|b| Value::String(b.name.clone()).to_string())
            .collect();
        Self {
            listener,
            latest,
            setup,
            names,
            clients: Vec::new(),
            advertise: json!({"op": "advertise", "channels": channels}).to_string(),
            buf: Vec::with_capacity(64 * 1024),
        }
    }

    fn serve(mut self, period: Duration, stop: &AtomicBool) {
        let mut next = Instant::now();
        let mut last_sent = u64::MAX;
        while !stop.load(Ordering::Acquire) {
            self.accept();
            self.read_clients();
            let now = Instant::now();
            if now >= next {
                next += period;
                if next < now {
                    next = now + period;
                }
                let snap = self.latest.latest();
                if snap.index != last_sent || last_sent == u64::MAX {
                    last_sent = snap.index;
                    self.broadcast(&snap);
                }
            }
            // Wake at the next frame, or sooner to answer clients (at most 5 ms of latency).
            let wait = next
                .saturating_duration_since(Instant::now())
                .min(Duration::from_millis(5));
            std::thread::park_timeout(wait);
        }
        for c in &mut self.clients {
            let _ = c.ws.close(None);
            let _ = c.ws.flush();
        }
    }

    fn accept(&mut self) {
        loop {
            match self.listener.accept() {
                Ok((stream, _)) => {
                    if let Some(c) = self.handshake(stream) {
                        self.clients.push(c);
                    }
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock => return,
                Err(_) => return,
            }
        }
    }

    /// The WebSocket handshake, blocking with a 2 s timeout (on this thread, never the loop's),
    /// then the stream becomes non-blocking; `serverInfo` and `advertise` are queued.
    fn handshake(&self, stream: TcpStream) -> Option<Client> {
        stream.set_nonblocking(false).ok()?;
        stream.set_read_timeout(Some(Duration::from_secs(2))).ok()?;
        stream
            .set_write_timeout(Some(Duration::from_secs(2)))
            .ok()?;
        let _ = stream.set_nodelay(true);
        // The error type is tungstenite's (its `Callback` trait), not ours to shrink.
        #[allow(clippy::result_large_err)]
        let cb = |req: &Request, mut resp: Response| -> Result<Response, ErrorResponse> {
            let offered = req
                .headers()
                .get_all("Sec-WebSocket-Protocol")
                .iter()
                .filter_map(|v| v.to_str().ok())
                .flat_map(|v| v.split(','))
                .any(|p| p.trim() == SUBPROTOCOL);
            if offered {
                resp.headers_mut().insert(
                    "Sec-WebSocket-Protocol",
                    tungstenite::http::HeaderValue::from_static(SUBPROTOCOL),
                );
            }
            Ok(resp)
        };
        let config = WebSocketConfig::default()
            .max_write_buffer_size(MAX_CLIENT_BUFFER)
            .max_message_size(Some(1 << 20));
        let mut ws = tungstenite::accept_hdr_with_config(stream, cb, Some(config)).ok()?;
        ws.get_mut().set_nonblocking(true).ok()?;
        let info = json!({"op": "serverInfo", "name": "haptic2d", "capabilities": [],
            "supportedEncodings": [], "metadata": self.setup.scene, "sessionId": format!("{}", std::process::id())});
        ws.send(Message::text(info.to_string())).ok()?;
        ws.send(Message::text(self.advertise.clone())).ok()?;
        Some(Client {
            ws,
            subs: HashMap::new(),
        })
    }

    /// Reads every waiting client message; drops clients that closed or failed.
    fn read_clients(&mut self) {
        self.clients.retain_mut(|c| loop {
            match c.ws.read() {
                Ok(Message::Text(t)) => {
                    if let Err(e) = handle(c, t.as_str()) {
                        let status = json!({"op": "status", "level": 1, "message": e});
                        if c.ws.send(Message::text(status.to_string())).is_err() {
                            break false;
                        }
                    }
                }
                Ok(Message::Binary(_)) => {
                    let status = json!({"op": "status", "level": 1,
                        "message": "binary client messages are not supported by this server"});
                    if c.ws.send(Message::text(status.to_string())).is_err() {
                        break false;
                    }
                }
                Ok(Message::Close(_)) => break false,
                Ok(_) => {}
                // Interrupted (a signal, or SIGSTOP/SIGCONT): nothing lost, try again next round.
                Err(tungstenite::Error::Io(e))
                    if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) =>
                {
                    break match c.ws.flush() {
                        Ok(()) => true,
                        Err(tungstenite::Error::Io(e))
                            if matches!(
                                e.kind(),
                                ErrorKind::WouldBlock | ErrorKind::Interrupted
                            ) =>
                        {
                            true
                        }
                        Err(_) => false,
                    };
                }
                Err(_) => break false,
            }
        });
    }

    fn broadcast(&mut self, snap: &LoggedTick) {
        if self.clients.iter().all(|c| c.subs.is_empty()) {
            return;
        }
        let t = snap.deadline_ns;
        for ch in 1..=CHANNELS.len() as u32 {
            if !self
                .clients
                .iter()
                .any(|c| c.subs.values().any(|&v| v == ch))
            {
                continue;
            }
            let world = snap.world.body_count > 0;
            self.buf.clear();
            self.buf.extend_from_slice(&[0x01, 0, 0, 0, 0]);
            self.buf.extend_from_slice(&t.to_le_bytes());
            let ok = match ch {
                1 => encode_tick(&mut self.buf, snap).is_ok(),
                2 if world => encode_bodies(&mut self.buf, &self.names, &snap.world).is_ok(),
                3 if world => encode_contacts(&mut self.buf, &self.names, &snap.world).is_ok(),
                4 if world => encode_energy(&mut self.buf, &snap.world).is_ok(),
                5 if world => encode_scene_update(
                    &mut self.buf,
                    &self.setup.bodies,
                    &self.names,
                    &snap.world,
                    t,
                )
                .is_ok(),
                _ => false,
            };
            if !ok {
                continue;
            }
            let buf = &mut self.buf;
            self.clients.retain_mut(|c| {
                for (&sub, _) in c.subs.iter().filter(|(_, &v)| v == ch) {
                    buf[1..5].copy_from_slice(&sub.to_le_bytes());
                    match c.ws.send(Message::binary(buf.clone())) {
                        Ok(()) => {}
                        Err(tungstenite::Error::Io(e))
                            if matches!(
                                e.kind(),
                                ErrorKind::WouldBlock | ErrorKind::Interrupted
                            ) => {}
                        Err(_) => return false, // closed, or its buffer is full: too slow
                    }
                }
                true
            });
        }
    }
}

/// Handles one client text message; an error is the text of the `status` reply.
fn handle(c: &mut Client, text: &str) -> Result<(), String> {
    let v: Value =
        serde_json::from_str(text).map_err(|e| format!("the message is not JSON: {e}"))?;
    match v.get("op").and_then(Value::as_str) {
        Some("subscribe") => {
            let subs = v
                .get("subscriptions")
                .and_then(Value::as_array)
                .ok_or("subscribe needs an array `subscriptions` of {id, channelId}")?;
            for s in subs {
                let id = s.get("id").and_then(Value::as_u64);
                let ch = s.get("channelId").and_then(Value::as_u64);
                match (id, ch) {
                    (Some(id), Some(ch)) if (1..=CHANNELS.len() as u64).contains(&ch) && id <= u32::MAX as u64 => {
                        c.subs.insert(id as u32, ch as u32);
                    }
                    _ => return Err(format!("bad subscription {s}: needs an id (u32) and a channelId from the advertisement")),
                }
            }
            Ok(())
        }
        Some("unsubscribe") => {
            let ids = v
                .get("subscriptionIds")
                .and_then(Value::as_array)
                .ok_or("unsubscribe needs an array `subscriptionIds`")?;
            for id in ids.iter().filter_map(Value::as_u64) {
                c.subs.remove(&(id as u32));
            }
            Ok(())
        }
        Some(op) => Err(format!("operation `{op}` is not supported by this server")),
        None => Err("the message has no `op`".into()),
    }
}
