//! The display as a control surface (issue 11, build item 6): a page from another origin cannot
//! command the loop while the page's own origin can; the token is needed off loopback, checked
//! exactly, and a connection gets a few tries; a slow-header client is dropped; a scene the loop
//! cannot run at its rate is refused. Against an in-process server with a stand-in loop that
//! records every command reaching it.

use crate::ws::{closed_within_5_s, connect, connect_with, next_of, send, start, start_on};
use haptic2d_view::{assess_builtin_scenes, Command, ViewOptions, DEFAULT_STEP_FRACTION};
use std::io::{Read, Write};
use std::time::{Duration, Instant};

/// Every command the page can send, as an attacker would send them.
const COMMANDS: [&str; 6] = [
    r#"{"type":"set_controller","name":"coupling"}"#,
    r#"{"type":"set_wall_law","name":"zoh"}"#,
    r#"{"type":"switch_scene","name":"pile"}"#,
    r#"{"type":"set_hand_target","x":0.01,"y":0.0,"theta":0.0}"#,
    r#"{"type":"pause"}"#,
    r#"{"type":"reset"}"#,
];

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cross_origin_page_cannot_command_the_loop_and_the_pages_own_origin_can() {
    let (server, fake) = start(ViewOptions::default());
    let addr = server.local_addr();
    assert!(server.token().is_none(), "loopback: no token by default");

    // 1. A page from http://evil.example (what the browser sends for it): view only.
    let mut evil = connect_with(addr, "", &[("origin", "http://evil.example".to_string())]).await;
    let w = next_of(&mut evil, "welcome").await;
    assert_eq!(w["control"], false);
    let why = w["view_only_reason"].as_str().unwrap();
    assert!(why.contains("evil.example"), "{why}");
    next_of(&mut evil, "frame").await; // viewing works
    for cmd in COMMANDS {
        send(&mut evil, cmd).await;
        if !cmd.contains("set_hand_target") {
            let e = next_of(&mut evil, "error").await;
            assert!(
                e["message"]
                    .as_str()
                    .unwrap()
                    .contains("only from the page"),
                "{cmd}: {e}"
            );
        }
    }
    // Presenting a token does not help a foreign origin.
    send(&mut evil, r#"{"type":"hello","token":"anything"}"#).await;
    next_of(&mut evil, "error").await;

    // 2. A DNS-rebinding page: same-origin with its own name, which resolves to this machine.
    let host = format!("evil.example:{}", addr.port());
    let mut rebind = connect_with(
        addr,
        "",
        &[("origin", format!("http://{host}")), ("host", host.clone())],
    )
    .await;
    let w = next_of(&mut rebind, "welcome").await;
    assert_eq!(w["control"], false, "{w}");
    send(&mut rebind, r#"{"type":"pause"}"#).await;
    next_of(&mut rebind, "error").await;

    // 3. A browser request without Origin (fetch metadata present): view only.
    let mut bare = connect_with(addr, "", &[("sec-fetch-mode", "websocket".to_string())]).await;
    assert_eq!(next_of(&mut bare, "welcome").await["control"], false);
    send(&mut bare, r#"{"type":"pause"}"#).await;
    next_of(&mut bare, "error").await;

    // Nothing reached the loop: every command above was answered (an error) before this line, and a
    // command is counted as forwarded before its answer is sent, so the counter is final here.
    assert!(
        fake.commands.lock().unwrap().is_empty(),
        "commands from foreign origins reached the loop: {:?}",
        fake.commands.lock().unwrap()
    );
    assert_eq!(server.stats().commands_forwarded, 0);
    assert_eq!(server.stats().view_only, 3);

    // 4. The page's own origin (the Host it was served from) commands the loop.
    let mut page = connect_with(addr, "", &[("origin", format!("http://{addr}"))]).await;
    let w = next_of(&mut page, "welcome").await;
    assert_eq!(w["control"], true);
    assert!(w.get("view_only_reason").is_none());
    send(&mut page, r#"{"type":"set_wall_law","name":"zoh"}"#).await;
    assert_eq!(next_of(&mut page, "ack").await["command"], "set_wall_law");
    // And `localhost` is a name no other site can own.
    let mut local = connect_with(
        addr,
        "",
        &[
            ("origin", format!("http://localhost:{}", addr.port())),
            ("host", format!("localhost:{}", addr.port())),
        ],
    )
    .await;
    assert_eq!(next_of(&mut local, "welcome").await["control"], true);
    send(&mut local, r#"{"type":"pause"}"#).await;
    next_of(&mut local, "ack").await;
    assert_eq!(
        fake.wait_for(2),
        vec![Command::SetWallLaw { name: "zoh" }, Command::Pause]
    );
    drop(fake);
    server.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn token_wrong_refused_right_accepted_and_the_try_after_the_limit_closes() {
    let token = "0123456789abcdef0123456789abcdef";
    let (server, fake) = start(ViewOptions {
        require_token: true,
        token: Some(token.into()),
        ..ViewOptions::default()
    });
    let addr = server.local_addr();
    let origin = [("origin", format!("http://{addr}"))];
    let n = haptic2d_view::access::MAX_TOKEN_TRIES;

    // Wrong tokens (a prefix, one byte off, longer) are refused; the connection stays view-only.
    let mut ws = connect_with(addr, "", &origin).await;
    assert_eq!(next_of(&mut ws, "welcome").await["control"], false);
    let wrong = [
        &token[..31],
        "0123456789abcdef0123456789abcdeF",
        "0123456789abcdef0123456789abcdef0",
    ];
    assert_eq!(wrong.len() as u32, n);
    for t in wrong {
        send(&mut ws, &format!(r#"{{"type":"hello","token":"{t}"}}"#)).await;
        let e = next_of(&mut ws, "error").await;
        assert!(
            e["message"].as_str().unwrap().starts_with("wrong token"),
            "{e}"
        );
        send(&mut ws, r#"{"type":"pause"}"#).await;
        assert!(next_of(&mut ws, "error").await["message"]
            .as_str()
            .unwrap()
            .contains("token"));
    }
    // The N+1-th try closes the connection, even with the right token.
    send(&mut ws, &format!(r#"{{"type":"hello","token":"{token}"}}"#)).await;
    let mut seen = Vec::new();
    assert!(closed_within_5_s(&mut ws, &mut seen).await, "not closed");
    assert!(
        seen.iter()
            .any(|v| v["type"] == "error" && v["message"].as_str().unwrap().contains("closing")),
        "{seen:?}"
    );
    assert!(seen.iter().all(|v| v["type"] != "welcome"), "{seen:?}");
    assert_eq!(server.stats().token_lockouts, 1);

    // A wrong token in the URL counts as the first try.
    let mut ws = connect_with(addr, "?token=nope", &origin).await;
    assert_eq!(next_of(&mut ws, "welcome").await["control"], false);
    for _ in 1..n {
        send(&mut ws, r#"{"type":"hello","token":"nope"}"#).await;
        next_of(&mut ws, "error").await;
    }
    send(&mut ws, r#"{"type":"hello","token":"nope"}"#).await;
    assert!(closed_within_5_s(&mut ws, &mut Vec::new()).await);

    // The right token, after a wrong one, gives control on a fresh connection.
    let mut ws = connect_with(addr, "", &origin).await;
    next_of(&mut ws, "welcome").await;
    send(&mut ws, r#"{"type":"hello","token":"guess"}"#).await;
    next_of(&mut ws, "error").await;
    send(&mut ws, &format!(r#"{{"type":"hello","token":"{token}"}}"#)).await;
    assert_eq!(next_of(&mut ws, "welcome").await["control"], true);
    send(&mut ws, r#"{"type":"pause"}"#).await;
    next_of(&mut ws, "ack").await;
    // A program (no Origin) needs the token as well.
    let mut prog = connect(addr, "").await;
    assert_eq!(next_of(&mut prog, "welcome").await["control"], false);
    let mut prog = connect(addr, &format!("?token={token}")).await;
    assert_eq!(next_of(&mut prog, "welcome").await["control"], true);
    assert_eq!(fake.wait_for(1), vec![Command::Pause]);
    assert_eq!(server.stats().commands_forwarded, 1);
    drop(fake);
    server.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn token_is_required_off_loopback() {
    // Bound to every interface (not loopback): the token is required whatever the options say.
    let (server, fake) = start_on("0.0.0.0:0", ViewOptions::default());
    let token = server.token().expect("a token off loopback").to_string();
    assert_eq!(token.len(), 32);
    assert!(server.banner().contains(&token));
    let addr = std::net::SocketAddr::from(([127, 0, 0, 1], server.local_addr().port()));
    let origin = [("origin", format!("http://{addr}"))];
    let mut ws = connect_with(addr, "", &origin).await;
    let w = next_of(&mut ws, "welcome").await;
    assert_eq!(
        (w["control"].clone(), w["token_required"].clone()),
        (false.into(), true.into())
    );
    send(&mut ws, r#"{"type":"pause"}"#).await;
    next_of(&mut ws, "error").await;
    let mut ok = connect_with(addr, &format!("?token={token}"), &origin).await;
    assert_eq!(next_of(&mut ok, "welcome").await["control"], true);
    // With the token, a page reached through a DNS name is fine (it was opened with the token).
    let host = format!("lab-pc.local:{}", addr.port());
    let mut named = connect_with(
        addr,
        &format!("?token={token}"),
        &[("origin", format!("http://{host}")), ("host", host.clone())],
    )
    .await;
    assert_eq!(next_of(&mut named, "welcome").await["control"], true);
    assert_eq!(server.stats().commands_forwarded, 0);
    drop(fake);
    server.shutdown();
}

/// Reads until the server closes the connection (EOF or reset) or `limit` passes; returns how
/// long that took, or `None` if it stayed open.
fn time_to_close(s: &mut std::net::TcpStream, limit: Duration) -> Option<Duration> {
    let t0 = Instant::now();
    s.set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    let mut buf = [0u8; 1024];
    while t0.elapsed() < limit {
        match s.read(&mut buf) {
            Ok(0) => return Some(t0.elapsed()),
            Ok(_) => {}
            // Interrupted: SIGSTOP/SIGCONT on a socket with a read timeout (CI suspends machines).
            Err(e)
                if e.kind() == std::io::ErrorKind::WouldBlock
                    || e.kind() == std::io::ErrorKind::TimedOut
                    || e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(_) => return Some(t0.elapsed()),
        }
    }
    None
}

#[test]
fn slow_header_client_is_disconnected_after_the_timeout() {
    let (server, fake) = start(ViewOptions {
        header_read_timeout: Duration::from_millis(300),
        ..ViewOptions::default()
    });
    let addr = server.local_addr();

    // Half a request, then silence.
    let mut half = std::net::TcpStream::connect(addr).unwrap();
    write!(half, "GET /health HTTP/1.1\r\nHost: {addr}\r\n").unwrap();
    let t = time_to_close(&mut half, Duration::from_secs(5));
    assert!(
        t.is_some(),
        "a half-sent request kept its connection for 5 s"
    );

    // Slowloris: one header byte every 50 ms, forever. The timeout is on the whole header, so the
    // trickle does not keep the connection.
    let mut slow = std::net::TcpStream::connect(addr).unwrap();
    write!(slow, "GET /health HTTP/1.1\r\nHost: {addr}\r\n").unwrap();
    let t0 = Instant::now();
    let mut closed = false;
    while t0.elapsed() < Duration::from_secs(5) {
        if slow.write_all(b"X").is_err() {
            closed = true;
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
        slow.set_read_timeout(Some(Duration::from_millis(1)))
            .unwrap();
        let mut b = [0u8; 64];
        if matches!(slow.read(&mut b), Ok(0)) {
            closed = true;
            break;
        }
    }
    assert!(closed, "a trickling client kept its connection for 5 s");

    // A client that connects and sends nothing is dropped too.
    let mut idle = std::net::TcpStream::connect(addr).unwrap();
    assert!(time_to_close(&mut idle, Duration::from_secs(5)).is_some());

    // The server still answers a normal request.
    let mut ok = std::net::TcpStream::connect(addr).unwrap();
    ok.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    write!(
        ok,
        "GET /health HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut out = String::new();
    let _ = ok.read_to_string(&mut out);
    assert!(
        out.starts_with("HTTP/1.1 200") && out.ends_with("ok"),
        "{out}"
    );
    drop(fake);
    server.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn switch_to_a_scene_too_heavy_for_the_rate_is_refused_with_the_reason() {
    // The 1000-box pile at 10 kHz: its step (about 1.5 ms with the proximity stage, in release)
    // cannot fit 50 % of a 100 µs period.
    let rate = 10_000.0;
    let costs = assess_builtin_scenes(rate, DEFAULT_STEP_FRACTION);
    let pile = costs.iter().find(|c| c.name == "pile").unwrap().clone();
    assert!(!pile.runnable, "{pile:?}");
    assert!(pile.step_us > pile.budget_us && (pile.budget_us - 50.0).abs() < 1e-9);
    let (server, fake) = start(ViewOptions {
        scene_costs: costs,
        ..ViewOptions::default()
    });
    let mut ws = connect(server.local_addr(), "").await;
    let w = next_of(&mut ws, "welcome").await;
    assert_eq!(w["control"], true);
    // The page learns which scenes are runnable.
    let listed = w["options"]["scene_costs"].as_array().unwrap();
    let p = listed.iter().find(|c| c["name"] == "pile").unwrap();
    assert_eq!(p["runnable"], false);
    assert!(p["reason"].as_str().unwrap().contains("too heavy"));

    send(&mut ws, r#"{"type":"switch_scene","name":"pile"}"#).await;
    let e = next_of(&mut ws, "error").await;
    let msg = e["message"].as_str().unwrap();
    println!("refusal: {msg}");
    assert!(
        msg.contains("switch_scene refused")
            && msg.contains("pile")
            && msg.contains("10000 Hz")
            && msg.contains("--rate"),
        "{msg}"
    );
    // Refused before forwarding (the error above is the answer): nothing was or will be forwarded.
    assert_eq!(server.stats().commands_forwarded, 0);
    drop(fake);
    server.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn switch_to_a_scene_that_fits_is_forwarded() {
    // box-in-walls at 1 kHz: a step of microseconds against a 500 µs budget.
    let costs = assess_builtin_scenes(1000.0, DEFAULT_STEP_FRACTION);
    let light = costs.iter().find(|c| c.name == "box-in-walls").unwrap();
    assert!(light.runnable, "{light:?}");
    let (server, fake) = start(ViewOptions {
        scene_costs: costs,
        ..ViewOptions::default()
    });
    let mut ws = connect(server.local_addr(), "").await;
    next_of(&mut ws, "welcome").await;
    send(&mut ws, r#"{"type":"switch_scene","name":"box-in-walls"}"#).await;
    next_of(&mut ws, "ack").await;
    assert_eq!(
        fake.wait_for(1),
        vec![Command::SwitchScene {
            name: "box-in-walls"
        }]
    );
    drop(fake);
    server.shutdown();
}
