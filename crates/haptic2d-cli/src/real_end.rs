//! A real device of the registry opened as one end of a link — the device side of `run --world`,
//! the slave of `serve-world --device`, either end of `teleop --live`: its device file read and
//! checked, its [`DeviceEnd`] (the same safety stage as `run`'s tick), then the device opened.

use std::path::Path;
use std::time::Duration;

use haptic2d::haptic::DeviceEnd;
use haptic2d_devices::registry::DeviceChoice;
use haptic2d_rt::DeviceIo;

use crate::exit::{Failure, Status};

/// An opened real device and its end.
pub struct RealEnd {
    /// The device, handshake done.
    pub io: Box<dyn DeviceIo + Send>,
    /// Its kinematics and safety stage.
    pub end: DeviceEnd,
    /// Its name in messages, e.g. `haply:/dev/ttyACM0`.
    pub name: String,
    /// Where its parameters came from, its kind and limits (for the start line).
    pub summary: String,
    /// Its device file's limit of consecutive missed deadlines (`None`: off).
    pub max_missed_run: Option<u32>,
}

/// Opens `spec` (`haply:PATH`, `udp:ADDR:PORT`, `inverse3[:URL]`) with its device file `file` at
/// period `dt` (s); `allow_remote` lets a UDP device be beyond loopback. A bad name or device
/// file is bad input (exit 2); a device that cannot be opened is a lost device (exit 4, as in
/// `run`). `sim` and `replay:…` are refused: the callers build the simulated twin themselves.
pub fn open(
    spec: &str,
    file: Option<&Path>,
    allow_remote: bool,
    dt: f64,
) -> Result<RealEnd, Failure> {
    let choice = DeviceChoice::parse(spec).map_err(Failure::from)?;
    let real = choice
        .load_real(file, allow_remote)
        .map_err(Failure::from)?
        .ok_or_else(|| {
            Failure::from(format!(
                "{spec}: not a real device\n    fix: haply:PATH, udp:ADDR:PORT or inverse3[:URL]"
            ))
        })?;
    let end = real.device_end(dt).map_err(Failure::from)?;
    let io = (real.open)(Duration::from_secs_f64(dt)).map_err(|m| Failure {
        status: Status::DeviceLost,
        message: m,
    })?;
    Ok(RealEnd {
        io,
        end,
        name: real.name,
        summary: real.summary,
        max_missed_run: real.max_missed_run,
    })
}
