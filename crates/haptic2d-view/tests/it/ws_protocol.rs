//! The WebSocket protocol against an in-process server: scene and frames reach several viewers,
//! commands reach the loop, bad messages get an error frame (and never stop the server or the
//! frames), the token guards commands, a taken port is a clear error, `/health` and `/` answer.

use crate::ws::{connect, next_of, send, start, world};
use futures_util::{SinkExt, StreamExt};
use haptic2d_view::{Command, ControllerKind, Frame, ViewHub, ViewOptions, ViewServer};
use serde_json::Value;
use std::io::{Read, Write};
use std::time::Duration;
use tokio_tungstenite::tungstenite::Message;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn viewers_get_welcome_scene_and_frames_and_commands_reach_the_loop() {
    let (server, fake) = start(ViewOptions::default());
    assert!(server.token().is_none(), "loopback: no token");
    let addr = server.local_addr();
    let mut viewers = Vec::new();
    for _ in 0..3 {
        let mut ws = connect(addr, "").await;
        let w = next_of(&mut ws, "welcome").await;
        assert_eq!(w["control"], true);
        assert!(w["options"]["wall_laws"]
            .as_array()
            .unwrap()
            .iter()
            .any(|n| n == "paper"));
        let s = next_of(&mut ws, "scene").await;
        assert_eq!(s["name"], "box-in-walls");
        assert_eq!(s["bodies"][1]["name"], "box");
        assert_eq!(s["bodies"][0]["fixed"], true);
        assert_eq!(s["bodies"][0]["pieces"].as_array().unwrap().len(), 4);
        viewers.push(ws);
    }
    // Frames reach every viewer, in sequence, for the published scene.
    for ws in viewers.iter_mut() {
        let a = next_of(ws, "frame").await;
        let b = next_of(ws, "frame").await;
        assert!(b["seq"].as_u64() > a["seq"].as_u64());
        assert_eq!(a["scene_seq"], 1);
        assert_eq!(a["bodies"].as_array().unwrap().len(), 2);
        assert_eq!(a["wall_law"], "paper");
    }
    // Commands: parsed, acknowledged (except hand targets), delivered in order.
    let ws = &mut viewers[0];
    send(
        ws,
        r#"{"type":"set_hand_target","x":0.01,"y":0.002,"theta":0.1}"#,
    )
    .await;
    for msg in [
        r#"{"type":"pause"}"#,
        r#"{"type":"set_wall_law","name":"colgate"}"#,
        r#"{"type":"set_friction","name":"reset-integrator"}"#,
        r#"{"type":"set_controller","name":"four-channel"}"#,
        r#"{"type":"switch_scene","name":"peg-in-hole"}"#,
        r#"{"type":"resume"}"#,
        r#"{"type":"reset"}"#,
    ] {
        send(ws, msg).await;
        let ack = next_of(ws, "ack").await;
        let kind: Value = serde_json::from_str::<Value>(msg).unwrap()["type"].clone();
        assert_eq!(ack["command"], kind);
    }
    let got = fake.wait_for(8);
    assert_eq!(
        got,
        vec![
            Command::SetHandTarget {
                x: 0.01,
                y: 0.002,
                theta: 0.1
            },
            Command::Pause,
            Command::SetWallLaw { name: "colgate" },
            Command::SetFriction {
                name: "reset-integrator"
            },
            Command::SetController {
                kind: ControllerKind::FourChannel
            },
            Command::SwitchScene {
                name: "peg-in-hole"
            },
            Command::Resume,
            Command::Reset,
        ]
    );
    assert_eq!(server.stats().commands_forwarded, 8);
    assert_eq!(server.stats().viewers, 3);
    drop(viewers);
    drop(fake);
    server.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_messages_get_an_error_frame_and_the_stream_goes_on() {
    let (server, fake) = start(ViewOptions::default());
    let addr = server.local_addr();
    let mut ws = connect(addr, "").await;
    let mut other = connect(addr, "").await;
    next_of(&mut ws, "welcome").await;
    let big = format!(r#"{{"type":"hello","token":"{}"}}"#, "x".repeat(5000));
    for (msg, needle) in [
        ("{not json", "malformed"),
        (r#"{"type":"self_destruct"}"#, "malformed"),
        (
            r#"{"type":"set_wall_law","name":"rubber"}"#,
            "unknown wall law",
        ),
        (
            r#"{"type":"set_hand_target","x":1e300,"y":0,"theta":0}"#,
            "out of range",
        ),
        (big.as_str(), "limit of 4096 bytes"),
    ] {
        send(&mut ws, msg).await;
        let e = next_of(&mut ws, "error").await;
        assert!(
            e["message"].as_str().unwrap().contains(needle),
            "{msg:.60}: {e}"
        );
    }
    ws.send(Message::Binary(vec![1u8, 2, 3].into()))
        .await
        .unwrap();
    let e = next_of(&mut ws, "error").await;
    assert!(e["message"].as_str().unwrap().contains("binary"));
    // Still connected and receiving frames; nothing reached the loop.
    next_of(&mut ws, "frame").await;
    assert!(fake.commands.lock().unwrap().is_empty());
    assert_eq!(server.stats().bad_messages, 6);

    // A message past the hard limit (64 KiB) closes that connection only.
    let huge = "y".repeat(100 * 1024);
    let _ = ws.send(Message::Text(huge.into())).await;
    let closed = tokio::time::timeout(Duration::from_secs(5), async {
        loop {
            match ws.next().await {
                None | Some(Err(_)) | Some(Ok(Message::Close(_))) => return true,
                Some(Ok(_)) => {}
            }
        }
    })
    .await
    .unwrap_or(false);
    assert!(closed, "an over-limit message closes the connection");
    next_of(&mut other, "frame").await;
    let mut again = connect(addr, "").await;
    next_of(&mut again, "frame").await;
    drop(fake);
    server.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn commands_need_the_token_when_required_viewing_does_not() {
    let (server, fake) = start(ViewOptions {
        require_token: true,
        token: Some("s3cret".into()),
        ..ViewOptions::default()
    });
    assert_eq!(server.token(), Some("s3cret"));
    assert!(server.url().ends_with("/?token=s3cret"));
    assert!(server.banner().contains("s3cret"));
    let addr = server.local_addr();

    // Viewing without a token works; commands are refused.
    let mut ws = connect(addr, "").await;
    let w = next_of(&mut ws, "welcome").await;
    assert_eq!(w["control"], false);
    assert_eq!(w["token_required"], true);
    next_of(&mut ws, "frame").await;
    send(&mut ws, r#"{"type":"pause"}"#).await;
    assert!(next_of(&mut ws, "error").await["message"]
        .as_str()
        .unwrap()
        .contains("token"));
    send(&mut ws, r#"{"type":"hello","token":"guess"}"#).await;
    assert!(next_of(&mut ws, "error").await["message"]
        .as_str()
        .unwrap()
        .starts_with("wrong token"));
    send(&mut ws, r#"{"type":"hello","token":"s3cret"}"#).await;
    assert_eq!(next_of(&mut ws, "welcome").await["control"], true);
    send(&mut ws, r#"{"type":"pause"}"#).await;
    next_of(&mut ws, "ack").await;

    // The token in the URL works too.
    let mut ws2 = connect(addr, "?token=s3cret").await;
    assert_eq!(next_of(&mut ws2, "welcome").await["control"], true);
    send(&mut ws2, r#"{"type":"resume"}"#).await;
    next_of(&mut ws2, "ack").await;
    assert_eq!(fake.wait_for(2), vec![Command::Pause, Command::Resume]);
    drop(fake);
    server.shutdown();
}

fn http_get(addr: std::net::SocketAddr, path: &str) -> String {
    let mut s = std::net::TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut out = String::new();
    let _ = s.read_to_string(&mut out);
    out
}

#[test]
fn health_page_script_and_port_taken() {
    let (w, _) = world();
    let (_hub, end) = ViewHub::new(&Frame::for_world(&w), 60.0).unwrap();
    let server =
        ViewServer::start("127.0.0.1:0".parse().unwrap(), end, ViewOptions::default()).unwrap();
    let addr = server.local_addr();
    let health = http_get(addr, "/health");
    assert!(health.starts_with("HTTP/1.1 200"), "{health}");
    assert!(health.ends_with("ok"), "{health}");
    let page = http_get(addr, "/");
    assert!(page.contains("text/html") && page.contains("<canvas id=\"world\""));
    let js = http_get(addr, "/app.js");
    assert!(js.contains("text/javascript") && js.contains("window.__haptic2d"));

    // The same port again: a clear error naming the address.
    let (_hub2, end2) = ViewHub::new(&Frame::for_world(&w), 60.0).unwrap();
    let err = ViewServer::start(addr, end2, ViewOptions::default())
        .err()
        .expect("a taken port is an error");
    assert!(
        err.contains("already in use") && err.contains(&addr.to_string()),
        "{err}"
    );
    assert!(ViewHub::new(&Frame::default(), 0.0)
        .err()
        .unwrap()
        .contains("frame_rate_hz"));
    server.shutdown();
}
