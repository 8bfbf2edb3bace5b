//! Shared by the Inverse3 tests: the emulator on an ephemeral loopback port and the shipped device
//! file pointed at it.

use std::time::Duration;

use haptic2d_devices::inverse3::{
    Emulator3Config, Inverse3Device, Inverse3DeviceFile, Inverse3Emulator,
};

/// The emulator with `cfg` on `127.0.0.1:0`.
pub fn emulator(cfg: Emulator3Config) -> Inverse3Emulator {
    Inverse3Emulator::start("127.0.0.1:0".parse().unwrap(), cfg).unwrap()
}

/// The lost-device timeout (periods of 1 ms) of the tests that do not test the timeout itself.
///
/// The emulator, the client's socket thread and the test's loop share two cores with the rest of
/// a debug build's test run: a CI run stalled one of them for 65.7 ms, past the 50 ms these tests
/// used, and the closed-loop test failed with a lost device that was not lost. The tests of the
/// timeout set their own (module `inverse3_safety`, the service killed mid-run: 50 periods).
pub const NOT_THE_TIMEOUT_UNDER_TEST: f64 = 1000.0;

/// The shipped file, talking to `emu`, with the timeout at `timeout_periods` periods.
pub fn file_for(emu: &Inverse3Emulator, timeout_periods: f64) -> Inverse3DeviceFile {
    let a = emu.addr();
    let mut f =
        Inverse3DeviceFile::shipped().with_service(format!("http://{a}"), format!("ws://{a}/"));
    f.timeout_periods = timeout_periods;
    f
}

/// The driver on `file` at 1 kHz.
pub fn open(file: &Inverse3DeviceFile) -> Inverse3Device {
    Inverse3Device::open(file, Duration::from_millis(1), "inverse3:test").unwrap()
}

/// Sleeps until `t0 + k` ms (a 1 kHz tick).
pub fn wait_tick(t0: std::time::Instant, k: u64) {
    let at = t0 + Duration::from_millis(k);
    let now = std::time::Instant::now();
    if at > now {
        std::thread::sleep(at - now);
    }
}
