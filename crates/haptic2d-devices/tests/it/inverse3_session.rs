//! The Inverse Service emulator speaks the real service's session as Haply documents it (DEVICES
//! §4, issue 34 finding 9): on connect it first pushes an inventory (every device's configuration
//! and state); after that exactly one state message per message received and nothing unprompted;
//! `set_cursor_force` and `probe_position` answered; the HTTP endpoints exist (read with the `haply`
//! crate's own HTTP client). And the driver: a state without a cursor position is a lost device,
//! never (0, 0, 0).

use crate::inverse3_support::*;

use haptic2d_test_support::wait_for;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use haply::device_model::{Command, Force, ServiceData, ServiceMsg, ServiceState};
use haptic2d_devices::inverse3::emulator::EMULATED_ID;
use haptic2d_devices::inverse3::{Emulator3Config, Hand3};
use haptic2d_rt::DeviceError;
use tungstenite::Message;

type Ws = tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>>;

fn connect(emu: &haptic2d_devices::inverse3::Inverse3Emulator) -> Ws {
    let (ws, _) = tungstenite::connect(format!("ws://{}/", emu.addr())).unwrap();
    if let tungstenite::stream::MaybeTlsStream::Plain(s) = ws.get_ref() {
        s.set_read_timeout(Some(Duration::from_millis(20))).unwrap();
    }
    ws
}

/// Every text message that arrives within `wait`.
fn messages(ws: &mut Ws, wait: Duration) -> Vec<String> {
    let end = Instant::now() + wait;
    let mut got = Vec::new();
    while Instant::now() < end {
        match ws.read() {
            Ok(Message::Text(t)) => got.push(t.to_string()),
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(e) => panic!("{e}"),
        }
    }
    got
}

/// A frame the `haply` crate builds for `commands`.
fn frame(commands: &[Command]) -> String {
    let mut msg = ServiceMsg::default();
    haply::state::update_entire_msg(commands, &mut msg).unwrap();
    serde_json::to_string(&msg).unwrap()
}

fn force(x: f32) -> Command {
    Command::SetCursorForce {
        device_id: EMULATED_ID.into(),
        vector: Force { x, y: 0.0, z: 0.0 },
        execute: true,
    }
}

#[test]
fn the_service_pushes_an_inventory_first_then_one_state_per_message_and_nothing_unprompted() {
    let emu = emulator(Emulator3Config {
        start: [0.01, 0.02, 0.03],
        ..Emulator3Config::default()
    });
    let mut ws = connect(&emu);
    // Unprompted: the inventory, and only it.
    let first = messages(&mut ws, Duration::from_millis(300));
    assert_eq!(first.len(), 1, "{first:?}");
    let inv: ServiceData = serde_json::from_str(&first[0]).unwrap();
    assert_eq!(inv.inverse3.len(), 1);
    assert_eq!(inv.inverse3[0].device_id, EMULATED_ID);
    assert!(
        inv.inverse3[0].config.is_some(),
        "an inventory carries the configuration"
    );
    let p = inv.inverse3[0].state.cursor_position.unwrap();
    assert_eq!([p.x, p.y, p.z], [0.01f32, 0.02, 0.03]);
    // Five messages, five answers, then silence.
    for _ in 0..5 {
        ws.send(Message::text(frame(&[force(0.5)]))).unwrap();
    }
    let got = messages(&mut ws, Duration::from_millis(300));
    assert_eq!(got.len(), 5, "one state per message");
    let r = emu.report();
    assert_eq!((r.inventories, r.forces, r.states), (1, 5, 6), "{r:?}");
    assert_eq!(
        emu.plant().f_cmd,
        [0.5, 0.0, 0.0],
        "set_cursor_force applied"
    );
}

#[test]
fn probe_position_is_answered_with_the_cursor_position() {
    let emu = emulator(Emulator3Config {
        start: [-0.02, 0.01, 0.0],
        ..Emulator3Config::default()
    });
    let mut ws = connect(&emu);
    messages(&mut ws, Duration::from_millis(100));
    let probe = frame(&[Command::ProbePosition {
        device_id: EMULATED_ID.into(),
    }]);
    assert!(probe.contains("probe_position"), "{probe}");
    ws.send(Message::text(probe)).unwrap();
    let got = messages(&mut ws, Duration::from_millis(300));
    assert_eq!(got.len(), 1, "{got:?}");
    // The crate asks for the full state on every frame; either form carries the position.
    let p = serde_json::from_str::<ServiceData>(&got[0])
        .map(|d| d.inverse3[0].state.cursor_position)
        .or_else(|_| {
            serde_json::from_str::<ServiceState>(&got[0])
                .map(|s| s.inverse3[0].state.cursor_position)
        })
        .unwrap()
        .expect("the probe's answer has the position");
    assert!(
        (p.x + 0.02).abs() < 1e-6 && (p.y - 0.01).abs() < 1e-6,
        "{p:?}"
    );
    assert_eq!(emu.report().probes, 1);
}

#[test]
fn the_http_endpoints_answer_haplys_own_http_client() {
    let emu = emulator(Emulator3Config::default());
    let base = format!("http://{}", emu.addr());
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    let (version, devices) = rt.block_on(async {
        let c = haply::http::InverseHttpClient::new(&base);
        (c.get_version().await, c.get_devices().await)
    });
    let version = version.expect("GET /version");
    assert!(version.project_name.contains("emulator"), "{version:?}");
    let devices = devices.expect("GET /devices");
    assert!(devices.iter().any(|d| d.id() == EMULATED_ID), "{devices:?}");
    // Anything else: 404 with a JSON note.
    let mut s = TcpStream::connect(emu.addr()).unwrap();
    write!(s, "GET /nothing HTTP/1.1\r\nHost: x\r\n\r\n").unwrap();
    let mut reply = String::new();
    s.read_to_string(&mut reply).unwrap();
    assert!(
        reply.starts_with("HTTP/1.1 404") && reply.contains("/version"),
        "{reply}"
    );
    assert!(emu.report().http >= 3);
}

/// Regression (issue 34, finding 9): a state without a cursor position was read as (0, 0, 0); the
/// handle jumped 20 mm in one sample and the force swung from +10 to −10 N. Now it is a lost device:
/// the read fails naming the field, zero force is latched and sent, and no reading ever jumps.
#[test]
fn a_state_without_a_cursor_position_is_a_lost_device_not_the_origin() {
    let start = [0.02, 0.0, 0.0];
    let emu = emulator(Emulator3Config {
        start,
        hand: Some(Hand3::hold(start, 2000.0, 20.0)),
        drop_position_after: Some(300),
        ..Emulator3Config::default()
    });
    let file = file_for(&emu, NOT_THE_TIMEOUT_UNDER_TEST);
    let mut dev = open(&file);
    let t0 = Instant::now();
    let mut k = 0;
    let err = loop {
        match dev.read_point() {
            Ok(_) => {
                let p = dev.sample().position;
                assert!(
                    (p[0] - start[0]).abs() < 2e-3,
                    "tick {k}: cursor x {} m, the hand holds {} m",
                    p[0],
                    start[0]
                );
            }
            Err(e) => break e,
        }
        dev.write_force(&[0.001, -0.001]).unwrap();
        k += 1;
        wait_tick(t0, k);
        assert!(t0.elapsed() < Duration::from_secs(5), "never lost");
    };
    let DeviceError::Lost(m) = &err else {
        panic!("{err}")
    };
    assert!(
        m.contains("cursor_position") && m.contains("zero force latched"),
        "{m}"
    );
    assert!(k >= 100, "lost only once positions went missing (tick {k})");
    assert!(dev.read_point().is_err(), "stays lost");
    wait_for("zero force sent", Duration::from_secs(5), || {
        emu.plant().f_cmd == [0.0; 3]
    });
}
