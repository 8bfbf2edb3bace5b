//! The shipped Haply device files parse; bad values name the field, the unit and the fix.

use haptic2d_devices::haply::{HaplyDeviceFile, HaplyKind};

fn shipped(name: &str) -> HaplyDeviceFile {
    let path = format!("{}/../../devices/{name}", env!("CARGO_MANIFEST_DIR"));
    HaplyDeviceFile::from_path(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn shipped_files_parse() {
    let g2 = shipped("haply-2diy-gen2.toml");
    assert_eq!(g2.joints(), 2);
    assert!(matches!(g2.kind, HaplyKind::TwoDiy { .. }));
    // Motor 1 is on port 2: in the wire's port order it comes second.
    assert_eq!(&g2.wire_index()[..2], &[1, 0]);
    let s = g2.board_setup();
    assert_eq!(s.motor_mask, 0b11);
    assert_eq!(s.enc_offset_deg[1], 241.0);
    let g3 = shipped("haply-2diy-gen3.toml");
    assert!(matches!(g3.kind, HaplyKind::TwoDiy { linkage, .. } if linkage.d == 0.038));
    let twin = shipped("haply-twin.toml");
    assert_eq!(twin.joints(), 4);
    match twin.kind {
        HaplyKind::Twin(p) => {
            assert_eq!(p.tau_max, 0.123);
            assert_eq!(p.s, 0.038);
        }
        k => panic!("{k:?}"),
    }
}

fn err(text: &str) -> String {
    HaplyDeviceFile::from_toml(text, "test.toml")
        .unwrap_err()
        .to_string()
}

const GOOD: &str = r#"
kind = "2diy"
[board]
id = 1
[linkage]
d = 0.038
l1 = 0.07
l2 = 0.09
[workspace]
center = [0.019, 0.10]
half_width = 0.03
[[motor]]
port = 2
direction = "ccw"
offset_deg = 168.0
counts_per_turn = 4880.0
[[motor]]
port = 1
direction = "ccw"
offset_deg = 12.0
counts_per_turn = 4880.0
"#;

#[test]
fn good_text_parses() {
    HaplyDeviceFile::from_toml(GOOD, "t").unwrap();
}

#[test]
fn torque_limit_above_the_firmware_clamp_is_refused() {
    let e = err(&GOOD.replace("id = 1", "id = 1\ntorque_limit = 0.5"));
    assert!(
        e.contains("board.torque_limit") && e.contains("N·m") && e.contains("0.123"),
        "{e}"
    );
}

#[test]
fn ports_with_a_gap_are_refused_because_of_the_quirk() {
    let e = err(&GOOD.replace("port = 1", "port = 3"));
    assert!(e.contains("motor.port") && e.contains("port 1"), "{e}");
}

#[test]
fn bad_direction_names_the_field() {
    let e = err(&GOOD.replacen("direction = \"ccw\"", "direction = \"up\"", 1));
    assert!(e.contains("motor[0].direction") && e.contains("ccw"), "{e}");
}

#[test]
fn unknown_field_and_syntax_errors_point_at_the_line() {
    let e = err(&GOOD.replace("half_width", "halfwidth"));
    assert!(e.contains("line") && e.contains("halfwidth"), "{e}");
}

#[test]
fn unreachable_workspace_is_refused() {
    let e = err(&GOOD.replace("half_width = 0.03", "half_width = 0.09"));
    assert!(
        e.contains("workspace.half_width") && e.contains("shrink"),
        "{e}"
    );
}

#[test]
fn wrong_motor_count_is_refused() {
    let two = GOOD.rfind("[[motor]]").unwrap();
    let e = err(&GOOD[..two]);
    assert!(e.contains("exactly 2"), "{e}");
}

/// Device files were read with no size cap (scene files have 16 MiB since issue 10):
/// `--device-file /dev/zero` would read until memory ran out. Both kinds now stop at the cap.
#[test]
fn device_files_are_read_with_the_scene_file_cap() {
    let zero = std::path::Path::new("/dev/zero");
    if !zero.exists() {
        return;
    }
    let e = haptic2d_devices::haply::HaplyDeviceFile::from_path(zero).unwrap_err();
    assert!(e.contains("larger than the documented cap"), "{e}");
    let e = haptic2d_devices::udp::UdpDeviceFile::from_path(zero).unwrap_err();
    assert!(e.contains("larger than the documented cap"), "{e}");
}
