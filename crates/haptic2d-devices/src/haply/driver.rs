//! [`HaplyDevice`]: a Haply board behind `haptic2d-rt`'s [`DeviceIo`].
//!
//! Joint `j` (the `j`-th `[[motor]]` of the device file: 2DIY motors 1, 2; twin `q11, q12, q21, q22`)
//! sits on its port; its angle (degrees on the wire) becomes radians, CCW from +x in the board frame.
//! A 2DIY fills `q[0..2]` and ignores `τ[2..4]`.
//!
//! Opening follows the firmware (docs/DEVICES.md §7): identify (stock firmware → a warning, see
//! [`HaplyDevice::start_warning`]; haptic2d firmware → its watchdog set from the device file), then
//! reset, setup and a zero-torque write **with the handle held at the rest pose**, then the rest-pose
//! check before any torque: every angle right after the setup equals its offset within
//! [`REST_TOLERANCE_COUNTS`], and the angles assemble into the linkage (the twin: closure).
//!
//! Timing of one tick: [`read_encoders`](DeviceIo::read_encoders) waits for the reply to the previous
//! tick's write (the board sampled its encoders when it serviced that write), or, when no write is
//! pending, sends a zero-torque write first (the protocol's way to read the state);
//! [`write_torques`](DeviceIo::write_torques) sends the write and returns at once. A reply later than
//! `timeout_periods` periods after its write means the device is lost.
//!
//! Safety in the driver itself: every torque is clamped to the device file's `torque_limit`
//! (≤ 0.123 N·m); a non-finite torque sends zeros and fails; **a stream out of step or a silent
//! board latches zero torques** (an all-zero write at once, if the port still takes bytes) and every
//! later call fails: the setup is never re-sent (it would re-zero the encoders wherever the handle
//! is); [`zero_torques`](DeviceIo::zero_torques) and `Drop` send a zero write before the port closes.
//!
//! Buttons: the device file's `[[buttons]]` pins are the set-up's analog sensors; every reply's
//! analog values go through a [`ButtonReader`] (by pin rank, debounced over two samples) and
//! [`buttons`](DeviceIo::buttons) returns its state. A lost board reports no button pressed.

use std::io::{Read, Write};
use std::time::Duration;

use haptic2d::device::TwinKinematics;
use haptic2d_rt::{DeviceError, DeviceIo};

use super::buttons::ButtonReader;
use super::codec::{CodecError, FirmwareIdentity, PORTS};
use super::device_file::{HaplyDeviceFile, HaplyKind};
use super::transport::{HaplyError, Transport};

/// How far (encoder counts) an angle right after the setup may be from its offset: the truncation
/// to a whole count (< 1), one edge of jitter, and one count of a hand holding still.
pub const REST_TOLERANCE_COUNTS: f64 = 3.0;

/// How long the driver waits for haptic2d firmware's answer to identify.
pub const IDENTIFY_WAIT: Duration = Duration::from_millis(100);

/// The warning for a board without a watchdog (the stock firmware), printed once at start.
pub const NO_WATCHDOG_WARNING: &str = "this board's firmware has no watchdog: if haptic2d dies, the motors keep the last torque; flash haptic2d's firmware, see docs/FIRMWARE.md";

/// The shortest reply timeout on a pseudo-terminal (control periods; 100 ms at 1 kHz), whatever
/// the device file says. A pseudo-terminal is an emulator (`haptic2d emulate haply`, or haptic2d's
/// firmware built natively): it has no motor, and each reply crosses the kernel's tty worker twice
/// (host → emulator, emulator → host), a kernel thread at normal priority that neither side's
/// real-time priority lifts. On this project's 2-core VM under load (load average 13–15, two
/// CPU-burning threads, both sides at `SCHED_FIFO`) replies took up to 46 ms, where the device
/// file's 20 periods stopped 2 of 10 twin runs with a lost device (issue 39 item 4). A real board's
/// serial port keeps the device file's timeout: there the timeout bounds how long its motors hold
/// a stale torque.
pub const PTY_MIN_TIMEOUT_PERIODS: f64 = 100.0;

/// True when the port `name` (e.g. `haply:/dev/pts/3`) is a pseudo-terminal.
pub fn is_pty(name: &str) -> bool {
    name.contains("/dev/pts/")
}

/// The reply timeout (control periods) the driver uses on the port `name`: the device file's, and
/// on a pseudo-terminal at least [`PTY_MIN_TIMEOUT_PERIODS`].
pub fn timeout_periods_for(file: &HaplyDeviceFile, name: &str) -> f64 {
    if is_pty(name) {
        file.timeout_periods.max(PTY_MIN_TIMEOUT_PERIODS)
    } else {
        file.timeout_periods
    }
}

/// A Haply board driven over `S` (a serial port, or a pseudo-terminal in tests).
#[derive(Debug)]
pub struct HaplyDevice<S: Read + Write> {
    transport: Transport<S>,
    joints: usize,
    wire: [usize; PORTS],
    torque_limit: f64,
    q: [f64; 4],
    sent: [f32; PORTS],
    name: String,
    lost: bool,
    firmware: Option<FirmwareIdentity>,
    /// The port is a pseudo-terminal (an emulator): no USB cable to check.
    pty: bool,
    /// The device file's buttons, from the replies' analog values.
    buttons: ButtonReader,
}

impl<S: Read + Write> HaplyDevice<S> {
    /// Opens the board of device file `file` over `stream` at control period `period` (docs/DEVICES.md
    /// §7): identify, reset, setup and a zero write, and the rest-pose check; nothing but zero
    /// torques has been sent when it returns. `name` (e.g. `haply:/dev/ttyACM0`) appears in
    /// messages. The error names the device and what to check.
    pub fn open(
        stream: S,
        file: &HaplyDeviceFile,
        period: Duration,
        name: &str,
    ) -> Result<Self, String> {
        let timeout = period.mul_f64(timeout_periods_for(file, name));
        let pty = is_pty(name);
        // The handshake may wait for a board that is still booting: allow at least 100 ms.
        let mut transport = Transport::from_stream(
            stream,
            file.board_setup(),
            timeout.max(Duration::from_millis(100)),
        )
        .map_err(|e| format!("{name}: {e}"))?;
        let check = if pty {
            "that the emulator (`haptic2d emulate haply`) still runs on this pseudo-terminal, and that board.id"
        } else {
            "the USB cable, that the board is powered and runs Haply's or haptic2d's firmware, that board.id"
        };
        transport.drain(Duration::from_millis(5), Duration::from_millis(50));
        let firmware = transport.identify(IDENTIFY_WAIT).map_err(|e| {
            format!("{name}: the board answered the identify query (0x03) with something else ({e})\n    check: that {name} is a Haply board, and that no other program has the port open")
        })?;
        let needed = file.motors.iter().map(|m| m.port).max().unwrap_or(0);
        let mut firmware = firmware;
        if let Some(id) = firmware {
            if id.ports < needed {
                return Err(ports_message(name, file, Some(id.ports)));
            }
            if id.has_watchdog() {
                let set = transport
                    .set_watchdog(file.watchdog_ms, IDENTIFY_WAIT)
                    .map_err(|e| {
                        format!(
                            "{name}: setting the board's watchdog to {} ms failed ({e})",
                            file.watchdog_ms
                        )
                    })?;
                if set.watchdog_ms != file.watchdog_ms {
                    return Err(format!(
                        "{name}: the board's watchdog is {} ms after asking for {} ms (board.watchdog_ms in {})",
                        set.watchdog_ms, file.watchdog_ms, file.source
                    ));
                }
                firmware = Some(set);
            }
        }
        let reply = transport.handshake().map_err(|e| match e {
            HaplyError::OutOfStep(CodecError::Short { got, .. }) if got >= 1 => {
                ports_message(name, file, None)
            }
            e => format!(
                "{name}: the board did not answer the set-up ({e})\n    check: {check} = {} in {} is the board's id, and that no other program has the port open",
                file.id, file.source
            ),
        })?;
        transport.set_timeout(timeout);
        let mut dev = Self {
            transport,
            joints: file.joints(),
            wire: file.wire_index(),
            torque_limit: file.torque_limit,
            q: [0.0; 4],
            sent: [0.0; PORTS],
            name: name.to_string(),
            lost: false,
            firmware,
            pty,
            buttons: ButtonReader::new(&file.buttons),
        };
        let n = usize::from(dev.transport.setup().n_sensors);
        dev.buttons.update(&reply.analog[..n]);
        dev.take_angles(&reply.angles_deg);
        check_rest(file, &dev.q).map_err(|e| format!("{name}: {e}"))?;
        Ok(dev)
    }

    fn take_angles(&mut self, deg: &[f32; PORTS]) {
        for j in 0..self.joints {
            self.q[j] = (deg[self.wire[j]] as f64).to_radians();
        }
    }

    /// The torques last sent, in port order (N·m), after clamping (for tests and `device check`).
    pub fn last_sent(&self) -> [f32; PORTS] {
        self.sent
    }

    /// haptic2d firmware's identity, or `None` for a stock firmware (no answer to identify).
    pub fn firmware(&self) -> Option<FirmwareIdentity> {
        self.firmware
    }

    /// The warning to print once at start: `Some` for a board without a watchdog.
    pub fn start_warning(&self) -> Option<&'static str> {
        match self.firmware {
            Some(f) if f.has_watchdog() => None,
            _ => Some(NO_WATCHDOG_WARNING),
        }
    }

    /// One line on the firmware, for the start of a run: stock, or haptic2d's with its watchdog.
    pub fn firmware_summary(&self) -> String {
        match self.firmware {
            None => "stock firmware (no identify answer): no watchdog".into(),
            Some(f) => format!(
                "haptic2d firmware v{} ({} ports): watchdog {}, reset {} the motors, torque clamp {}",
                f.version,
                f.ports,
                if f.has_watchdog() {
                    format!("{} ms", f.watchdog_ms)
                } else {
                    "none".into()
                },
                if f.reset_zeroes_motors() { "zeroes" } else { "keeps" },
                if f.clamps_torque() { "on the board" } else { "in the host only" },
            ),
        }
    }

    /// True once the device is lost (zero torques latched).
    pub fn is_lost(&self) -> bool {
        self.lost
    }

    /// The transport (e.g. to inspect the stream).
    pub fn transport(&self) -> &Transport<S> {
        &self.transport
    }

    /// Latches the loss: an all-zero write at once (no wait for its reply), then the error.
    fn lost_error(&mut self, e: HaplyError) -> DeviceError {
        self.lost = true;
        self.buttons.clear();
        let n = self.transport.setup().n_motors();
        let zeroed = self.transport.send_write(&[0.0; PORTS][..n]).is_ok();
        self.sent = [0.0; PORTS];
        let what = match (&e, self.pty) {
            (HaplyError::OutOfStep(_), _) => "a byte was lost or added on the line; haptic2d does not re-send the setup during a run (the firmware would re-zero its encoders wherever the handle is): check that no other program uses the port, then start again with the handle at the rest pose",
            (_, true) => "this is an emulator on a pseudo-terminal (no USB cable): its replies cross the kernel's tty worker twice, so its timeout is at least 100 periods; check that `haptic2d emulate haply` still runs and got real-time priority (its first line on standard error says), or raise board.timeout_periods above 100",
            (_, false) => "check the USB cable, the board's power supply and that the board still shows up in `haptic2d devices`",
        };
        let zero = if zeroed {
            "zero torques sent"
        } else {
            "the port no longer takes bytes: the board may still hold the last torque"
        };
        DeviceError::Lost(format!("Haply board {}: {e}; {zero}; {what}", self.name))
    }

    fn send(&mut self, tau: &[f32; PORTS]) -> Result<(), DeviceError> {
        self.sent = *tau;
        let n = self.transport.setup().n_motors();
        match self.transport.send_write(&tau[..n]) {
            Ok(()) => Ok(()),
            Err(e) => Err(self.lost_error(e)),
        }
    }

    fn already_lost(&self) -> DeviceError {
        DeviceError::Lost(format!(
            "Haply board {}: already lost (zero torques latched)",
            self.name
        ))
    }
}

/// The message for a board with fewer ports than the file uses (`ports`: what the board said, if
/// it said).
fn ports_message(name: &str, file: &HaplyDeviceFile, ports: Option<u8>) -> String {
    let needed = file.motors.iter().map(|m| m.port).max().unwrap_or(0);
    let has = match ports {
        Some(p) => format!("the board has {p} motor/encoder ports"),
        None => "the board answered the first write with fewer bytes than the set-up asks for: it has fewer motor/encoder ports than the set-up names (an M0 board has 2 ports, an M3 board 4)".into(),
    };
    format!(
        "{name}: {has}, but {} uses ports 1–{needed}\n    fix: a twin pantograph needs an M3 board (4 ports); on an M0 use a 2DIY device file",
        file.source
    )
}

/// The rest-pose check (docs/DEVICES.md §7 step 4): the angles `q` (rad, joint order) read right
/// after the setup must equal the offsets within [`REST_TOLERANCE_COUNTS`] and assemble into the
/// linkage (the twin: closure within `closure_tol`).
pub fn check_rest(file: &HaplyDeviceFile, q: &[f64; PORTS]) -> Result<(), String> {
    for (j, m) in file.motors.iter().enumerate() {
        let tol = REST_TOLERANCE_COUNTS * 360.0 / m.counts_per_turn;
        let got = q[j].to_degrees();
        if (got - m.offset_deg).abs() > tol {
            return Err(format!(
                "motor[{j}] (port {}) reads {got:.3}° right after the set-up, not its offset {:.3}° (± {tol:.3}°): the board did not take the set-up, or the handle moved during it\n    fix: hold the handle still at the rest pose (docs/HARDWARE.md, \"Start-up\") and start again",
                m.port, m.offset_deg
            ));
        }
    }
    match &file.kind {
        HaplyKind::TwoDiy { linkage, .. } => linkage.fk([q[0], q[1]]).map(|_| ()).map_err(|e| {
            format!("the offsets do not assemble into the linkage ({e})\n    fix: check motor[*].offset_deg and [linkage] in {}", file.source)
        }),
        HaplyKind::Twin(p) => match TwinKinematics::new(p).fk(q, 0.0) {
            Ok(_) => Ok(()),
            Err(e) => Err(format!(
                "at the homing pose the two linkages do not close ({e})\n    fix: the four offsets must be the inverse kinematics of one handle pose (see [rest] in devices/haply-twin.toml) in {}",
                file.source
            )),
        },
    }
}

impl<S: Read + Write> DeviceIo for HaplyDevice<S> {
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        if self.lost {
            return Err(self.already_lost());
        }
        if !self.transport.pending() {
            self.send(&[0.0; PORTS])?;
        }
        match self.transport.read_reply() {
            Ok(r) => {
                self.take_angles(&r.angles_deg);
                let n = usize::from(self.transport.setup().n_sensors);
                self.buttons.update(&r.analog[..n]);
                Ok(self.q)
            }
            Err(e) => Err(self.lost_error(e)),
        }
    }

    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
        if self.lost {
            return Err(self.already_lost());
        }
        let mut wire = [0f32; PORTS];
        let mut bad = None;
        for j in 0..self.joints {
            let t = tau[j];
            if !t.is_finite() {
                bad = Some((j, t));
                continue;
            }
            wire[self.wire[j]] = t.clamp(-self.torque_limit, self.torque_limit) as f32;
        }
        if let Some((j, t)) = bad {
            self.send(&[0.0; PORTS])?;
            return Err(DeviceError::Io(format!(
                "Haply board {}: non-finite torque τ[{j}] = {t}; zero torques sent",
                self.name
            )));
        }
        self.send(&wire)
    }

    fn zero_torques(&mut self) {
        if self.lost {
            // Best effort: one zero write, no wait for a board that is not answering.
            let n = self.transport.setup().n_motors();
            let _ = self.transport.send_write(&[0.0; PORTS][..n]);
            self.sent = [0.0; PORTS];
            return;
        }
        if self.transport.pending() {
            let _ = self.transport.read_reply();
        }
        self.sent = [0.0; PORTS];
        let n = self.transport.setup().n_motors();
        if self.transport.send_write(&[0.0; PORTS][..n]).is_ok() {
            let _ = self.transport.read_reply();
        }
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn buttons(&self) -> u8 {
        self.buttons.state()
    }
}

impl<S: Read + Write> Drop for HaplyDevice<S> {
    fn drop(&mut self) {
        self.zero_torques();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gen3() -> HaplyDeviceFile {
        let text = include_str!("../../../../devices/haply-2diy-gen3.toml");
        HaplyDeviceFile::from_toml(text, "haply-2diy-gen3").unwrap()
    }

    /// Issue 39 item 4: an emulator's replies cross the kernel's tty worker twice; on a pseudo-terminal
    /// the reply timeout is at least 100 periods, on a serial port it stays the device file's.
    #[test]
    fn a_pseudo_terminal_waits_at_least_100_periods_a_serial_port_the_files_timeout() {
        let f = gen3();
        assert_eq!(
            timeout_periods_for(&f, "haply:/dev/ttyACM0"),
            f.timeout_periods
        );
        assert_eq!(
            timeout_periods_for(&f, "haply:/dev/pts/3"),
            PTY_MIN_TIMEOUT_PERIODS
        );
        let mut patient = gen3();
        patient.timeout_periods = 500.0;
        assert_eq!(timeout_periods_for(&patient, "haply:/dev/pts/3"), 500.0);
        assert!(f.timeout_periods < PTY_MIN_TIMEOUT_PERIODS);
    }
}
