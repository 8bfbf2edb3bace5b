//! Byte vectors of the Haply protocol (docs/DEVICES.md §1), written out by hand from the spec.

use haptic2d_devices::haply::codec::*;

fn gen2_setup() -> BoardSetup {
    // Gen 2 (docs/DEVICES.md §2): motor 1 CCW on port 2 (241°), motor 2 CW on port 1 (−61°), 10752 counts.
    let mut s = BoardSetup::empty(1);
    s.motor_mask = 0b0011;
    s.enc_mask = 0b0011;
    s.motor_dir = [
        Rotation::Clockwise,
        Rotation::CounterClockwise,
        Rotation::Clockwise,
        Rotation::Clockwise,
    ];
    s.enc_dir = s.motor_dir;
    s.enc_offset_deg = [-61.0, 241.0, 0.0, 0.0];
    s.enc_resolution = [10752.0, 10752.0, 0.0, 0.0];
    s
}

#[test]
fn reset_vector() {
    let mut b = [0u8; 4];
    assert_eq!(encode_reset(7, &mut b), Ok(2));
    assert_eq!(&b[..2], &[0x00, 0x07]);
}

#[test]
fn setup_vector_gen2_in_port_order() {
    let mut b = [0u8; SETUP_MAX_LEN];
    let n = encode_setup(&gen2_setup(), &mut b).unwrap();
    #[rustfmt::skip]
    let want: [u8; 26] = [
        0x01, 0x01,             // setup, id 1
        0x03, 0x00, 0x01,       // motor mask ports 1+2; port 1 CW (motor 2), port 2 CCW (motor 1)
        0x03, 0x00, 0x01,       // encoder mask and directions, same order
        0x00,                   // no analog sensors
        0x00,                   // no PWM pins
        0x00, 0x00, 0x74, 0xc2, // port 1 offset −61.0°
        0x00, 0x00, 0x28, 0x46, // port 1 resolution 10752
        0x00, 0x00, 0x71, 0x43, // port 2 offset 241.0°
        0x00, 0x00, 0x28, 0x46, // port 2 resolution 10752
    ];
    assert_eq!(&b[..n], &want);
    // The firmware reads it back to the same set-up (mask starting at port 1: no quirk).
    assert_eq!(decode_setup(&b[..n]).unwrap(), gen2_setup());
}

#[test]
fn write_vector() {
    let mut b = [0u8; WRITE_MAX_LEN];
    let n = encode_write(1, &[], &[0.1, -0.05], &mut b).unwrap();
    assert_eq!(
        &b[..n],
        &[0x02, 0x01, 0xcd, 0xcc, 0xcc, 0x3d, 0xcd, 0xcc, 0x4c, 0xbd]
    );
    let n = encode_write(3, &[0x80], &[0.0], &mut b).unwrap();
    assert_eq!(&b[..n], &[0x02, 0x03, 0x80, 0, 0, 0, 0]);
}

#[test]
fn reply_vector_decodes() {
    // id 1, angles 12.5° and −90°.
    let bytes = [0x01, 0x00, 0x00, 0x48, 0x41, 0x00, 0x00, 0xb4, 0xc2];
    let r = decode_reply(1, 0, 2, &bytes).unwrap();
    assert_eq!(&r.angles_deg[..2], &[12.5, -90.0]);
    let mut out = [0u8; REPLY_MAX_LEN];
    let n = encode_reply(1, &[], &[12.5, -90.0], &mut out).unwrap();
    assert_eq!(&out[..n], &bytes);
}

#[test]
fn reply_with_sensors_puts_analog_first() {
    let mut out = [0u8; REPLY_MAX_LEN];
    let n = encode_reply(2, &[1.0], &[30.0], &mut out).unwrap();
    assert_eq!(n, 9);
    let r = decode_reply(2, 1, 1, &out[..n]).unwrap();
    assert_eq!(r.analog[0], 1.0);
    assert_eq!(r.angles_deg[0], 30.0);
}

#[test]
fn wrong_id_is_out_of_step() {
    let bytes = [0x05, 0, 0, 0, 0, 0, 0, 0, 0];
    assert_eq!(
        decode_reply(1, 0, 2, &bytes),
        Err(CodecError::WrongId {
            expected: 1,
            got: 5
        })
    );
}

#[test]
fn short_reply_is_detected() {
    let bytes = [0x01, 0, 0, 0x48, 0x41, 0];
    assert_eq!(
        decode_reply(1, 0, 2, &bytes),
        Err(CodecError::Short {
            expected: 9,
            got: 6
        })
    );
}

#[test]
fn nan_in_reply_is_garbage() {
    let mut bytes = [0x01, 0, 0, 0, 0, 0, 0, 0, 0];
    bytes[5..9].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_eq!(
        decode_reply(1, 0, 2, &bytes),
        Err(CodecError::NonFinite { offset: 5 })
    );
}

#[test]
fn buffer_too_small_is_an_error_not_a_panic() {
    let mut b = [0u8; 5];
    assert!(matches!(
        encode_setup(&gen2_setup(), &mut b),
        Err(CodecError::BufferTooSmall(26))
    ));
    assert!(matches!(
        encode_write(1, &[], &[0.0, 0.0], &mut b),
        Err(CodecError::BufferTooSmall(10))
    ));
}

#[test]
fn direction_quirk_shifts_directions_for_a_mask_not_starting_at_port_1() {
    // Motors on ports 2 and 3, both CCW as sent in port order: the firmware gives byte 0 to port 1
    // and byte 1 to port 2, so port 3 falls back to CW.
    let mut s = BoardSetup::empty(1);
    s.motor_mask = 0b0110;
    s.motor_dir = [
        Rotation::Clockwise,
        Rotation::CounterClockwise,
        Rotation::CounterClockwise,
        Rotation::Clockwise,
    ];
    let mut b = [0u8; SETUP_MAX_LEN];
    let n = encode_setup(&s, &mut b).unwrap();
    assert_eq!(&b[..n], &[0x01, 0x01, 0x06, 0x01, 0x01, 0x00, 0x00, 0x00]);
    let fw = decode_setup(&b[..n]).unwrap();
    assert_eq!(fw.motor_dir[1], Rotation::CounterClockwise);
    assert_eq!(
        fw.motor_dir[2],
        Rotation::Clockwise,
        "port 3 lost its direction"
    );
}

#[test]
fn host_frames_decode_incrementally() {
    let setup = gen2_setup();
    let mut b = [0u8; WRITE_MAX_LEN];
    let n = encode_write(1, &[], &[0.25, -0.5], &mut b).unwrap();
    for k in 0..n {
        assert_eq!(decode_host_frame(&b[..k], &setup), Ok(None), "prefix {k}");
    }
    let (frame, used) = decode_host_frame(&b[..n], &setup).unwrap().unwrap();
    assert_eq!(used, n);
    match frame {
        HostFrame::Write { id, torques, .. } => {
            assert_eq!(id, 1);
            assert_eq!(&torques[..2], &[0.25, -0.5]);
        }
        f => panic!("not a write: {f:?}"),
    }
    assert_eq!(
        decode_host_frame(&[0x09], &setup),
        Err(CodecError::UnknownCommand(9))
    );
}

// ---- The emulated stock firmware against docs/DEVICES.md §1.3 (issue 34 findings 1, 3, 4) ----

mod firmware {
    use haptic2d_devices::haply::codec::{
        decode_reply, encode_identify, encode_reset, encode_setup, encode_write, BoardSetup,
        REPLY_MAX_LEN, SETUP_MAX_LEN, WRITE_MAX_LEN,
    };
    use haptic2d_devices::haply::{Firmware, HaplyDeviceFile};

    fn shipped(name: &str) -> HaplyDeviceFile {
        let path = format!("{}/../../devices/{name}", env!("CARGO_MANIFEST_DIR"));
        HaplyDeviceFile::from_path(std::path::Path::new(&path)).unwrap()
    }

    /// Feeds `bytes` to `fw` with the linkage at `q` (rad, joint order); returns the last reply.
    fn feed(fw: &mut Firmware, q: &[f64; 4], bytes: &[u8]) -> Vec<u8> {
        fw.receive(bytes);
        let mut out = [0u8; REPLY_MAX_LEN];
        let mut last = Vec::new();
        while let Some(n) = fw.service(q, &mut out) {
            if n > 0 {
                last = out[..n].to_vec();
            }
        }
        last
    }

    fn setup_bytes(s: &BoardSetup) -> Vec<u8> {
        let mut b = [0u8; SETUP_MAX_LEN];
        let n = encode_setup(s, &mut b).unwrap();
        b[..n].to_vec()
    }

    fn write_bytes(torques: &[f32]) -> Vec<u8> {
        let mut b = [0u8; WRITE_MAX_LEN];
        let n = encode_write(1, &[], torques, &mut b).unwrap();
        b[..n].to_vec()
    }

    /// Angles (deg, port order) of a reply to a write with 2 encoders.
    fn angles(reply: &[u8], n_enc: usize) -> Vec<f32> {
        decode_reply(1, 0, n_enc, reply).unwrap().angles_deg[..n_enc].to_vec()
    }

    /// The angle the firmware reports right after a setup with `offset` and `resolution`: the count
    /// `trunc(offset · resolution / 360)` (f32, toward zero), times 360 / resolution (docs/DEVICES.md §1.3.3).
    fn at_setup(offset: f32, resolution: f32) -> f32 {
        let count = (offset * resolution / 360.0) as i64;
        360.0 * count as f32 / resolution
    }

    /// Finding 1: the board reported the pose where the handle was at **setup** as the offsets; our
    /// emulator used to report the true pose (counts from power-up at the offsets).
    #[test]
    fn encoders_are_set_at_every_setup_whatever_the_power_up_pose() {
        let file = shipped("haply-2diy-gen3.toml");
        let s = file.board_setup();
        // Powered up somewhere, set up somewhere else (the workspace centre, not the rest pose).
        let mut fw = Firmware::new(&file);
        let q_power = [2.0, 0.5, 0.0, 0.0];
        fw.power_up(&q_power);
        let q_centre = {
            let haptic2d_devices::haply::HaplyKind::TwoDiy { linkage, .. } = file.kind else {
                unreachable!()
            };
            let q = linkage.ik(haptic2d::geom::Vec2::new(0.019, 0.10)).unwrap();
            [q[0], q[1], 0.0, 0.0]
        };
        let mut bytes = vec![0x00, 1];
        bytes.extend(setup_bytes(&s));
        feed(&mut fw, &q_centre, &bytes);
        let r = feed(&mut fw, &q_centre, &write_bytes(&[0.0, 0.0]));
        // Port 1 = motor 2 (offset 12°), port 2 = motor 1 (offset 168°).
        assert_eq!(
            angles(&r, 2),
            vec![at_setup(12.0, 4880.0), at_setup(168.0, 4880.0)]
        );
        // Then the reported angle is the offset plus the motion since the setup (10° on motor 1).
        let moved = [q_centre[0] + 10f64.to_radians(), q_centre[1], 0.0, 0.0];
        let r = feed(&mut fw, &moved, &write_bytes(&[0.0, 0.0]));
        let a = angles(&r, 2);
        assert!((a[1] - 178.0).abs() < 2.0 * 360.0 / 4880.0, "{a:?}");
        assert_eq!(a[0], at_setup(12.0, 4880.0));
        // A second setup, with the handle there, re-zeroes: the offsets again.
        let r = feed(&mut fw, &moved, &setup_bytes(&s));
        assert!(r.is_empty(), "no reply to a setup");
        let r = feed(&mut fw, &moved, &write_bytes(&[0.0, 0.0]));
        assert_eq!(
            angles(&r, 2),
            vec![at_setup(12.0, 4880.0), at_setup(168.0, 4880.0)]
        );
    }

    /// Finding 4: angles are whole counts truncated toward zero (12° at 4880 counts is 162.67
    /// counts: 162, not 163; −61° at 10752 is −1821.9: −1821, not −1822).
    #[test]
    fn reported_angle_is_a_count_truncated_toward_zero() {
        for (name, port1_offset, res) in [
            ("haply-2diy-gen3.toml", 12.0f32, 4880.0f32),
            ("haply-2diy-gen2.toml", -61.0, 10752.0),
        ] {
            let file = shipped(name);
            let mut fw = Firmware::new(&file);
            let q = file.rest_joint_angles();
            feed(&mut fw, &q, &setup_bytes(&file.board_setup()));
            let r = feed(&mut fw, &q, &write_bytes(&[0.0, 0.0]));
            let got = angles(&r, 2)[0];
            let truncated = at_setup(port1_offset, res);
            let rounded = 360.0 * (port1_offset * res / 360.0).round() / res;
            assert_eq!(got, truncated, "{name}");
            assert_ne!(got, rounded, "{name}: rounded, not truncated");
        }
    }

    /// Finding 3: no watchdog, and reset does not zero the motor output.
    #[test]
    fn reset_leaves_the_motors_on_and_without_writes_the_last_torque_is_held() {
        let file = shipped("haply-2diy-gen3.toml");
        let mut fw = Firmware::new(&file);
        let q = file.rest_joint_angles();
        feed(&mut fw, &q, &setup_bytes(&file.board_setup()));
        // Port 1 (motor 2) 0.2 N·m → clamped to 0.123; port 2 (motor 1) −0.1.
        feed(&mut fw, &q, &write_bytes(&[0.2, -0.1]));
        let held = fw.joint_torques();
        assert!(
            (held[0] + 0.1).abs() < 1e-6 && (held[1] - 0.123).abs() < 1e-6,
            "{held:?}"
        );
        // The host dies: nothing arrives for a long time; the board has no clock to notice.
        for _ in 0..1000 {
            assert!(feed(&mut fw, &q, &[]).is_empty());
        }
        assert_eq!(fw.joint_torques(), held);
        // A reset (a new host starting) forgets the setup, not the torque.
        let mut b = [0u8; 2];
        encode_reset(1, &mut b).unwrap();
        feed(&mut fw, &q, &b);
        assert_eq!(fw.joint_torques(), held, "reset zeroed the motor output");
        assert_eq!(fw.setup().n_motors(), 0);
    }

    /// Finding 4: analog inputs come back in ascending pin order, whatever the setup's order.
    #[test]
    fn analog_inputs_are_reported_in_ascending_pin_order() {
        let file = shipped("haply-2diy-gen3.toml");
        let mut fw = Firmware::new(&file);
        fw.analog_in[0] = 1.5; // A0 = pin 54
        fw.analog_in[2] = 3.25; // A2 = pin 56
        let mut s = file.board_setup();
        s.n_sensors = 2;
        s.sensor_pins[0] = 56;
        s.sensor_pins[1] = 54;
        let q = file.rest_joint_angles();
        feed(&mut fw, &q, &setup_bytes(&s));
        let r = feed(&mut fw, &q, &write_bytes(&[0.0, 0.0]));
        let reply = decode_reply(1, 2, 2, &r).unwrap();
        assert_eq!(&reply.analog[..2], &[1.5, 3.25]);
    }

    /// Finding 4: an M0 board (2 ports) asked for 4 encoders answers 1 of 17 bytes, not silence.
    #[test]
    fn m0_answers_a_setup_naming_ports_it_lacks_with_a_shorter_reply() {
        use haptic2d_devices::haply::BoardKind;
        let file = shipped("haply-twin.toml");
        let s = file.board_setup();
        assert_eq!(s.reply_len(), 17);
        let q = [0.0; 4];
        let mut m0 = Firmware::with_board(&file, BoardKind::M0);
        feed(&mut m0, &q, &setup_bytes(&s));
        let mut w = [0u8; WRITE_MAX_LEN];
        let n = encode_write(1, &[], &[0.0; 4], &mut w).unwrap();
        let r = feed(&mut m0, &q, &w[..n]);
        assert_eq!(r, vec![1], "an M0 answers with the id alone");
        let mut m3 = Firmware::with_board(&file, BoardKind::M3);
        feed(&mut m3, &q, &setup_bytes(&s));
        assert_eq!(feed(&mut m3, &q, &w[..n]).len(), 17);
    }

    /// haptic2d's identify query is a lone 0x03: the stock firmware discards it one byte at a time
    /// and stays in step (a setup and a write after it work).
    #[test]
    fn stock_firmware_discards_the_identify_byte_and_stays_in_step() {
        let file = shipped("haply-2diy-gen3.toml");
        let mut fw = Firmware::new(&file);
        let q = file.rest_joint_angles();
        let mut b = [0u8; 1];
        encode_identify(&mut b).unwrap();
        assert!(feed(&mut fw, &q, &b).is_empty(), "no answer to identify");
        assert_eq!(fw.discarded, 1);
        feed(&mut fw, &q, &setup_bytes(&file.board_setup()));
        let r = feed(&mut fw, &q, &write_bytes(&[0.0, 0.0]));
        assert_eq!(r.len(), 9);
        assert_eq!(r[0], 1);
    }
}
