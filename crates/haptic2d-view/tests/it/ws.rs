//! In-process server + stand-in loop for the WebSocket tests, and small client helpers.

use futures_util::{SinkExt, StreamExt};
use haptic2d::scene::builtin;
use haptic2d::world::World;
use haptic2d_view::{Command, Frame, FrameInputs, SceneInfo, ViewHub, ViewOptions, ViewServer};
use serde_json::Value;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use tokio_tungstenite::tungstenite::http::HeaderValue;
use tokio_tungstenite::tungstenite::Message;

pub type Ws =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

pub fn world() -> (World, SceneInfo) {
    let s = builtin("box-in-walls", Some(1000.0)).unwrap().unwrap();
    let info = SceneInfo::from_world(&s.world, &s.name, &s.description, Some(1), None);
    (s.world, info)
}

/// A stand-in loop: steps the world and publishes frames at 1 kHz on its own thread; commands it
/// receives are collected.
pub struct FakeLoop {
    stop: Arc<AtomicBool>,
    pub commands: Arc<Mutex<Vec<Command>>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl FakeLoop {
    pub fn start(mut hub: ViewHub, mut world: World) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let commands = Arc::new(Mutex::new(Vec::new()));
        let (s, c) = (stop.clone(), commands.clone());
        let thread = std::thread::spawn(move || {
            let t0 = std::time::Instant::now();
            while !s.load(Ordering::Relaxed) {
                while let Some(cmd) = hub.poll_command() {
                    c.lock().unwrap().push(cmd);
                }
                world.step();
                let now = t0.elapsed().as_secs_f64();
                if hub.frame_due(now) {
                    let inputs = FrameInputs {
                        slave: Some(1),
                        controller: "coupling",
                        ..FrameInputs::default()
                    };
                    hub.publish_frame(now, &world, &inputs);
                }
                std::thread::sleep(Duration::from_millis(1));
            }
        });
        Self {
            stop,
            commands,
            thread: Some(thread),
        }
    }
}

impl FakeLoop {
    /// The commands the loop has received once it has at least `n` (polled until a 10 s deadline,
    /// never a fixed sleep: a loaded machine only makes it take longer).
    pub fn wait_for(&self, n: usize) -> Vec<Command> {
        let deadline = std::time::Instant::now() + Duration::from_secs(10);
        haptic2d_test_support::wait_until(deadline, || self.commands.lock().unwrap().len() >= n);
        self.commands.lock().unwrap().clone()
    }
}

impl Drop for FakeLoop {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// A server on `bind` (port 0) with the stand-in loop behind it.
pub fn start_on(bind: &str, options: ViewOptions) -> (haptic2d_view::ViewHandle, FakeLoop) {
    let (w, info) = world();
    let (mut hub, end) = ViewHub::new(&Frame::for_world(&w), 60.0).unwrap();
    hub.publish_scene(info).unwrap();
    let server = ViewServer::start(bind.parse().unwrap(), end, options).unwrap();
    (server, FakeLoop::start(hub, w))
}

/// A loopback server with the stand-in loop behind it.
pub fn start(options: ViewOptions) -> (haptic2d_view::ViewHandle, FakeLoop) {
    start_on("127.0.0.1:0", options)
}

/// A WebSocket to `ws://{addr}/ws{query}` as a program would open it (no `Origin`).
pub async fn connect(addr: std::net::SocketAddr, query: &str) -> Ws {
    connect_with(addr, query, &[]).await
}

/// A WebSocket to `ws://{addr}/ws{query}` with extra (or replaced) request headers, e.g. the
/// `Origin` a browser would send.
pub async fn connect_with(
    addr: std::net::SocketAddr,
    query: &str,
    headers: &[(&'static str, String)],
) -> Ws {
    let mut req = format!("ws://{addr}/ws{query}")
        .into_client_request()
        .unwrap();
    for (k, v) in headers {
        req.headers_mut()
            .insert(*k, HeaderValue::from_str(v).unwrap());
    }
    let (ws, _) = tokio_tungstenite::connect_async(req)
        .await
        .expect("websocket connects");
    ws
}

/// The next JSON text message whose `type` is `kind` (skipping others), within 5 s.
pub async fn next_of(ws: &mut Ws, kind: &str) -> Value {
    let fut = async {
        loop {
            match ws.next().await {
                Some(Ok(Message::Text(t))) => {
                    let v: Value = serde_json::from_str(t.as_str()).expect("server sends JSON");
                    if v["type"] == kind {
                        return v;
                    }
                }
                Some(Ok(_)) => {}
                other => panic!("connection ended while waiting for `{kind}`: {other:?}"),
            }
        }
    };
    tokio::time::timeout(Duration::from_secs(5), fut)
        .await
        .unwrap_or_else(|_| panic!("no `{kind}` message within 5 s"))
}

/// True if the server closes the connection within 5 s (a close frame, an error or the end);
/// text messages on the way are collected into `seen`.
pub async fn closed_within_5_s(ws: &mut Ws, seen: &mut Vec<Value>) -> bool {
    tokio::time::timeout(Duration::from_secs(5), async {
        loop {
            match ws.next().await {
                None | Some(Err(_)) | Some(Ok(Message::Close(_))) => return true,
                Some(Ok(Message::Text(t))) => {
                    if let Ok(v) = serde_json::from_str::<Value>(t.as_str()) {
                        if v["type"] != "frame" {
                            seen.push(v);
                        }
                    }
                }
                Some(Ok(_)) => {}
            }
        }
    })
    .await
    .unwrap_or(false)
}

pub async fn send(ws: &mut Ws, text: &str) {
    ws.send(Message::Text(text.into())).await.expect("send");
}
