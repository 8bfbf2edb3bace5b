//! The Inverse Service emulator's messages checked against the `haply` crate's own types (issue
//! 15): every payload round-trips through the crate's serde, the crate's own client-side merge
//! (`haply::state::update_state_on_message`) takes them into its device state, and a command the
//! crate builds (`Command::SetCursorForce` through `update_entire_msg`) is read by the emulator.

use std::sync::Arc;

use haply::device_model::{
    Command, Force, ServiceData, ServiceMsg, ServiceState, TimestampedServiceData,
    VerseGripDuplicateMode,
};
use haptic2d_devices::inverse3::emulator::{
    cursor_force, full_payload, parse_service_msg, state_payload, Plant3, EMULATED_ID,
};
use haptic2d_devices::inverse3::Emulator3Config;

fn plant() -> Plant3 {
    Plant3 {
        p: [0.0125, -0.03, 0.1],
        v: [0.5, -0.25, 0.0],
        f_cmd: [1.0, 2.0, -3.0],
        t: 0.0,
    }
}

fn cfg() -> Emulator3Config {
    Emulator3Config {
        grip: Some([0.9238795, 0.0, 0.0, 0.3826834]),
        ..Emulator3Config::default()
    }
}

#[test]
fn full_and_state_payloads_round_trip_through_the_haply_types() {
    let full = full_payload(&cfg(), &plant());
    let text = serde_json::to_string(&full).unwrap();
    let back: ServiceData = serde_json::from_str(&text).unwrap();
    assert_eq!(back, full);
    assert!(
        text.contains("\"config\""),
        "a full payload carries config: {text}"
    );
    let i3 = &back.inverse3[0];
    assert_eq!(i3.device_id, EMULATED_ID);
    let p = i3.state.cursor_position.unwrap();
    assert_eq!([p.x, p.y, p.z], [0.0125f32, -0.03, 0.1]);
    assert!(i3.status.ready);
    assert_eq!(back.verse_grip.len(), 1);

    let state = state_payload(&cfg(), &plant());
    let text = serde_json::to_string(&state).unwrap();
    let back: ServiceState = serde_json::from_str(&text).unwrap();
    assert_eq!(back, state);
    assert!(
        !text.contains("\"config\""),
        "a state-only payload has no config"
    );
    let v = back.inverse3[0].state.cursor_velocity.unwrap();
    assert_eq!([v.x, v.y, v.z], [0.5f32, -0.25, 0.0]);
}

#[test]
fn the_haply_client_merge_takes_the_emulator_payloads_into_its_state() {
    let rt = tokio::runtime::Builder::new_current_thread()
        .build()
        .unwrap();
    rt.block_on(async {
        let state = Arc::new(tokio::sync::Mutex::new(TimestampedServiceData {
            data: ServiceData::default(),
            timestamp: std::time::Instant::now(),
        }));
        let mut first = true;
        let full = serde_json::to_string(&full_payload(&cfg(), &plant())).unwrap();
        haply::state::update_state_on_message(
            state.clone(),
            full,
            &mut first,
            VerseGripDuplicateMode::default(),
        )
        .await;
        {
            let g = state.lock().await;
            assert_eq!(g.data.inverse3.len(), 1);
            assert_eq!(g.data.inverse3[0].device_id, EMULATED_ID);
            assert!(g.data.inverse3[0].config.is_some());
            let o = g.data.verse_grip[0].state.orientation.unwrap();
            assert_eq!(o.w, 0.9238795);
        }
        let mut moved = plant();
        moved.p = [0.02, 0.01, -0.005];
        let t0 = state.lock().await.timestamp;
        let upd = serde_json::to_string(&state_payload(&cfg(), &moved)).unwrap();
        haply::state::update_state_on_message(
            state.clone(),
            upd,
            &mut first,
            VerseGripDuplicateMode::default(),
        )
        .await;
        let g = state.lock().await;
        assert!(g.timestamp > t0, "a state message refreshes the timestamp");
        assert_eq!(g.data.inverse3.len(), 1, "the same device, updated");
        let p = g.data.inverse3[0].state.cursor_position.unwrap();
        assert_eq!([p.x, p.y, p.z], [0.02f32, 0.01, -0.005]);
    });
}

#[test]
fn a_force_command_built_by_the_haply_crate_is_read_by_the_emulator() {
    let mut msg = ServiceMsg::default();
    haply::state::update_entire_msg(
        &[Command::SetCursorForce {
            device_id: EMULATED_ID.into(),
            vector: Force {
                x: 0.5,
                y: -1.5,
                z: 2.0,
            },
            execute: true,
        }],
        &mut msg,
    )
    .unwrap();
    let text = serde_json::to_string(&msg).unwrap();
    let parsed = parse_service_msg(&text).unwrap();
    assert_eq!(parsed, msg);
    assert_eq!(cursor_force(&parsed), Some([0.5, -1.5, 2.0]));
    assert!(parsed.session.force_render_full_state.is_some());
    // Another device's force, or one not to execute, is not ours.
    let mut other = ServiceMsg::default();
    haply::state::update_entire_msg(
        &[Command::SetCursorForce {
            device_id: "someone-else".into(),
            vector: Force {
                x: 1.0,
                y: 0.0,
                z: 0.0,
            },
            execute: true,
        }],
        &mut other,
    )
    .unwrap();
    assert_eq!(cursor_force(&other), None);
}

/// Regression: the emulator parsed client frames with `serde_json::from_str::<ServiceMsg>`, which
/// refuses the crate's own frames (empty device lists are skipped when serialising, required when
/// deserialising): every frame of a real `haply` client was counted malformed and no state was ever
/// sent. The crate's own first frame (`ServiceMsg::default()`, a session-only full-state request)
/// and a force frame must parse.
#[test]
fn the_haply_clients_own_frames_parse_though_its_serde_skips_empty_lists() {
    let first = serde_json::to_string(&ServiceMsg::default()).unwrap();
    assert!(
        serde_json::from_str::<ServiceMsg>(&first).is_err(),
        "the crate's serde round-trips again: the workaround in parse_service_msg can go"
    );
    let parsed = parse_service_msg(&first).unwrap();
    assert_eq!(parsed, ServiceMsg::default());
    assert!(parsed.session.force_render_full_state.is_some());
    assert_eq!(parse_service_msg("{}"), None, "a ping is not a ServiceMsg");
    assert_eq!(parse_service_msg("not json"), None);
    assert_eq!(parse_service_msg("[1, 2]"), None);
}
