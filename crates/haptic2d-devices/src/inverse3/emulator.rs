//! A stand-in for Haply's Inverse Service on loopback (`haptic2d emulate inverse3`): a WebSocket
//! and HTTP server speaking the messages the `haply` crate sends and parses — serialised and parsed
//! with the crate's own serde types — in front of a simulated 3-DOF device pushed by a simulated
//! hand.
//!
//! The session, as Haply documents the Inverse Service 3.x (DEVICES §4): WebSocket and HTTP on the
//! same port. When a client connects, the service first pushes an **inventory**: a full payload, a
//! `ServiceData` whose devices carry their `config` and state. After that it sends **exactly one
//! state message per message received, nothing unprompted**: a message asking for
//! `session.force_render_full_state` gets the full payload again, every other one a state-only
//! `ServiceState`. `set_cursor_force` of our device id is applied (zero-order hold until the next);
//! `probe_position` is answered like any message, with the state (the cursor's position). Messages
//! that do not parse are counted and answered with nothing. HTTP (a request without a WebSocket
//! upgrade): `GET /version` (a `VersionResponse`) and `GET /devices` (the inventory) answer `200`
//! with JSON; any other path `404` with a JSON note.
//!
//! Hazards the real service can show, on request: [`Emulator3Config::drop_position_after`] makes the
//! states after that many replies lack `cursor_position` (a state without a field the driver needs).
//!
//! Device: per axis `m·a = F_cmd + F_hand − b·v`, `|F_cmd|` clamped to the emulated force limit,
//! stepped by semi-implicit Euler in ≤ 0.1 ms sub-steps over the wall-clock time since the last
//! step (at most 50 ms at a time), on every message and every 10 ms without one, from the first
//! WebSocket connection on (before it the device rests and the hand's clock stands). Hand: a spring
//! to its target (`k`, `b` per axis) for `t_hold` s, then the constant push plus the hand's damping.

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use haply::device_model::{
    DeviceConfig, Inverse3Device as WireInverse3, Inverse3Message, Inverse3State, Inverse3Status,
    ServiceData, ServiceMsg, ServiceState, VGConfig, Vec3D, Vec4D, VerseGripDevice,
    VerseGripMessage, VerseGripState, VerseGripStatus, VersionResponse,
};
use tungstenite::Message;

/// The emulated device's id in every message.
pub const EMULATED_ID: &str = "emulated-inverse3";

/// The emulated VerseGrip's id.
pub const EMULATED_GRIP_ID: &str = "emulated-versegrip";

/// The simulated hand: a spring to `target` for `t_hold` s, then the constant `push`; damping `b`
/// throughout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hand3 {
    /// Spring target (m, device frame).
    pub target: [f64; 3],
    /// Spring stiffness per axis (N/m).
    pub k: [f64; 3],
    /// Damping per axis (N·s/m).
    pub b: [f64; 3],
    /// How long the spring holds before the push (s).
    pub t_hold: f64,
    /// The push after `t_hold` (N, device frame).
    pub push: [f64; 3],
}

impl Hand3 {
    /// A hand holding `target` forever (`k` N/m, `b` N·s/m on every axis).
    pub fn hold(target: [f64; 3], k: f64, b: f64) -> Self {
        Self {
            target,
            k: [k; 3],
            b: [b; 3],
            t_hold: f64::INFINITY,
            push: [0.0; 3],
        }
    }

    /// The hand of `haptic2d emulate inverse3 --hand SPEC` around `start` (m) with damping `b`
    /// (N·s/m): `follow` (a 300 N/m spring holding `start`), `free` (damping only) or
    /// `push:FX,FY,FZ[,HOLD]` (follow for HOLD s, default 1, then push with the constant force, N).
    /// `None` for `free` with `b = 0`. Errors name the form.
    pub fn parse(spec: &str, start: [f64; 3], b: f64) -> Result<Option<Self>, String> {
        let form = "expected follow | free | push:FX,FY,FZ[,HOLD] (N, N, N, s)";
        match spec {
            "follow" => Ok(Some(Self::hold(start, 300.0, b))),
            "free" if b == 0.0 => Ok(None),
            "free" => Ok(Some(Self {
                k: [0.0; 3],
                ..Self::hold(start, 0.0, b)
            })),
            _ => {
                let Some(rest) = spec.strip_prefix("push:") else {
                    return Err(format!("--hand `{spec}`: {form}"));
                };
                let v: Vec<f64> = rest
                    .split(',')
                    .map(|x| x.trim().parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| format!("--hand `{spec}`: {form}"))?;
                if !(v.len() == 3 || v.len() == 4) || !v.iter().all(|x| x.is_finite()) {
                    return Err(format!("--hand `{spec}`: {form}"));
                }
                let t_hold = v.get(3).copied().unwrap_or(1.0);
                if t_hold < 0.0 {
                    return Err(format!("--hand `{spec}`: HOLD must be ≥ 0 s"));
                }
                Ok(Some(Self {
                    t_hold,
                    push: [v[0], v[1], v[2]],
                    ..Self::hold(start, 300.0, b)
                }))
            }
        }
    }

    /// The hand's force (N) at time `t` (s), cursor `p` (m), velocity `v` (m/s).
    pub fn force(&self, t: f64, p: &[f64; 3], v: &[f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| {
            let spring = if t < self.t_hold {
                self.k[i] * (self.target[i] - p[i])
            } else {
                self.push[i]
            };
            spring - self.b[i] * v[i]
        })
    }
}

/// What the emulated device is.
#[derive(Clone, Debug, PartialEq)]
pub struct Emulator3Config {
    /// Moving mass per axis (kg). Default 0.2 (an estimate of the Inverse3's apparent mass).
    pub mass: [f64; 3],
    /// Viscous damping per axis (N·s/m). Default 1.
    pub damping: [f64; 3],
    /// The emulated device's own force limit (N). Default 10.
    pub force_limit: f64,
    /// Start position of the cursor (m, device frame).
    pub start: [f64; 3],
    /// The hand; `None` = no hand.
    pub hand: Option<Hand3>,
    /// Report a VerseGrip with this orientation quaternion `(w, x, y, z)`; `None` = no VerseGrip.
    pub grip: Option<[f64; 4]>,
    /// The VerseGrip turns about the device's z axis at this rate (rad/s of simulated time), from
    /// `grip` at t = 0. Default 0.
    pub grip_rate: f64,
    /// A fault: every state message after this many (the inventory counts) lacks
    /// `cursor_position`. `None` (default): every state has it.
    pub drop_position_after: Option<u64>,
}

impl Default for Emulator3Config {
    fn default() -> Self {
        Self {
            mass: [0.2; 3],
            damping: [1.0; 3],
            force_limit: 10.0,
            start: [0.0; 3],
            hand: None,
            grip: None,
            grip_rate: 0.0,
            drop_position_after: None,
        }
    }
}

/// The simulated device.
#[derive(Clone, Debug, PartialEq)]
pub struct Plant3 {
    /// Cursor position (m).
    pub p: [f64; 3],
    /// Cursor velocity (m/s).
    pub v: [f64; 3],
    /// The commanded force being applied (N, after the device's clamp).
    pub f_cmd: [f64; 3],
    /// Simulated time (s).
    pub t: f64,
}

impl Plant3 {
    /// Advances `dt` s under `cfg` (the commanded force held).
    pub fn step(&mut self, cfg: &Emulator3Config, dt: f64) {
        let n = (dt / 1e-4).ceil().max(1.0) as usize;
        let h = dt / n as f64;
        for _ in 0..n {
            let fh = cfg
                .hand
                .map_or([0.0; 3], |hand| hand.force(self.t, &self.p, &self.v));
            for (i, f_hand) in fh.iter().enumerate() {
                let a = (self.f_cmd[i] + f_hand - cfg.damping[i] * self.v[i]) / cfg.mass[i];
                self.v[i] += h * a;
                self.p[i] += h * self.v[i];
            }
            self.t += h;
        }
    }
}

/// Counters of a running emulator.
#[derive(Debug, Default)]
pub struct Emulator3Counters {
    /// WebSocket connections accepted.
    pub connections: AtomicU64,
    /// Client messages parsed as `ServiceMsg`.
    pub messages: AtomicU64,
    /// Client messages that did not parse (ignored).
    pub malformed: AtomicU64,
    /// State messages sent.
    pub states: AtomicU64,
    /// Force commands applied.
    pub forces: AtomicU64,
    /// Inventories pushed on connection.
    pub inventories: AtomicU64,
    /// `probe_position` commands answered.
    pub probes: AtomicU64,
    /// HTTP requests answered (any status).
    pub http: AtomicU64,
}

/// What the emulator saw, for reports and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Emulator3Report {
    /// WebSocket connections.
    pub connections: u64,
    /// Client messages parsed.
    pub messages: u64,
    /// Client messages that did not parse.
    pub malformed: u64,
    /// States sent.
    pub states: u64,
    /// Force commands applied.
    pub forces: u64,
    /// Inventories pushed on connection.
    pub inventories: u64,
    /// `probe_position` commands answered.
    pub probes: u64,
    /// HTTP requests answered.
    pub http: u64,
}

struct Shared {
    cfg: Emulator3Config,
    plant: Mutex<(Plant3, Instant)>,
    stop: AtomicBool,
    counters: Emulator3Counters,
}

impl Shared {
    /// True when the state about to be sent must lack its cursor position (the fault of
    /// [`Emulator3Config::drop_position_after`]).
    fn position_dropped(&self) -> bool {
        self.cfg
            .drop_position_after
            .is_some_and(|n| self.counters.states.load(Ordering::Relaxed) >= n)
    }

    fn without_position(&self, mut d: ServiceData) -> ServiceData {
        if self.position_dropped() {
            for dev in &mut d.inverse3 {
                dev.state.cursor_position = None;
            }
        }
        d
    }

    /// Steps the plant to now; applies `force` if given; returns the state.
    fn advance(&self, force: Option<[f64; 3]>) -> Plant3 {
        let mut g = self.plant.lock().unwrap_or_else(|e| e.into_inner());
        let now = Instant::now();
        let dt = now.duration_since(g.1).as_secs_f64().min(0.05);
        g.1 = now;
        // The device (and the hand's clock) start with the first connection.
        let connected = self.counters.connections.load(Ordering::Relaxed) > 0;
        if dt > 0.0 && connected {
            let cfg = &self.cfg;
            g.0.step(cfg, dt);
        }
        if let Some(f) = force {
            let f = super::planar::clamp_norm(f, self.cfg.force_limit);
            g.0.f_cmd = f;
        }
        g.0.clone()
    }
}

/// A running emulator: a listener thread and one thread per connection.
pub struct Inverse3Emulator {
    addr: SocketAddr,
    shared: Arc<Shared>,
    threads: Vec<JoinHandle<()>>,
}

impl Inverse3Emulator {
    /// Listens at `bind` (use port 0 for any free port) and serves until [`stop`](Self::stop).
    pub fn start(bind: SocketAddr, cfg: Emulator3Config) -> std::io::Result<Self> {
        let listener = TcpListener::bind(bind)?;
        listener.set_nonblocking(true)?;
        let addr = listener.local_addr()?;
        let plant = Plant3 {
            p: cfg.start,
            v: [0.0; 3],
            f_cmd: [0.0; 3],
            t: 0.0,
        };
        let shared = Arc::new(Shared {
            cfg,
            plant: Mutex::new((plant, Instant::now())),
            stop: AtomicBool::new(false),
            counters: Emulator3Counters::default(),
        });
        let s = shared.clone();
        let acceptor = std::thread::Builder::new()
            .name("inverse3-emulator".into())
            .spawn(move || accept_loop(listener, s))?;
        Ok(Self {
            addr,
            shared,
            threads: vec![acceptor],
        })
    }

    /// The address it listens at.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The simulated device now (stepped to the present).
    pub fn plant(&self) -> Plant3 {
        self.shared.advance(None)
    }

    /// The counters so far.
    pub fn report(&self) -> Emulator3Report {
        let c = &self.shared.counters;
        Emulator3Report {
            connections: c.connections.load(Ordering::Relaxed),
            messages: c.messages.load(Ordering::Relaxed),
            malformed: c.malformed.load(Ordering::Relaxed),
            states: c.states.load(Ordering::Relaxed),
            forces: c.forces.load(Ordering::Relaxed),
            inventories: c.inventories.load(Ordering::Relaxed),
            probes: c.probes.load(Ordering::Relaxed),
            http: c.http.load(Ordering::Relaxed),
        }
    }

    /// The stop flag (set it to stop, e.g. from a Ctrl-C handler).
    pub fn is_stopped(&self) -> bool {
        self.shared.stop.load(Ordering::Relaxed)
    }

    /// Stops serving: every connection is dropped (the client sees the service gone).
    pub fn stop(&mut self) -> Emulator3Report {
        self.shared.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
        self.report()
    }
}

impl Drop for Inverse3Emulator {
    fn drop(&mut self) {
        self.stop();
    }
}

fn accept_loop(listener: TcpListener, shared: Arc<Shared>) {
    let mut conns = Vec::new();
    while !shared.stop.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((stream, _)) => {
                let s = shared.clone();
                if let Ok(t) = std::thread::Builder::new()
                    .name("inverse3-emulator-conn".into())
                    .spawn(move || serve_connection(stream, s))
                {
                    conns.push(t);
                }
            }
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) => {
                // Keep the plant moving in real time between messages.
                shared.advance(None);
                std::thread::sleep(Duration::from_millis(10));
            }
            Err(_) => std::thread::sleep(Duration::from_millis(10)),
        }
    }
    for t in conns {
        let _ = t.join();
    }
}

/// True if the request head in `buf` asks for a WebSocket upgrade.
fn is_upgrade(head: &[u8]) -> bool {
    String::from_utf8_lossy(head)
        .to_ascii_lowercase()
        .contains("upgrade: websocket")
}

fn serve_connection(stream: TcpStream, shared: Arc<Shared>) {
    let _ = stream.set_nonblocking(false);
    let _ = stream.set_nodelay(true);
    let _ = stream.set_read_timeout(Some(Duration::from_millis(50)));
    // Peek at the request head: a WebSocket upgrade or plain HTTP.
    let mut head = [0u8; 2048];
    let start = Instant::now();
    let n = loop {
        match stream.peek(&mut head) {
            Ok(n)
                if n > 0 && (head[..n].windows(4).any(|w| w == b"\r\n\r\n") || n == head.len()) =>
            {
                break n
            }
            Ok(0) => return,
            Ok(_) => {}
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                ) => {}
            Err(_) => return,
        }
        if shared.stop.load(Ordering::Relaxed) || start.elapsed() > Duration::from_secs(2) {
            return;
        }
        std::thread::sleep(Duration::from_millis(1));
    };
    if !is_upgrade(&head[..n]) {
        shared.counters.http.fetch_add(1, Ordering::Relaxed);
        plain_http(stream, &shared);
        return;
    }
    let _ = stream.set_read_timeout(Some(Duration::from_secs(2)));
    let Ok(mut ws) = tungstenite::accept(stream) else {
        return;
    };
    let _ = ws
        .get_ref()
        .set_read_timeout(Some(Duration::from_millis(20)));
    shared.counters.connections.fetch_add(1, Ordering::Relaxed);
    // The service's first message on a new session: the inventory, unprompted.
    let plant = shared.advance(None);
    let inventory =
        serde_json::to_string(&shared.without_position(full_payload(&shared.cfg, &plant)))
            .unwrap_or_else(|_| "{}".into());
    if ws.send(Message::text(inventory)).is_err() {
        return;
    }
    shared.counters.inventories.fetch_add(1, Ordering::Relaxed);
    shared.counters.states.fetch_add(1, Ordering::Relaxed);
    while !shared.stop.load(Ordering::Relaxed) {
        let msg = match ws.read() {
            Ok(m) => m,
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                ) =>
            {
                shared.advance(None);
                continue;
            }
            Err(_) => return,
        };
        let text = match msg {
            Message::Text(t) => t,
            Message::Close(_) => return,
            _ => continue,
        };
        let Some(cmd) = parse_service_msg(text.as_str()) else {
            shared.counters.malformed.fetch_add(1, Ordering::Relaxed);
            continue;
        };
        shared.counters.messages.fetch_add(1, Ordering::Relaxed);
        let reply = answer(&shared, &cmd);
        if ws.send(Message::text(reply)).is_err() {
            return;
        }
        shared.counters.states.fetch_add(1, Ordering::Relaxed);
    }
    // Stopped: drop the connection without a close handshake, as a killed service would.
}

/// The HTTP side: `GET /version`, `GET /devices` (the inventory); 404 with a JSON note otherwise.
fn plain_http(mut stream: TcpStream, shared: &Shared) {
    let mut buf = [0u8; 4096];
    let n = stream.read(&mut buf).unwrap_or(0);
    let head = String::from_utf8_lossy(&buf[..n]);
    let mut words = head.split_whitespace();
    let (method, target) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
    let path = target.split('?').next().unwrap_or("");
    let (status, body) = match (method, path) {
        ("GET", "/version") => (
            "200 OK",
            serde_json::to_string(&VersionResponse {
                project_name: "haptic2d Inverse Service emulator".into(),
                project_version: env!("CARGO_PKG_VERSION").into(),
                ..Default::default()
            })
            .unwrap_or_default(),
        ),
        ("GET", "/devices") => {
            let plant = shared.advance(None);
            (
                "200 OK",
                serde_json::to_string(&full_payload(&shared.cfg, &plant)).unwrap_or_default(),
            )
        }
        _ => (
            "404 Not Found",
            format!(
                "{{\"error\":\"haptic2d's Inverse Service emulator serves GET /version, GET /devices and the WebSocket; not {} {}\"}}",
                method.escape_default(),
                path.escape_default()
            ),
        ),
    };
    let _ = write!(
        stream,
        "HTTP/1.1 {status}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    );
}

/// A client frame as the `haply` crate's [`ServiceMsg`]. The crate serialises the message with its
/// empty device lists left out (`skip_serializing_if = "Vec::is_empty"`) but has no `default` for
/// them when deserialising, so its own frames do not parse back as they are: the missing lists are
/// put back as empty ones first. `None` for anything else (not JSON, not an object, bad fields).
pub fn parse_service_msg(text: &str) -> Option<ServiceMsg> {
    let mut v: serde_json::Value = serde_json::from_str(text).ok()?;
    let obj = v.as_object_mut()?;
    for key in ["inverse3", "verse_grip", "wireless_verse_grip"] {
        obj.entry(key)
            .or_insert_with(|| serde_json::Value::Array(Vec::new()));
    }
    serde_json::from_value(v).ok()
}

/// The command's force for our device, if any.
pub fn cursor_force(cmd: &ServiceMsg) -> Option<[f64; 3]> {
    cmd.inverse3
        .iter()
        .filter(|d| d.device_id == EMULATED_ID)
        .find_map(|d| d.commands.as_ref()?.set_cursor_force)
        .filter(|c| c.execute)
        .map(|c| [c.vector.x as f64, c.vector.y as f64, c.vector.z as f64])
}

/// True when the command probes our device's position.
pub fn probes_position(cmd: &ServiceMsg) -> bool {
    cmd.inverse3
        .iter()
        .filter(|d| d.device_id == EMULATED_ID)
        .any(|d| {
            d.commands
                .as_ref()
                .is_some_and(|c| c.probe_position.is_some())
        })
}

fn answer(shared: &Shared, cmd: &ServiceMsg) -> String {
    let force = cursor_force(cmd);
    if force.is_some() {
        shared.counters.forces.fetch_add(1, Ordering::Relaxed);
    }
    if probes_position(cmd) {
        shared.counters.probes.fetch_add(1, Ordering::Relaxed);
    }
    let plant = shared.advance(force);
    let full = cmd.session.force_render_full_state.is_some();
    let text = if full {
        serde_json::to_string(&shared.without_position(full_payload(&shared.cfg, &plant)))
    } else {
        let mut s = state_payload(&shared.cfg, &plant);
        if shared.position_dropped() {
            for d in &mut s.inverse3 {
                d.state.cursor_position = None;
            }
        }
        serde_json::to_string(&s)
    };
    text.unwrap_or_else(|_| "{}".into())
}

fn v3(a: [f64; 3]) -> Vec3D {
    Vec3D {
        x: a[0] as f32,
        y: a[1] as f32,
        z: a[2] as f32,
    }
}

fn inverse3_state(plant: &Plant3) -> (Inverse3State, Inverse3Status) {
    (
        Inverse3State {
            cursor_position: Some(v3(plant.p)),
            cursor_velocity: Some(v3(plant.v)),
            current_cursor_force: Some(v3(plant.f_cmd)),
            ..Default::default()
        },
        Inverse3Status {
            calibrated: true,
            in_use: true,
            power_supply: true,
            ready: true,
            started: true,
            navigation: None,
        },
    )
}

/// The VerseGrip's orientation at simulated time `t` (s): `grip` turned by `grip_rate·t` about the
/// device's z axis (the quaternion product `r ⊗ q`, `r = (cos(b/2), 0, 0, sin(b/2))`).
fn grip_now(cfg: &Emulator3Config, t: f64) -> Option<[f64; 4]> {
    let q = cfg.grip?;
    let (s, c) = (0.5 * cfg.grip_rate * t).sin_cos();
    Some([
        c * q[0] - s * q[3],
        c * q[1] - s * q[2],
        c * q[2] + s * q[1],
        c * q[3] + s * q[0],
    ])
}

fn grip_state(q: [f64; 4]) -> (VerseGripState, VerseGripStatus) {
    (
        VerseGripState {
            orientation: Some(Vec4D {
                w: q[0] as f32,
                x: q[1] as f32,
                y: q[2] as f32,
                z: q[3] as f32,
            }),
            ..Default::default()
        },
        VerseGripStatus {
            error: None,
            ready: Some(true),
        },
    )
}

/// The payload's VerseGrip list: one entry made by `entry` from the grip's state and status when
/// the emulator reports a grip ([`grip_now`]), none otherwise.
fn grip_entries<T>(
    cfg: &Emulator3Config,
    plant: &Plant3,
    entry: impl FnOnce(VerseGripState, VerseGripStatus) -> T,
) -> Vec<T> {
    grip_now(cfg, plant.t)
        .map(|q| {
            let (state, status) = grip_state(q);
            vec![entry(state, status)]
        })
        .unwrap_or_default()
}

/// The full payload (`ServiceData`, devices with their `config`) for the plant's state.
pub fn full_payload(cfg: &Emulator3Config, plant: &Plant3) -> ServiceData {
    let (state, status) = inverse3_state(plant);
    ServiceData {
        inverse3: vec![WireInverse3 {
            device_id: EMULATED_ID.into(),
            config: Some(DeviceConfig {
                id: EMULATED_ID.into(),
                port: "emulated".into(),
                ..Default::default()
            }),
            state,
            status,
        }],
        verse_grip: grip_entries(cfg, plant, |state, status| VerseGripDevice {
            device_id: EMULATED_GRIP_ID.into(),
            config: Some(VGConfig {
                id: EMULATED_GRIP_ID.into(),
                port: "emulated".into(),
                ..Default::default()
            }),
            state,
            status,
        }),
        session_id: 1,
        ..Default::default()
    }
}

/// The state-only payload (`ServiceState`) for the plant's state.
pub fn state_payload(cfg: &Emulator3Config, plant: &Plant3) -> ServiceState {
    let (state, status) = inverse3_state(plant);
    ServiceState {
        inverse3: vec![Inverse3Message {
            device_id: EMULATED_ID.into(),
            state,
            status,
        }],
        verse_grip: grip_entries(cfg, plant, |state, status| VerseGripMessage {
            device_id: EMULATED_GRIP_ID.into(),
            state,
            status,
        }),
        session_id: 1,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hands_parse_and_bad_ones_say_the_form() {
        let s = [0.01, 0.0, 0.0];
        let h = Hand3::parse("follow", s, 2.0).unwrap().unwrap();
        assert_eq!(h.force(0.0, &[0.0; 3], &[0.0; 3]), [3.0, 0.0, 0.0]);
        assert_eq!(Hand3::parse("free", s, 0.0).unwrap(), None);
        let h = Hand3::parse("push:-0.8,0,0.4,0.5", s, 0.0)
            .unwrap()
            .unwrap();
        assert_eq!(h.force(0.4, &s, &[0.0; 3]), [0.0; 3]);
        assert_eq!(h.force(0.6, &s, &[0.0; 3]), [-0.8, 0.0, 0.4]);
        for bad in ["push:1,2", "push:a,b,c", "shove", "push:1,2,3,-1"] {
            let e = Hand3::parse(bad, s, 0.0).unwrap_err();
            assert!(e.contains("--hand"), "{bad}: {e}");
        }
    }

    #[test]
    fn the_plant_moves_under_force_and_clamps_at_its_limit() {
        let cfg = Emulator3Config::default(); // 0.2 kg, 1 N·s/m, 10 N
        let mut p = Plant3 {
            p: [0.0; 3],
            v: [0.0; 3],
            f_cmd: [1.0, 0.0, 0.0],
            t: 0.0,
        };
        p.step(&cfg, 2.0);
        // Terminal velocity F/b = 1 m/s after 10 time constants (m/b = 0.2 s).
        assert!((p.v[0] - 1.0).abs() < 1e-3, "{:?}", p.v);
        assert_eq!(
            super::super::planar::clamp_norm([30.0, 40.0, 0.0], cfg.force_limit),
            [6.0, 8.0, 0.0]
        );
    }
}
