//! Buttons on a Haply board's analog pins (issue 40 item 2): the device file's `[[buttons]]`
//! tables are checked with clear errors, become the set-up's analog sensors, and the driver reports
//! the emulated board's analog readings (ascending pin order, DEVICES §1.3 rule 7) as
//! `DeviceIo::buttons`, by pin and debounced over two samples.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use haptic2d_devices::haply::codec::{encode_setup, BoardSetup, SETUP_MAX_LEN};
use haptic2d_devices::haply::serial::{open_port, Pty};
use haptic2d_devices::haply::{
    emulator, serve_with_analog, AnalogInputs, EmulatorConfig, Firmware, HaplyDevice,
    HaplyDeviceFile,
};
use haptic2d_rt::DeviceIo;

/// The shipped gen 3 file with `extra` appended (e.g. `[[buttons]]` tables), a reply timeout of
/// 100 periods (a machine shared with compilers).
fn gen3_with(extra: &str) -> Result<HaplyDeviceFile, String> {
    let path = format!(
        "{}/../../devices/haply-2diy-gen3.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(path).unwrap() + "\n" + extra;
    HaplyDeviceFile::from_toml(&text, "gen3-buttons.toml")
        .map(|mut f| {
            f.timeout_periods = 100.0;
            f
        })
        .map_err(|e| e.to_string())
}

/// Button 0 on A5, button 1 on A2: the file's order is not the pins' order.
const TWO_BUTTONS: &str = r#"
[[buttons]]
pin = "A5"
pressed_above = 512.0

[[buttons]]
pin = 56
pressed_above = 300.0
"#;

#[test]
fn the_button_pins_are_the_setups_analog_sensors_and_a_file_without_buttons_has_none() {
    let f = gen3_with(TWO_BUTTONS).unwrap();
    let s = f.board_setup();
    assert_eq!(s.n_sensors, 2);
    assert_eq!(&s.sensor_pins[..2], &[54 + 5, 54 + 2]);
    // Reply: id, 2 analog values, 2 angles.
    assert_eq!(s.reply_len(), 1 + 4 * (2 + 2));
    let plain = gen3_with("").unwrap();
    assert!(plain.buttons.is_empty());
    assert_eq!(plain.board_setup().n_sensors, 0);
}

#[test]
fn the_emulated_firmware_reports_the_button_pins_in_ascending_order() {
    let f = gen3_with(TWO_BUTTONS).unwrap();
    let mut fw = Firmware::new(&f);
    fw.analog_in[2] = 700.0; // A2
    fw.analog_in[5] = 100.0; // A5
    let mut bytes = [0u8; SETUP_MAX_LEN];
    let n = encode_setup(&f.board_setup(), &mut bytes).unwrap();
    fw.receive(&bytes[..n]);
    let q = f.rest_joint_angles();
    let mut out = [0u8; 65];
    while fw.service(&q, &mut out).is_some_and(|n| n == 0) {}
    fw.receive(&[0x02, f.id, 0, 0, 0, 0, 0, 0, 0, 0]);
    let len = fw.service(&q, &mut out).unwrap();
    let setup: &BoardSetup = fw.setup();
    assert_eq!(len, setup.reply_len());
    let r = haptic2d_devices::haply::codec::decode_reply(f.id, 2, 2, &out[..len]).unwrap();
    // Ascending pin order: A2 first, although the set-up named A5 first.
    assert_eq!(&r.analog[..2], &[700.0, 100.0]);
}

/// The driver against the emulated board on a pseudo-terminal: a press on A2 (button 1) is
/// reported after two replies, a press on A5 (button 0) then too, a release after two replies.
#[test]
fn the_driver_reports_a_press_on_the_emulated_boards_analog_pin_after_two_samples() {
    let f = gen3_with(TWO_BUTTONS).unwrap();
    let pty = Pty::new().unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let analog = AnalogInputs::default();
    let config = EmulatorConfig::default();
    let plant = emulator::plant_for(&f, None, &config).unwrap();
    let (s2, f2, a2) = (stop.clone(), f.clone(), analog.clone());
    let master = pty.master;
    let emu = std::thread::spawn(move || serve_with_analog(master, &f2, plant, &config, &s2, &a2));
    let port = open_port(&pty.path).unwrap();
    let name = format!("haply:{}", pty.path);
    let mut dev = HaplyDevice::open(port, &f, Duration::from_millis(1), &name).unwrap();
    // Each read sends a zero write and waits for its reply: one analog sample per read.
    let read = |dev: &mut HaplyDevice<_>| {
        dev.read_encoders().unwrap();
        dev.buttons()
    };
    for _ in 0..3 {
        assert_eq!(read(&mut dev), 0, "nothing pressed");
    }
    analog.set(54 + 2, 301.0); // A2 above button 1's 300
    assert_eq!(read(&mut dev), 0, "one sample is not yet a press");
    assert_eq!(
        read(&mut dev),
        0b10,
        "button 1 (A2), by pin, not file order"
    );
    analog.set(54 + 5, 512.5); // A5 above button 0's 512
    read(&mut dev);
    assert_eq!(read(&mut dev), 0b11);
    analog.set(54 + 2, 299.0);
    analog.set(54 + 5, 512.0); // at the threshold is not above it
    assert_eq!(read(&mut dev), 0b11, "one sample is not yet a release");
    assert_eq!(read(&mut dev), 0);
    // A pin that is no button changes nothing.
    analog.set(54, 1000.0);
    read(&mut dev);
    assert_eq!(read(&mut dev), 0);
    drop(dev);
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let report = emu.join().unwrap();
    assert!(report.replies >= 12, "{report:?}");
}

/// Each bad `[[buttons]]` table is refused with its field and what to write.
#[test]
fn bad_button_tables_are_refused_with_the_field_and_the_fix() {
    let one =
        |pin: &str, above: &str| format!("[[buttons]]\npin = {pin}\npressed_above = {above}\n");
    let cases = [
        (one("\"A12\"", "1.0"), "buttons[0].pin", "\"A0\" … \"A11\""),
        (one("2", "1.0"), "buttons[0].pin", "54–65"),
        (one("\"D3\"", "1.0"), "`D3` is not an analog pin", "\"A0\""),
        (
            one("\"A1\"", "nan"),
            "buttons[0].pressed_above",
            "ADC units",
        ),
        (one("\"A1\"", "inf"), "not a finite number", "e.g. 512"),
        (
            one("\"A1\"", "1.0") + &one("55", "2.0"),
            "buttons[1].pin",
            "its own analog pin",
        ),
        (
            (0..9).map(|i| one(&format!("\"A{i}\""), "1.0")).collect(),
            "9 [[buttons]] tables, at most 8",
            "at most 8 buttons",
        ),
        (
            "[[buttons]]\npin = \"A1\"\n".to_string(),
            "pressed_above",
            "",
        ),
        (
            "[[buttons]]\npin = \"A1\"\npressed_above = 1.0\npressed_below = 2.0\n".to_string(),
            "pressed_below",
            "",
        ),
    ];
    for (extra, what, fix) in cases {
        let e = gen3_with(&extra).expect_err(&extra);
        assert!(e.contains(what) && e.contains(fix), "{extra}\n→ {e}");
    }
    // The duplicate names the button that has the pin already.
    let e = gen3_with(&(one("\"A1\"", "1.0") + &one("55", "2.0"))).unwrap_err();
    assert!(e.contains("pin A1 is already button 0"), "{e}");
    // Eight distinct pins by name and number are fine.
    let eight: String = (0..8).map(|i| one(&(54 + i).to_string(), "1.0")).collect();
    assert_eq!(gen3_with(&eight).unwrap().buttons.len(), 8);
}
