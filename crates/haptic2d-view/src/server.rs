//! The display server: axum on its own thread with its own tokio runtime.
//!
//! - `GET /` the page, `GET /app.js` its script (both embedded in the binary);
//! - `GET /ws` the WebSocket: server → page `welcome`, `scene`, `frame`, `ack`, `error` messages
//!   (JSON text, `{"type": …}`); page → server commands (see [`crate::command`]);
//! - `GET /health` the plain text `ok`.
//!
//! A broadcaster task reads the latest [`Frame`](crate::Frame) from the triple buffer at the frame
//! rate, serialises it once and hands the text to every viewer through a `tokio::sync::broadcast`
//! channel; a viewer that falls behind skips frames (never the loop, never the other viewers).
//!
//! When the server listens on a non-loopback address, commands need the token of
//! [`ViewHandle::token`] (in the WebSocket URL `?token=…` or a first message
//! `{"type": "hello", "token": "…"}`); viewing never does.

use crate::command::MAX_MESSAGE_BYTES;
use crate::command::{parse_client_message, scene_names, ClientMessage, Command, ControllerKind};
use crate::frame::Frame;
use crate::hub::ServerEnd;
use crate::scene_info::SceneInfo;
use axum::extract::ws::{Message, Utf8Bytes, WebSocket, WebSocketUpgrade};
use axum::extract::{ConnectInfo, RawQuery, State};
use axum::http::header;
use axum::response::{Html, IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NORMAL_MODEL_NAMES;
use serde::Serialize;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;
use tokio::sync::{broadcast, watch};

/// The page, embedded.
pub const INDEX_HTML: &str = include_str!("page/index.html");
/// The page's script, embedded.
pub const APP_JS: &str = include_str!("page/app.js");

/// A WebSocket message larger than this closes the connection (bytes); between
/// [`MAX_MESSAGE_BYTES`] and this, the client gets an error frame and stays connected.
pub const HARD_MESSAGE_LIMIT: usize = 64 * 1024;
/// Error lines logged per connection before that connection's errors are no longer logged.
const LOG_BUDGET: u32 = 20;

/// Options of [`ViewServer::start`].
#[derive(Clone, Debug, Default)]
pub struct ViewOptions {
    /// Commands need a token: `None` = only when bound to a non-loopback address (default).
    pub require_token: Option<bool>,
    /// The token to use instead of a random one (tests).
    pub token: Option<String>,
}

/// Counters of a running server.
#[derive(Debug, Default)]
struct Counters {
    frames_broadcast: AtomicU64,
    commands_forwarded: AtomicU64,
    bad_messages: AtomicU64,
}

/// A snapshot of the server's counters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ServerStats {
    /// Frames serialised and broadcast so far.
    pub frames_broadcast: u64,
    /// Commands handed to the loop so far.
    pub commands_forwarded: u64,
    /// Client messages rejected so far (malformed, unknown, oversized, unauthorised).
    pub bad_messages: u64,
    /// Viewers connected now.
    pub viewers: u64,
}

/// The display server (see the module docs).
pub struct ViewServer;

/// A running display server. Dropping it (or [`ViewHandle::shutdown`]) stops the server and joins
/// its thread.
pub struct ViewHandle {
    addr: SocketAddr,
    token: Option<String>,
    shutdown: watch::Sender<bool>,
    thread: Option<JoinHandle<()>>,
    counters: Arc<Counters>,
    viewers: Arc<std::sync::atomic::AtomicUsize>,
}

struct AppState {
    frames_tx: broadcast::Sender<Utf8Bytes>,
    scene_rx: watch::Receiver<Option<Utf8Bytes>>,
    commands: Mutex<rtrb::Producer<Command>>,
    viewers: Arc<std::sync::atomic::AtomicUsize>,
    token: Option<String>,
    frame_rate_hz: f64,
    shutdown: watch::Receiver<bool>,
    counters: Arc<Counters>,
}

/// The selectable options, sent in the `welcome` message.
#[derive(Serialize)]
struct Options {
    scenes: Vec<&'static str>,
    wall_laws: Vec<&'static str>,
    friction_models: Vec<&'static str>,
    controllers: Vec<&'static str>,
}

/// Messages from the server to the page.
#[derive(Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
enum Outgoing<'a> {
    Welcome {
        control: bool,
        token_required: bool,
        frame_rate_hz: f64,
        max_message_bytes: usize,
        options: Options,
    },
    Scene(&'a SceneInfo),
    Frame(&'a Frame),
    Ack {
        command: &'a str,
    },
    Error {
        message: &'a str,
    },
}

fn to_text(m: &Outgoing<'_>) -> Utf8Bytes {
    match serde_json::to_string(m) {
        Ok(s) => s.into(),
        Err(e) => {
            // Only non-finite numbers can fail here: serde_json refuses NaN/∞ (as does JSON).
            eprintln!("haptic2d-view: cannot serialise a message: {e}");
            Utf8Bytes::from_static(
                r#"{"type":"error","message":"server could not serialise a message"}"#,
            )
        }
    }
}

fn random_token() -> String {
    use std::io::Read;
    let mut bytes = [0u8; 16];
    let from_os = std::fs::File::open("/dev/urandom")
        .and_then(|mut f| f.read_exact(&mut bytes))
        .is_ok();
    if !from_os {
        use std::hash::{BuildHasher, Hasher};
        for (i, chunk) in bytes.chunks_mut(8).enumerate() {
            let mut h = std::collections::hash_map::RandomState::new().build_hasher();
            h.write_u128(
                std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map_or(0, |d| d.as_nanos()),
            );
            h.write_usize(i);
            chunk.copy_from_slice(&h.finish().to_le_bytes());
        }
    }
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

impl ViewServer {
    /// Starts the server on `bind` (e.g. `127.0.0.1:8080`; port 0 picks a free one) with the
    /// server end of a [`ViewHub`](crate::ViewHub). Binds synchronously, so a taken port is an
    /// error here, naming the address. Print [`ViewHandle::banner`] for the user.
    pub fn start(
        bind: SocketAddr,
        end: ServerEnd,
        options: ViewOptions,
    ) -> Result<ViewHandle, String> {
        let listener = std::net::TcpListener::bind(bind).map_err(|e| {
            if e.kind() == std::io::ErrorKind::AddrInUse {
                format!(
                    "cannot start the display on {bind}: the address is already in use (another haptic2d running?); choose another with --bind ADDR:PORT"
                )
            } else {
                format!("cannot start the display on {bind}: {e}")
            }
        })?;
        listener
            .set_nonblocking(true)
            .map_err(|e| format!("cannot start the display on {bind}: {e}"))?;
        let addr = listener
            .local_addr()
            .map_err(|e| format!("cannot start the display on {bind}: {e}"))?;
        let require = options.require_token.unwrap_or(!addr.ip().is_loopback());
        let token = require.then(|| options.token.clone().unwrap_or_else(random_token));

        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .thread_name("haptic2d-view")
            .enable_all()
            .build()
            .map_err(|e| format!("cannot start the display's runtime: {e}"))?;

        let ServerEnd {
            frames,
            scenes,
            commands,
            viewers,
            frame_rate_hz,
        } = end;
        let (shutdown_tx, shutdown_rx) = watch::channel(false);
        let (frames_tx, _) = broadcast::channel(8);
        let (scene_tx, scene_rx) = watch::channel(None);
        let counters = Arc::new(Counters::default());
        let state = Arc::new(AppState {
            frames_tx: frames_tx.clone(),
            scene_rx,
            commands: Mutex::new(commands),
            viewers: viewers.clone(),
            token: token.clone(),
            frame_rate_hz,
            shutdown: shutdown_rx.clone(),
            counters: counters.clone(),
        });

        let thread = std::thread::Builder::new()
            .name("haptic2d-view".into())
            .spawn(move || {
                runtime.block_on(async move {
                    let listener = match tokio::net::TcpListener::from_std(listener) {
                        Ok(l) => l,
                        Err(e) => {
                            eprintln!("haptic2d-view: cannot listen on {addr}: {e}");
                            return;
                        }
                    };
                    tokio::spawn(broadcaster(
                        frames,
                        scenes,
                        frames_tx,
                        scene_tx,
                        frame_rate_hz,
                        shutdown_rx.clone(),
                        state.counters.clone(),
                    ));
                    let app = Router::new()
                        .route("/", get(index))
                        .route("/app.js", get(app_js))
                        .route("/health", get(health))
                        .route("/ws", get(ws_upgrade))
                        .with_state(state);
                    let mut stop = shutdown_rx;
                    let serve = axum::serve(
                        listener,
                        app.into_make_service_with_connect_info::<SocketAddr>(),
                    )
                    .with_graceful_shutdown(async move {
                        stopped(&mut stop).await;
                    });
                    if let Err(e) = serve.await {
                        eprintln!("haptic2d-view: server error: {e}");
                    }
                });
                runtime.shutdown_timeout(Duration::from_secs(1));
            })
            .map_err(|e| format!("cannot start the display thread: {e}"))?;

        Ok(ViewHandle {
            addr,
            token,
            shutdown: shutdown_tx,
            thread: Some(thread),
            counters,
            viewers,
        })
    }
}

impl ViewHandle {
    /// The address the server listens on.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// The token commands need, if any (printed by [`banner`](Self::banner)).
    pub fn token(&self) -> Option<&str> {
        self.token.as_deref()
    }

    /// The page's URL (with `?token=…` when commands need one). An unspecified bind address
    /// (`0.0.0.0`) is shown as `127.0.0.1`.
    pub fn url(&self) -> String {
        let mut a = self.addr;
        if a.ip().is_unspecified() {
            a.set_ip(if a.is_ipv4() {
                std::net::Ipv4Addr::LOCALHOST.into()
            } else {
                std::net::Ipv6Addr::LOCALHOST.into()
            });
        }
        match &self.token {
            Some(t) => format!("http://{a}/?token={t}"),
            None => format!("http://{a}/"),
        }
    }

    /// The lines to print at startup: where to look, and the token if commands need one.
    pub fn banner(&self) -> String {
        match &self.token {
            Some(t) => format!(
                "display: {} (listening on {}; viewing is open, commands need token {t})",
                self.url(),
                self.addr
            ),
            None => format!("display: {}", self.url()),
        }
    }

    /// The server's counters now.
    pub fn stats(&self) -> ServerStats {
        ServerStats {
            frames_broadcast: self.counters.frames_broadcast.load(Ordering::Relaxed),
            commands_forwarded: self.counters.commands_forwarded.load(Ordering::Relaxed),
            bad_messages: self.counters.bad_messages.load(Ordering::Relaxed),
            viewers: self.viewers.load(Ordering::Relaxed) as u64,
        }
    }

    /// Stops the server (closing every viewer's connection) and joins its thread.
    pub fn shutdown(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        let _ = self.shutdown.send(true);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for ViewHandle {
    fn drop(&mut self) {
        self.stop();
    }
}

/// Reads scenes and the latest frame at the frame rate and broadcasts them as JSON text.
async fn broadcaster(
    mut frames: triple_buffer::Output<Frame>,
    mut scenes: rtrb::Consumer<SceneInfo>,
    frames_tx: broadcast::Sender<Utf8Bytes>,
    scene_tx: watch::Sender<Option<Utf8Bytes>>,
    frame_rate_hz: f64,
    mut shutdown: watch::Receiver<bool>,
    counters: Arc<Counters>,
) {
    // Poll at 4× the frame rate: the loop publishes on its own clock, and polling at the same rate
    // would alias (two publications between polls, one lost). Unchanged buffers cost one atomic load.
    let mut tick = tokio::time::interval(Duration::from_secs_f64(0.25 / frame_rate_hz));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    loop {
        tokio::select! {
            _ = tick.tick() => {}
            _ = stopped(&mut shutdown) => return,
        }
        // Scenes first, so a viewer never gets a frame of a scene it has not seen.
        while let Ok(info) = scenes.pop() {
            let text = to_text(&Outgoing::Scene(&info));
            scene_tx.send_replace(Some(text.clone()));
            let _ = frames_tx.send(text);
        }
        if frames.updated() {
            let f = frames.read();
            if frames_tx.receiver_count() > 0 {
                let text = to_text(&Outgoing::Frame(f));
                if frames_tx.send(text).is_ok() {
                    counters.frames_broadcast.fetch_add(1, Ordering::Relaxed);
                }
            }
        }
    }
}

/// Resolves once the shutdown flag is set (or its sender is gone).
async fn stopped(rx: &mut watch::Receiver<bool>) {
    let _ = rx.wait_for(|s| *s).await;
}

async fn index() -> Html<&'static str> {
    Html(INDEX_HTML)
}

async fn app_js() -> Response {
    (
        [(header::CONTENT_TYPE, "text/javascript; charset=utf-8")],
        APP_JS,
    )
        .into_response()
}

async fn health() -> &'static str {
    "ok"
}

fn query_token(query: Option<&str>) -> Option<&str> {
    query?.split('&').find_map(|kv| kv.strip_prefix("token="))
}

async fn ws_upgrade(
    ws: WebSocketUpgrade,
    RawQuery(query): RawQuery,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    State(state): State<Arc<AppState>>,
) -> Response {
    let authorised = match &state.token {
        None => true,
        Some(t) => query_token(query.as_deref()) == Some(t.as_str()),
    };
    ws.max_message_size(HARD_MESSAGE_LIMIT)
        .max_frame_size(HARD_MESSAGE_LIMIT)
        .on_upgrade(move |socket| viewer(socket, state, peer, authorised))
}

/// One connection to the page: forwards broadcasts, handles the page's messages.
struct Viewer {
    state: Arc<AppState>,
    peer: SocketAddr,
    authorised: bool,
    log_budget: u32,
}

impl Viewer {
    fn welcome(&self) -> Utf8Bytes {
        to_text(&Outgoing::Welcome {
            control: self.authorised,
            token_required: self.state.token.is_some(),
            frame_rate_hz: self.state.frame_rate_hz,
            max_message_bytes: MAX_MESSAGE_BYTES,
            options: Options {
                scenes: scene_names(),
                wall_laws: NORMAL_MODEL_NAMES.to_vec(),
                friction_models: FrictionModel::NAMES.to_vec(),
                controllers: ControllerKind::ALL.iter().map(|c| c.name()).collect(),
            },
        })
    }

    /// Counts, logs (within the budget) and returns the error frame for a rejected message.
    fn reject(&mut self, message: &str) -> Utf8Bytes {
        self.state
            .counters
            .bad_messages
            .fetch_add(1, Ordering::Relaxed);
        if self.log_budget > 0 {
            self.log_budget -= 1;
            let more = if self.log_budget == 0 {
                " (further errors from this viewer are not logged)"
            } else {
                ""
            };
            eprintln!("haptic2d-view: viewer {}: {message}{more}", self.peer);
        }
        to_text(&Outgoing::Error { message })
    }

    /// The reply to one message from the page, if any.
    fn handle(&mut self, msg: Message) -> Option<Utf8Bytes> {
        let text = match msg {
            Message::Text(t) => t,
            Message::Binary(_) => {
                return Some(self.reject("binary messages are not supported; send JSON text"))
            }
            _ => return None,
        };
        match parse_client_message(text.as_str()) {
            Err(e) => Some(self.reject(&e)),
            Ok(ClientMessage::Hello { token }) => match &self.state.token {
                Some(t) if *t != token => Some(self.reject("wrong token")),
                _ => {
                    self.authorised = true;
                    Some(self.welcome())
                }
            },
            Ok(ClientMessage::Command(cmd)) => {
                if !self.authorised {
                    return Some(self.reject(
                        "commands need the token printed at startup (open the page with ?token=…)",
                    ));
                }
                let pushed = match self.state.commands.lock() {
                    Ok(mut p) => p.push(cmd).is_ok(),
                    Err(_) => false,
                };
                if !pushed {
                    return Some(
                        self.reject("command queue full: the haptic loop is not taking commands"),
                    );
                }
                self.state
                    .counters
                    .commands_forwarded
                    .fetch_add(1, Ordering::Relaxed);
                match cmd {
                    Command::SetHandTarget { .. } => None,
                    _ => Some(to_text(&Outgoing::Ack {
                        command: cmd.kind(),
                    })),
                }
            }
        }
    }
}

async fn viewer(mut socket: WebSocket, state: Arc<AppState>, peer: SocketAddr, authorised: bool) {
    state.viewers.fetch_add(1, Ordering::Relaxed);
    let mut rx = state.frames_tx.subscribe();
    let mut shutdown = state.shutdown.clone();
    let mut v = Viewer {
        state: state.clone(),
        peer,
        authorised,
        log_budget: LOG_BUDGET,
    };
    let scene = state.scene_rx.borrow().clone();
    let mut ok = socket.send(Message::Text(v.welcome())).await.is_ok();
    if let (true, Some(s)) = (ok, scene) {
        ok = socket.send(Message::Text(s)).await.is_ok();
    }
    while ok {
        tokio::select! {
            r = rx.recv() => match r {
                Ok(text) => ok = socket.send(Message::Text(text)).await.is_ok(),
                Err(broadcast::error::RecvError::Lagged(_)) => {}
                Err(broadcast::error::RecvError::Closed) => ok = false,
            },
            m = socket.recv() => match m {
                Some(Ok(Message::Close(_))) | None => ok = false,
                Some(Ok(msg)) => {
                    if let Some(reply) = v.handle(msg) {
                        ok = socket.send(Message::Text(reply)).await.is_ok();
                    }
                }
                Some(Err(e)) => {
                    // A message over the hard limit ends the connection (tungstenite's capacity
                    // error): count and log it. Other errors are disconnects (a closed tab, a
                    // reset): not the viewer's fault, not logged.
                    let text = e.to_string();
                    if text.contains("Space limit exceeded") || text.contains("too long") {
                        let _ = v.reject(&format!(
                            "message over the hard limit of {HARD_MESSAGE_LIMIT} bytes, connection closed: {text}"
                        ));
                    }
                    ok = false;
                }
            },
            _ = stopped(&mut shutdown) => ok = false,
        }
    }
    state.viewers.fetch_sub(1, Ordering::Relaxed);
}
