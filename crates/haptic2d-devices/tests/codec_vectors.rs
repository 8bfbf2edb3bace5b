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
