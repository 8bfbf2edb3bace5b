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

/// Issue 34 finding 7: the shipped twin gave both linkages the same offsets; at the pose they
/// describe the end points coincide and the closure error is r_c = 0.020 m. Its offsets now are the
/// inverse kinematics of its homing pose: the closure error there is ~0.
#[test]
fn shipped_twin_offsets_close_at_its_homing_pose() {
    use haptic2d::device::TwinKinematics;
    let twin = shipped("haply-twin.toml");
    let HaplyKind::Twin(p) = &twin.kind else {
        panic!("not a twin")
    };
    let q: Vec<f64> = twin
        .motors
        .iter()
        .map(|m| m.offset_deg.to_radians())
        .collect();
    let fk = TwinKinematics::new(p)
        .fk(&[q[0], q[1], q[2], q[3]], 0.0)
        .unwrap_or_else(|e| panic!("the shipped offsets do not close: {e}"));
    assert!(fk.closure_error.abs() < 1e-6, "{}", fk.closure_error);
    let rest = twin.rest_pose().unwrap();
    assert!(
        (rest[0] - 0.0).abs() < 1e-6 && (rest[1] - 0.10).abs() < 1e-6 && rest[2].abs() < 1e-6,
        "{rest:?}"
    );
}

#[test]
fn twin_offsets_that_do_not_close_are_refused_naming_the_fix() {
    let text = std::fs::read_to_string(format!(
        "{}/../../devices/haply-twin.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    // Main's file: both linkages at the 2DIY gen 3 offsets.
    let same = text
        .replace("139.075826", "168.0")
        .replace("125.070550", "168.0")
        .replace("40.924174", "12.0")
        .replace("28.489432", "12.0")
        .replace("[rest]\npose = [0.0, 0.10, 0.0]", "");
    let e = err(&same);
    assert!(
        e.contains("motor.offset_deg") && e.contains("closure") && e.contains("inverse kinematics"),
        "{e}"
    );
    // A rest pose that the offsets do not describe names rest.pose and gives the offsets for it.
    let moved = text.replace("pose = [0.0, 0.10, 0.0]", "pose = [0.005, 0.10, 0.0]");
    let e = err(&moved);
    assert!(
        e.contains("rest.pose") && e.contains("q11 q12 q21 q22"),
        "{e}"
    );
}

#[test]
fn a_2diy_rest_pose_that_the_offsets_do_not_describe_is_refused() {
    let e = err(&GOOD.replace(
        "half_width = 0.03",
        "half_width = 0.03\n[rest]\npose = [0.019, 0.10]",
    ));
    assert!(
        e.contains("rest.pose") && e.contains("(0.0190, 0.0357) m"),
        "{e}"
    );
    HaplyDeviceFile::from_toml(
        &GOOD.replace(
            "half_width = 0.03",
            "half_width = 0.03\n[rest]\npose = [0.019, 0.0357]",
        ),
        "t",
    )
    .unwrap();
}

#[test]
fn watchdog_ms_defaults_to_20_and_is_checked() {
    assert_eq!(
        HaplyDeviceFile::from_toml(GOOD, "t").unwrap().watchdog_ms,
        20
    );
    let e = err(&GOOD.replace("id = 1", "id = 1\nwatchdog_ms = 0"));
    assert!(
        e.contains("board.watchdog_ms") && e.contains("1–1000"),
        "{e}"
    );
}

fn shipped_text(name: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/../../devices/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

/// Issue 38 item 6: every shipped device file carries the `[safety]` table with the shared
/// defaults (4π rad, 1000 rad/s, 20 ms), so the shipped behaviour is unchanged; the Inverse3's,
/// whose readings are a point, bounds it at 1 m and 50 m/s.
#[test]
fn shipped_safety_tables_are_the_shared_defaults() {
    use haptic2d_devices::device_safety::DeviceSafety;
    let d = DeviceSafety::default();
    assert_eq!(d.max_angle, 4.0 * std::f64::consts::PI);
    assert_eq!((d.max_velocity, d.stall_floor), (1000.0, 0.02));
    for f in [
        "haply-2diy-gen2.toml",
        "haply-2diy-gen3.toml",
        "haply-twin.toml",
    ] {
        assert_eq!(shipped(f).safety, d, "{f}");
    }
    let udp = haptic2d_devices::udp::UdpDeviceFile::from_toml(
        &shipped_text("udp-pantograph.toml"),
        "udp",
    )
    .unwrap();
    assert_eq!(udp.safety, d);
    #[cfg(feature = "inverse3")]
    {
        let i3 = haptic2d_devices::inverse3::Inverse3DeviceFile::from_toml(
            &shipped_text("inverse3.toml"),
            "inverse3",
        )
        .unwrap();
        // The Inverse3's readings are the plane point: its bounds are in m and m/s.
        let point = DeviceSafety {
            max_angle: 1.0,
            max_velocity: 50.0,
            ..d
        };
        assert_eq!(i3.safety, point);
    }
}

/// NaN, negative, zero and absurd bounds are refused, naming `safety.FIELD`, in every kind of file.
#[test]
fn bad_safety_values_name_the_field_in_every_device_file() {
    let cases = [
        (
            "max_velocity = 1000.0",
            "max_velocity = nan",
            "safety.max_velocity",
        ),
        (
            "max_velocity = 1000.0",
            "max_velocity = -5.0",
            "safety.max_velocity",
        ),
        (
            "max_velocity = 1000.0",
            "max_velocity = 1e9",
            "safety.max_velocity",
        ),
        (
            "max_angle = 12.566370614359172",
            "max_angle = 0.0",
            "safety.max_angle",
        ),
        (
            "max_angle = 12.566370614359172",
            "max_angle = inf",
            "safety.max_angle",
        ),
        (
            "stall_floor = 0.02",
            "stall_floor = -0.01",
            "safety.stall_floor",
        ),
        (
            "stall_floor = 0.02",
            "stall_floor = 60.0",
            "safety.stall_floor",
        ),
    ];
    for (from, to, field) in cases {
        let haply = shipped_text("haply-2diy-gen3.toml").replace(from, to);
        let e = HaplyDeviceFile::from_toml(&haply, "t")
            .unwrap_err()
            .to_string();
        assert!(e.contains(field) && e.contains("fix"), "{to}: {e}");
        let udp = shipped_text("udp-pantograph.toml").replace(from, to);
        let e = haptic2d_devices::udp::UdpDeviceFile::from_toml(&udp, "t")
            .unwrap_err()
            .to_string();
        assert!(e.contains(field), "udp {to}: {e}");
        #[cfg(feature = "inverse3")]
        {
            // The same field, from the Inverse3's own bounds (m, m/s).
            let from3 = from
                .replace("1000.0", "50.0")
                .replace("12.566370614359172", "1.0");
            let i3 = shipped_text("inverse3.toml").replace(&from3, to);
            assert_ne!(i3, shipped_text("inverse3.toml"), "{from3}");
            let e = haptic2d_devices::inverse3::Inverse3DeviceFile::from_toml(&i3, "t")
                .unwrap_err()
                .to_string();
            assert!(e.contains(field), "inverse3 {to}: {e}");
        }
    }
    // A stall floor of 0 is allowed (the periods alone), as in the shared settings.
    let haply =
        shipped_text("haply-2diy-gen3.toml").replace("stall_floor = 0.02", "stall_floor = 0");
    assert_eq!(
        HaplyDeviceFile::from_toml(&haply, "t")
            .unwrap()
            .safety
            .stall_floor,
        0.0
    );
}

const IDENTIFIED: &str = r#"
[identified]
date = "2026-12-05T14:02:15Z"
command = "haptic2d device identify"
inertia = [1.5e-4, 1.6e-4]
inertia_coupling = -1.2e-4
damping = [1.9e-4, 1.9e-4]
joint_inertia = 2.0e-5
end_mass = 0.031
"#;

/// The `[identified]` table of a 2DIY is read back; implausible values and a twin are refused.
#[test]
fn identified_tables_are_read_and_checked() {
    let text = shipped_text("haply-2diy-gen3.toml") + IDENTIFIED;
    let f = HaplyDeviceFile::from_toml(&text, "t").unwrap();
    let i = f.identified.unwrap();
    assert_eq!(i.inertia, [1.5e-4, 1.6e-4]);
    assert!((i.joint_damping() - 1.9e-4).abs() < 1e-12);
    for (from, to, field) in [
        (
            "inertia = [1.5e-4",
            "inertia = [-1.5e-4",
            "identified.inertia[0]",
        ),
        ("end_mass = 0.031", "end_mass = nan", "identified.end_mass"),
        (
            "damping = [1.9e-4",
            "damping = [50.0",
            "identified.damping[0]",
        ),
        (
            "inertia_coupling = -1.2e-4",
            "inertia_coupling = -3e-4",
            "identified.inertia_coupling",
        ),
    ] {
        let e = err(&text.replace(from, to));
        assert!(e.contains(field), "{to}: {e}");
    }
    let twin = shipped_text("haply-twin.toml") + IDENTIFIED;
    assert!(err(&twin).contains("identified"));
}
