//! The UDP driver against a device at its start pose, shared by the exchange and the
//! authentication modules: a paced 1 kHz run and the start-pose check of the reference devices.

use std::net::SocketAddr;
use std::thread;
use std::time::{Duration, Instant};

use haptic2d_devices::udp::{UdpCounters, UdpDevice, UdpDeviceFile};
use haptic2d_rt::{DeviceError, DeviceIo};

/// The control period of these tests (1 kHz).
pub const PERIOD: Duration = Duration::from_millis(1);

/// `ticks` ticks at 1 kHz: read, write `tau`, sleep to the next period. Returns the first error.
pub fn run(dev: &mut UdpDevice, ticks: usize, tau: f64) -> Result<(), DeviceError> {
    let start = Instant::now();
    for k in 0..ticks {
        dev.read_encoders()?;
        dev.write_torques(&[tau, -tau, 0.0, 0.0])?;
        let next = start + PERIOD * (k as u32 + 1);
        thread::sleep(next.saturating_duration_since(Instant::now()));
    }
    Ok(())
}

/// The reference file with a patient timeout (50 periods): a device process descheduled for a few
/// ms on a loaded machine is not what the reference-device tests are about.
pub fn patient_reference() -> UdpDeviceFile {
    let mut file = UdpDeviceFile::reference();
    file.timeout_periods = 50.0;
    file
}

/// Opens `file`'s driver on the device at `addr`, checks that it answers at the reference start
/// pose (end point (19, 100) mm), runs 300 ticks without torque and checks that at least 290
/// answers were fresh and none malformed; returns the counters.
pub fn answers_at_the_start_pose(addr: SocketAddr, file: UdpDeviceFile, name: &str) -> UdpCounters {
    let mut dev = UdpDevice::open(addr, &file, PERIOD, name).unwrap();
    let q = dev.read_encoders().unwrap();
    let e = file.linkage.fk([q[0], q[1]]).unwrap();
    assert!(
        (e.x - 0.019).abs() < 1e-5 && (e.y - 0.10).abs() < 1e-5,
        "{name}: {e:?}"
    );
    run(&mut dev, 300, 0.0).unwrap();
    let c = *dev.counters();
    assert!(c.fresh >= 290, "{name}: {c}");
    assert_eq!(c.malformed, 0, "{name}: {c}");
    c
}
