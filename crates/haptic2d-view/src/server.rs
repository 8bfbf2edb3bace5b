//! The display server: axum on its own thread with its own tokio runtime.
//!
//! - `GET /` the page, `GET /app.js` its script (both embedded in the binary);
//! - `GET /ws` the WebSocket: server → page `welcome`, `scene`, `frame`, `ack`, `error` messages
//!   (JSON text, `{"type": …}`); page → server commands (see [`crate::command`]);
//! - `GET /health` the plain text `ok`.
//!
//! A broadcaster task reads the latest [`Frame`] from the triple buffer at the frame
//! rate, serialises it once and hands the text to every viewer through a `tokio::sync::broadcast`
//! channel; a viewer that falls behind skips frames (never the loop, never the other viewers).
//!
//! Who may command the loop is decided at the upgrade ([`crate::access`], docs/DISPLAY.md): only
//! the page this server served (its `Origin` is the `Host` it was sent to) or a non-browser client;
//! any other origin gets a view-only connection and a log line. Off loopback (and on loopback with
//! [`ViewOptions::require_token`]) commands also need the token of [`ViewHandle::token`] (in the
//! WebSocket URL `?token=…` or a message `{"type": "hello", "token": "…"}`), compared in constant
//! time, [`MAX_TOKEN_TRIES`](crate::access::MAX_TOKEN_TRIES) wrong tries per connection. Viewing never
//! needs it. A request whose headers take longer than [`ViewOptions::header_read_timeout`] is
//! dropped ([`crate::http`]). A switch to a scene the loop cannot run at its rate
//! ([`ViewOptions::scene_costs`]) is refused with the reason.

use crate::access::{classify, decide, token_eq, Access, Client};
use crate::command::Command;
use crate::connection::{self, Viewer};
use crate::frame::Frame;
use crate::hub::ServerEnd;
use crate::scene_budget::SceneCost;
use crate::scene_info::SceneInfo;
use axum::extract::ws::{Utf8Bytes, WebSocketUpgrade};
use axum::extract::{ConnectInfo, RawQuery, State};
use axum::http::{header, HeaderMap};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::get;
use axum::Router;
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
/// [`MAX_MESSAGE_BYTES`](crate::command::MAX_MESSAGE_BYTES) and this, the client gets an error frame and stays connected.
pub const HARD_MESSAGE_LIMIT: usize = 64 * 1024;
/// Refused (view-only) connections logged in all; later ones are counted, not logged.
const REFUSAL_LOG_BUDGET: u64 = 20;

/// Options of [`ViewServer::start`].
#[derive(Clone, Debug)]
pub struct ViewOptions {
    /// Commands need the token on a loopback bind too (`haptic2d run --require-token`). Off
    /// loopback they always do.
    pub require_token: bool,
    /// The token to use instead of a random one (tests).
    pub token: Option<String>,
    /// Time a client has to send a request's headers before its connection is dropped (default
    /// [`DEFAULT_HEADER_READ_TIMEOUT`](crate::http::DEFAULT_HEADER_READ_TIMEOUT), 10 s).
    pub header_read_timeout: Duration,
    /// Which built-in scenes the loop can run at its rate (see
    /// [`assess_builtin_scenes`](crate::scene_budget::assess_builtin_scenes)): a switch to one
    /// marked not runnable is refused with its reason, and the page greys it out. Empty = no
    /// assessment, every scene may be switched to.
    pub scene_costs: Vec<SceneCost>,
}

impl Default for ViewOptions {
    fn default() -> Self {
        Self {
            require_token: false,
            token: None,
            header_read_timeout: crate::http::DEFAULT_HEADER_READ_TIMEOUT,
            scene_costs: Vec::new(),
        }
    }
}

/// Counters of a running server.
#[derive(Debug, Default)]
pub(crate) struct Counters {
    pub(crate) frames_broadcast: AtomicU64,
    pub(crate) commands_forwarded: AtomicU64,
    pub(crate) bad_messages: AtomicU64,
    pub(crate) view_only: AtomicU64,
    pub(crate) token_lockouts: AtomicU64,
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
    /// Connections made view-only by the origin check so far (foreign origin, browser without
    /// `Origin`, or a DNS name without a token).
    pub view_only: u64,
    /// Connections closed for too many wrong tokens so far.
    pub token_lockouts: u64,
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

pub(crate) struct AppState {
    pub(crate) frames_tx: broadcast::Sender<Utf8Bytes>,
    pub(crate) scene_rx: watch::Receiver<Option<Utf8Bytes>>,
    pub(crate) commands: Mutex<rtrb::Producer<Command>>,
    pub(crate) viewers: Arc<std::sync::atomic::AtomicUsize>,
    /// The token commands need, when they need one.
    pub(crate) token: Option<String>,
    pub(crate) scene_costs: Vec<SceneCost>,
    pub(crate) frame_rate_hz: f64,
    pub(crate) shutdown: watch::Receiver<bool>,
    pub(crate) counters: Arc<Counters>,
}

/// The selectable options, sent in the `welcome` message.
#[derive(Serialize)]
pub(crate) struct Options<'a> {
    pub(crate) scenes: Vec<&'static str>,
    /// Per built-in scene: its estimated step and whether the loop can run it (empty: not assessed).
    pub(crate) scene_costs: &'a [SceneCost],
    pub(crate) wall_laws: Vec<&'static str>,
    pub(crate) friction_models: Vec<&'static str>,
    pub(crate) impact_friction_modes: Vec<&'static str>,
    pub(crate) controllers: Vec<&'static str>,
}

/// Messages from the server to the page.
#[derive(Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub(crate) enum Outgoing<'a> {
    Welcome {
        control: bool,
        token_required: bool,
        /// Why this connection cannot command (absent when it can).
        #[serde(skip_serializing_if = "Option::is_none")]
        view_only_reason: Option<&'a str>,
        frame_rate_hz: f64,
        max_message_bytes: usize,
        options: Options<'a>,
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

pub(crate) fn to_text(m: &Outgoing<'_>) -> Utf8Bytes {
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
        // Off loopback the token is always required: anyone on the network could reach the port.
        let require = options.require_token || !addr.ip().is_loopback();
        let token = require.then(|| options.token.clone().unwrap_or_else(random_token));
        if options.header_read_timeout.is_zero() {
            return Err(
                "the display's header_read_timeout must be positive (default 10 s)".to_string(),
            );
        }

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
            scene_costs: options.scene_costs.clone(),
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
                    crate::http::serve(listener, app, options.header_read_timeout, shutdown_rx)
                        .await;
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
            view_only: self.counters.view_only.load(Ordering::Relaxed),
            token_lockouts: self.counters.token_lockouts.load(Ordering::Relaxed),
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
pub(crate) async fn stopped(rx: &mut watch::Receiver<bool>) {
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

/// The WebSocket upgrade: decides the connection's access from its headers and the URL's token
/// (see [`crate::access`]), logs a view-only connection (within a budget), then hands the socket
/// to [`connection::run`].
async fn ws_upgrade(
    ws: WebSocketUpgrade,
    headers: HeaderMap,
    RawQuery(query): RawQuery,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    State(state): State<Arc<AppState>>,
) -> Response {
    let client = classify(&headers);
    let url_token = query_token(query.as_deref());
    let url_token_ok = match (&state.token, url_token) {
        (Some(t), Some(given)) => token_eq(t, given),
        _ => false,
    };
    let access = decide(&client, state.token.is_some(), url_token_ok);
    // A wrong token in the URL is the connection's first failed try.
    let failures = u32::from(url_token.is_some() && state.token.is_some() && !url_token_ok);
    if let Access::ViewOnly(why) = &access {
        let n = state.counters.view_only.fetch_add(1, Ordering::Relaxed) + 1;
        if n <= REFUSAL_LOG_BUDGET {
            let who = match &client {
                Client::Foreign { origin } => format!("origin `{origin}`"),
                Client::BrowserWithoutOrigin => "a browser without Origin".to_string(),
                _ => format!(
                    "host `{}`",
                    headers
                        .get(header::HOST)
                        .and_then(|h| h.to_str().ok())
                        .unwrap_or("")
                ),
            };
            let more = if n == REFUSAL_LOG_BUDGET {
                " (further view-only connections are counted, not logged)"
            } else {
                ""
            };
            eprintln!("haptic2d-view: connection from {peer} ({who}): {why}{more}");
        }
    }
    let viewer = Viewer::new(state, peer, access, failures);
    ws.max_message_size(HARD_MESSAGE_LIMIT)
        .max_frame_size(HARD_MESSAGE_LIMIT)
        .on_upgrade(move |socket| connection::run(socket, viewer))
}
