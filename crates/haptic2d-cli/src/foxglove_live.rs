//! `haptic2d run --foxglove ADDR:PORT`: a Foxglove WebSocket live server (protocol
//! `foxglove.websocket.v1`: Foxglove's "Foxglove WebSocket" connection).
//!
//! It runs on its own thread and reads the loop's **latest** telemetry snapshot (the triple buffer
//! of the telemetry channel) at its own rate (default 60 Hz): the haptic loop never waits for it.
//! Each frame it sends the channels a client subscribed to, encoded exactly as in an MCAP log (the
//! same encoders), so the same Foxglove layout works live and on a recording.
//!
//! Who may connect, and what a client can cost the others (issue 38):
//!
//! - **Origin**: the rule of the display's access check, reused
//!   ([`haptic2d_view::access::check_page_origin`]): a program without `Origin` (Foxglove's desktop
//!   app, scripts) and pages of the Foxglove app ([`ALLOWED_ORIGINS`]) or on loopback are served;
//!   any other web page the user has open is refused at the upgrade (HTTP 403), so it cannot read
//!   the telemetry, the scene or the device files.
//! - **Address**: loopback only, unless `--foxglove-allow-remote` (a warning is printed).
//! - **No stalls**: every socket is non-blocking, the WebSocket handshake included (a connection
//!   that sends nothing is dropped after [`HANDSHAKE_TIMEOUT`] without ever blocking the thread);
//!   each connection has its own bounded send queue ([`MAX_CLIENT_BUFFER`]): a frame that does not
//!   fit is dropped for that client alone and counted ([`FoxgloveStats`]).
//!
//! Protocol subset: the server sends `serverInfo` and `advertise` (channels with their JSON
//! Schemas) on connect, accepts `subscribe` / `unsubscribe`, answers anything else with a `status`
//! warning, and sends message data as binary frames `[0x01][subscription id u32 LE][log time u64
//! LE][JSON payload]`. The log time is Unix-epoch ns, as in a recording: the tick's
//! `CLOCK_MONOTONIC` deadline plus the offset read when the server started
//! ([`haptic2d_rt::mcap::clock`]).

use haptic2d_rt::mcap::clock::monotonic_to_unix_offset_ns;
use haptic2d_rt::mcap::columns::tick_json_schema;
use haptic2d_rt::mcap::encode::{
    encode_bodies, encode_contacts, encode_energy, encode_frame_transforms, encode_scene_update,
    encode_tick,
};
use haptic2d_rt::mcap::schemas::*;
use haptic2d_rt::mcap::{LoggedTick, McapSetup};
use haptic2d_rt::SnapshotRx;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::io::ErrorKind;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
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

/// Bytes a client may have queued; a frame that would exceed it is dropped for that client (and
/// counted), the connection kept.
pub const MAX_CLIENT_BUFFER: usize = 1 << 20;

/// The origins of the Foxglove app's pages allowed besides loopback pages.
pub const ALLOWED_ORIGINS: [&str; 1] = ["https://app.foxglove.dev"];

/// Time a connection has to complete its WebSocket handshake.
pub const HANDSHAKE_TIMEOUT: Duration = Duration::from_secs(2);

/// Connections served at once; more are closed at accept.
pub const MAX_CLIENTS: usize = 16;

/// Connections in their handshake at once; more are closed at accept.
pub const MAX_PENDING: usize = 16;

/// What the server did, reported at shutdown.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FoxgloveStats {
    /// WebSocket connections served.
    pub served: u64,
    /// Upgrades refused for their `Origin`.
    pub refused_origin: u64,
    /// Connections closed for not completing the handshake in time, or over the connection caps.
    pub dropped_connections: u64,
    /// Frames sent.
    pub frames_sent: u64,
    /// Frames dropped for a client whose send queue was full.
    pub frames_dropped: u64,
}

impl std::fmt::Display for FoxgloveStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "foxglove: {} connections served, {} refused (origin), {} closed (no handshake in time, or over the caps); {} frames sent, {} dropped for slow clients",
            self.served, self.refused_origin, self.dropped_connections, self.frames_sent, self.frames_dropped
        )
    }
}

/// Channel ids advertised (1-based, in this order).
const CHANNELS: [(&str, &str); 6] = [
    (TOPIC_TICK, SCHEMA_TICK),
    (TOPIC_BODIES, SCHEMA_BODIES),
    (TOPIC_CONTACTS, SCHEMA_CONTACTS),
    (TOPIC_ENERGY, SCHEMA_ENERGY),
    (TOPIC_SCENE_UPDATE, SCHEMA_SCENE_UPDATE),
    (TOPIC_TF, SCHEMA_TF),
];

/// The running server; dropping it (or [`shutdown`](Self::shutdown)) stops it.
pub struct FoxgloveServer {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<FoxgloveStats>>,
}

impl FoxgloveServer {
    /// Binds `addr` (an error now if the port is taken) and starts serving the snapshots of
    /// `latest` at `rate_hz`, describing the world of `setup`. An address beyond loopback needs
    /// `allow_remote` (the caller prints the warning).
    pub fn start(
        addr: SocketAddr,
        latest: SnapshotRx<LoggedTick>,
        setup: McapSetup,
        rate_hz: f64,
        allow_remote: bool,
    ) -> Result<Self, String> {
        if !(rate_hz.is_finite() && rate_hz > 0.0 && rate_hz <= 1000.0) {
            return Err(format!(
                "--foxglove-rate must be in (0, 1000] Hz, got {rate_hz}\n    fix: e.g. --foxglove-rate 60"
            ));
        }
        check_address(addr, allow_remote)?;
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

    /// The address served (the port chosen, for port 0).
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Stops the server, closes every connection and returns what it did.
    pub fn shutdown(mut self) -> FoxgloveStats {
        self.stop_thread()
    }

    fn stop_thread(&mut self) -> FoxgloveStats {
        self.stop.store(true, Ordering::Release);
        match self.thread.take() {
            Some(t) => {
                t.thread().unpark();
                t.join().unwrap_or_default()
            }
            None => FoxgloveStats::default(),
        }
    }
}

impl Drop for FoxgloveServer {
    fn drop(&mut self) {
        self.stop_thread();
    }
}

/// `--foxglove ADDR`: loopback, or beyond it only with `allow_remote`.
pub fn check_address(addr: SocketAddr, allow_remote: bool) -> Result<(), String> {
    if addr.ip().is_loopback() || allow_remote {
        return Ok(());
    }
    Err(format!(
        "--foxglove {addr}: beyond loopback, anyone who can reach this machine could read the telemetry, the scene and the device files\n    fix: --foxglove 127.0.0.1:{} (Foxglove on this machine), or add --foxglove-allow-remote to serve the network on purpose",
        addr.port()
    ))
}

/// The warning printed when the live server is bound beyond loopback.
pub fn remote_warning(addr: SocketAddr) -> Option<String> {
    (!addr.ip().is_loopback()).then(|| {
        format!("warning: the Foxglove live server listens beyond loopback at {addr} (--foxglove-allow-remote): anyone who can reach it can read the telemetry, the scene and the device files")
    })
}

/// The upgrade's `Origin` check (see the module docs), as tungstenite's handshake callback.
struct OriginCheck {
    refused: Arc<AtomicU64>,
}

impl tungstenite::handshake::server::Callback for OriginCheck {
    // The error type is tungstenite's, not ours to shrink.
    #[allow(clippy::result_large_err)]
    fn on_request(self, req: &Request, mut resp: Response) -> Result<Response, ErrorResponse> {
        if let Err(why) = haptic2d_view::access::check_page_origin(req.headers(), &ALLOWED_ORIGINS)
        {
            self.refused.fetch_add(1, Ordering::Relaxed);
            let mut r = ErrorResponse::new(Some(why));
            *r.status_mut() = tungstenite::http::StatusCode::FORBIDDEN;
            return Err(r);
        }
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
    }
}

type Pending = tungstenite::handshake::MidHandshake<
    tungstenite::handshake::server::ServerHandshake<TcpStream, OriginCheck>,
>;

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
    /// Connections in their handshake, with their deadlines.
    pending: Vec<(Pending, Instant)>,
    advertise: String,
    buf: Vec<u8>,
    refused: Arc<AtomicU64>,
    stats: FoxgloveStats,
    /// `CLOCK_REALTIME − CLOCK_MONOTONIC` (ns), read at the start: deadline → Unix-epoch log time.
    unix_offset_ns: u64,
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
            TF_SCHEMA,
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
            pending: Vec::new(),
            refused: Arc::new(AtomicU64::new(0)),
            stats: FoxgloveStats::default(),
            advertise: json!({"op": "advertise", "channels": channels}).to_string(),
            buf: Vec::with_capacity(64 * 1024),
            unix_offset_ns: monotonic_to_unix_offset_ns(),
        }
    }

    fn serve(mut self, period: Duration, stop: &AtomicBool) -> FoxgloveStats {
        let mut next = Instant::now();
        let mut last_sent = u64::MAX;
        while !stop.load(Ordering::Acquire) {
            self.accept();
            self.progress_handshakes();
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
        self.stats.refused_origin = self.refused.load(Ordering::Relaxed);
        self.stats
    }

    /// Accepts every waiting connection and starts its handshake, without blocking: a connection
    /// over the caps is closed at once.
    fn accept(&mut self) {
        loop {
            match self.listener.accept() {
                Ok((stream, _)) => {
                    if self.pending.len() >= MAX_PENDING || self.clients.len() >= MAX_CLIENTS {
                        self.stats.dropped_connections += 1;
                        continue;
                    }
                    if stream.set_nonblocking(true).is_err() {
                        continue;
                    }
                    let _ = stream.set_nodelay(true);
                    let check = OriginCheck {
                        refused: self.refused.clone(),
                    };
                    let config = WebSocketConfig::default()
                        .max_write_buffer_size(MAX_CLIENT_BUFFER)
                        .max_message_size(Some(1 << 20));
                    let r = tungstenite::accept_hdr_with_config(stream, check, Some(config));
                    self.handshake_step(r, Instant::now() + HANDSHAKE_TIMEOUT);
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock => return,
                Err(_) => return,
            }
        }
    }

    /// Moves every pending handshake on as far as its bytes allow; drops the late ones.
    fn progress_handshakes(&mut self) {
        let now = Instant::now();
        for (mid, deadline) in std::mem::take(&mut self.pending) {
            if now > deadline {
                self.stats.dropped_connections += 1;
                continue;
            }
            self.handshake_step(mid.handshake(), deadline);
        }
    }

    fn handshake_step(
        &mut self,
        r: Result<
            WebSocket<TcpStream>,
            tungstenite::HandshakeError<
                tungstenite::handshake::server::ServerHandshake<TcpStream, OriginCheck>,
            >,
        >,
        deadline: Instant,
    ) {
        match r {
            Ok(ws) => {
                if let Some(c) = self.welcome(ws) {
                    self.stats.served += 1;
                    self.clients.push(c);
                }
            }
            Err(tungstenite::HandshakeError::Interrupted(mid)) => {
                self.pending.push((mid, deadline))
            }
            Err(tungstenite::HandshakeError::Failure(_)) => {}
        }
    }

    /// Queues `serverInfo` and `advertise` on a new connection.
    fn welcome(&self, mut ws: WebSocket<TcpStream>) -> Option<Client> {
        let info = json!({"op": "serverInfo", "name": "haptic2d", "capabilities": [],
            "supportedEncodings": [], "metadata": self.setup.scene, "sessionId": format!("{}", std::process::id())});
        queue(&mut ws, Message::text(info.to_string())).ok()?;
        queue(&mut ws, Message::text(self.advertise.clone())).ok()?;
        let _ = ws.flush(); // the rest goes out with the next rounds' flushes
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
                        if queue(&mut c.ws, Message::text(status.to_string())).is_err() {
                            break false;
                        }
                    }
                }
                Ok(Message::Binary(_)) => {
                    let status = json!({"op": "status", "level": 1,
                        "message": "binary client messages are not supported by this server"});
                    if queue(&mut c.ws, Message::text(status.to_string())).is_err() {
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
        let t = snap.deadline_ns.saturating_add(self.unix_offset_ns);
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
                6 if world => encode_frame_transforms(
                    &mut self.buf,
                    &self.names,
                    &snap.world,
                    Some(&snap.rec),
                    t,
                )
                .is_ok(),
                _ => false,
            };
            if !ok {
                continue;
            }
            let buf = &mut self.buf;
            let stats = &mut self.stats;
            self.clients.retain_mut(|c| {
                for (&sub, _) in c.subs.iter().filter(|(_, &v)| v == ch) {
                    buf[1..5].copy_from_slice(&sub.to_le_bytes());
                    match queue(&mut c.ws, Message::binary(buf.clone())) {
                        Ok(true) => stats.frames_sent += 1,
                        // This client's queue is full: the frame is dropped for it alone.
                        Ok(false) => stats.frames_dropped += 1,
                        Err(()) => return false, // closed
                    }
                }
                true
            });
        }
        // Push every queue towards its socket; a full socket keeps the rest for the next round.
        self.clients.retain_mut(|c| match c.ws.flush() {
            Ok(()) => true,
            Err(tungstenite::Error::Io(e))
                if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) =>
            {
                true
            }
            Err(_) => false,
        });
    }
}

/// Queues `msg` on a client's own bounded send queue (tungstenite's write buffer, at most
/// [`MAX_CLIENT_BUFFER`] bytes) and writes what the socket takes without blocking: `Ok(true)`
/// queued, `Ok(false)` dropped (the queue is full: a slow or idle reader), `Err` the connection
/// failed.
fn queue(ws: &mut WebSocket<TcpStream>, msg: Message) -> Result<bool, ()> {
    match ws.write(msg) {
        Ok(()) => Ok(true),
        Err(tungstenite::Error::WriteBufferFull(_)) => Ok(false),
        // Queued in the buffer; the socket takes it later.
        Err(tungstenite::Error::Io(e))
            if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) =>
        {
            Ok(true)
        }
        Err(_) => Err(()),
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

#[cfg(test)]
mod tests {
    use super::*;
    use haptic2d_rt::telemetry_channel;
    use std::collections::BTreeMap;
    use tungstenite::client::IntoClientRequest;

    /// A server on a free loopback port fed by a thread publishing a new tick every millisecond.
    struct Fixture {
        server: Option<FoxgloveServer>,
        stop: Arc<AtomicBool>,
        feeder: Option<JoinHandle<()>>,
    }

    impl Fixture {
        fn start() -> Self {
            let (mut tx, _rx, latest) = telemetry_channel(16, LoggedTick::default()).unwrap();
            let setup = McapSetup::ticks_only(BTreeMap::new());
            let server = FoxgloveServer::start(
                "127.0.0.1:0".parse().unwrap(),
                latest,
                setup,
                DEFAULT_LIVE_RATE_HZ,
                false,
            )
            .unwrap();
            let stop = Arc::new(AtomicBool::new(false));
            let s = stop.clone();
            let feeder = std::thread::spawn(move || {
                let mut t = LoggedTick::default();
                while !s.load(Ordering::Relaxed) {
                    t.index += 1;
                    t.deadline_ns = t.index * 1_000_000;
                    tx.set_latest(t);
                    std::thread::sleep(Duration::from_millis(1));
                }
            });
            Self {
                server: Some(server),
                stop,
                feeder: Some(feeder),
            }
        }

        fn addr(&self) -> SocketAddr {
            self.server.as_ref().unwrap().addr()
        }

        fn finish(mut self) -> FoxgloveStats {
            self.stop.store(true, Ordering::Relaxed);
            self.feeder.take().unwrap().join().unwrap();
            self.server.take().unwrap().shutdown()
        }
    }

    fn connect(
        addr: SocketAddr,
        origin: Option<&str>,
    ) -> Result<WebSocket<TcpStream>, tungstenite::Error> {
        let mut req = format!("ws://{addr}/").into_client_request().unwrap();
        req.headers_mut()
            .insert("Sec-WebSocket-Protocol", SUBPROTOCOL.parse().unwrap());
        if let Some(o) = origin {
            req.headers_mut().insert("Origin", o.parse().unwrap());
        }
        let stream = TcpStream::connect(addr).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_secs(5)))
            .unwrap();
        tungstenite::client(req, stream)
            .map(|(ws, _)| ws)
            .map_err(|e| match e {
                tungstenite::HandshakeError::Failure(e) => e,
                tungstenite::HandshakeError::Interrupted(_) => {
                    panic!("a blocking client handshake was interrupted")
                }
            })
    }

    fn read(ws: &mut WebSocket<TcpStream>) -> Message {
        loop {
            match ws.read() {
                Ok(m) => return m,
                Err(tungstenite::Error::Io(e)) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => panic!("a WebSocket message: {e:?}"),
            }
        }
    }

    /// Reads `serverInfo` and `advertise`, subscribes to the tick channel (id 1) as subscription 3.
    fn subscribe_ticks(ws: &mut WebSocket<TcpStream>) {
        let mut texts = 0;
        while texts < 2 {
            if let Message::Text(_) = read(ws) {
                texts += 1;
            }
        }
        ws.send(Message::text(
            json!({"op": "subscribe", "subscriptions": [{"id": 3, "channelId": 1}]}).to_string(),
        ))
        .unwrap();
    }

    /// Tick frames received in `span`.
    fn frames_in(ws: &mut WebSocket<TcpStream>, span: Duration) -> usize {
        let t0 = Instant::now();
        let mut n = 0;
        while t0.elapsed() < span {
            if let Message::Binary(b) = read(ws) {
                assert_eq!(u32::from_le_bytes(b[1..5].try_into().unwrap()), 3);
                n += 1;
            }
        }
        n
    }

    #[test]
    fn a_page_of_a_foreign_origin_is_refused_and_the_foxglove_app_and_loopback_pages_served() {
        let fx = Fixture::start();
        let addr = fx.addr();
        match connect(addr, Some("https://evil.example")) {
            Err(tungstenite::Error::Http(r)) => assert_eq!(r.status(), 403),
            Err(e) => panic!("expected HTTP 403, got {e:?}"),
            Ok(_) => panic!("a foreign origin was served"),
        }
        for origin in [
            Some("https://app.foxglove.dev"),
            Some("http://127.0.0.1:3000"),
            None,
        ] {
            let mut ws = connect(addr, origin).unwrap_or_else(|e| panic!("{origin:?}: {e:?}"));
            subscribe_ticks(&mut ws);
            assert!(
                frames_in(&mut ws, Duration::from_millis(200)) > 0,
                "{origin:?}"
            );
        }
        let stats = fx.finish();
        assert_eq!(stats.refused_origin, 1, "{stats}");
        assert_eq!(stats.served, 3, "{stats}");
    }

    #[test]
    fn five_idle_connections_do_not_stall_the_stream_of_a_real_client() {
        let fx = Fixture::start();
        let addr = fx.addr();
        // Five TCP connections that never send their upgrade request (the attack: they froze
        // the stream for 2 s each, 116 frames in 12 s), and one that upgrades but never reads.
        let idle: Vec<TcpStream> = (0..5).map(|_| TcpStream::connect(addr).unwrap()).collect();
        let idle_since = Instant::now();
        let mut silent = connect(addr, None).unwrap();
        subscribe_ticks(&mut silent);
        let t0 = Instant::now();
        let mut ws = connect(addr, None).unwrap();
        assert!(
            t0.elapsed() < Duration::from_millis(500),
            "the handshake waited {:?}",
            t0.elapsed()
        );
        subscribe_ticks(&mut ws);
        let span = Duration::from_millis(1500);
        let n = frames_in(&mut ws, span);
        // 60 Hz for 1.5 s is 90 frames; a loaded test machine gets at least two thirds of them.
        assert!(n >= 60, "{n} frames in {span:?} beside 5 idle connections");
        // Past their handshake time the idle connections are closed by the server.
        std::thread::sleep(
            (HANDSHAKE_TIMEOUT + Duration::from_millis(300)).saturating_sub(idle_since.elapsed()),
        );
        let stats = fx.finish();
        assert_eq!(stats.dropped_connections, 5, "{stats}");
        assert_eq!(stats.served, 2, "{stats}");
        drop((idle, silent));
    }
}
