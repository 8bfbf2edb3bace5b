//! [`HaplyDevice`]: a Haply board behind `haptic2d-rt`'s [`DeviceIo`].
//!
//! Joint `j` (the `j`-th `[[motor]]` of the device file: 2DIY motors 1, 2; twin `q11, q12, q21, q22`)
//! sits on its port; its angle (degrees on the wire) becomes radians, CCW from +x in the board frame.
//! A 2DIY fills `q[0..2]` and ignores `τ[2..4]`.
//!
//! Timing of one tick: [`read_encoders`](DeviceIo::read_encoders) waits for the reply to the previous
//! tick's write (the board sampled its encoders when it serviced that write), or, when no write is
//! pending, sends a zero-torque write first (the protocol's way to read the state);
//! [`write_torques`](DeviceIo::write_torques) sends the write and returns at once. A reply later than
//! `timeout_periods` periods after its write means the device is lost.
//!
//! Safety in the driver itself: every torque is clamped to the device file's `torque_limit`
//! (≤ 0.123 N·m); torques are zero until the first valid reply after opening or after a
//! resynchronisation; a non-finite torque sends zeros and fails; [`zero_torques`](DeviceIo::zero_torques)
//! and `Drop` send a zero write before the port closes.

use std::io::{Read, Write};
use std::time::Duration;

use haptic2d_rt::{DeviceError, DeviceIo};

use super::codec::PORTS;
use super::device_file::HaplyDeviceFile;
use super::transport::{HaplyError, Transport};

/// A Haply board driven over `S` (a serial port, or a pseudo-terminal in tests).
#[derive(Debug)]
pub struct HaplyDevice<S: Read + Write> {
    transport: Transport<S>,
    joints: usize,
    wire: [usize; PORTS],
    torque_limit: f64,
    q: [f64; 4],
    valid: bool,
    resyncs_seen: u32,
    sent: [f32; PORTS],
    name: String,
    lost: bool,
}

impl<S: Read + Write> HaplyDevice<S> {
    /// Opens the board of device file `file` over `stream` at control period `period`: sends reset,
    /// setup and a zero write and waits for the reply (before the first deadline). `name` (e.g.
    /// `haply:/dev/ttyACM0`) appears in messages. The error names the device and what to check.
    pub fn open(
        stream: S,
        file: &HaplyDeviceFile,
        period: Duration,
        name: &str,
    ) -> Result<Self, String> {
        let timeout = period.mul_f64(file.timeout_periods);
        // The handshake may wait for a board that is still booting: allow at least 100 ms.
        let mut transport = Transport::from_stream(
            stream,
            file.board_setup(),
            timeout.max(Duration::from_millis(100)),
        )
        .map_err(|e| format!("{name}: {e}"))?;
        let reply = transport.handshake().map_err(|e| {
            format!(
                "{name}: the board did not answer the set-up ({e})\n    check: the USB cable, that the board is powered and runs Haply's firmware, that board.id = {} in {} is the board's id, and that no other program has the port open",
                file.id, file.source
            )
        })?;
        transport.set_timeout(timeout);
        let mut dev = Self {
            transport,
            joints: file.joints(),
            wire: file.wire_index(),
            torque_limit: file.torque_limit,
            q: [0.0; 4],
            valid: false,
            resyncs_seen: 0,
            sent: [0.0; PORTS],
            name: name.to_string(),
            lost: false,
        };
        dev.take_angles(&reply.angles_deg);
        Ok(dev)
    }

    fn take_angles(&mut self, deg: &[f32; PORTS]) {
        for j in 0..self.joints {
            self.q[j] = (deg[self.wire[j]] as f64).to_radians();
        }
        self.valid = true;
    }

    /// The torques last sent, in port order (N·m), after clamping (for tests and `device check`).
    pub fn last_sent(&self) -> [f32; PORTS] {
        self.sent
    }

    /// Resynchronisations so far.
    pub fn resyncs(&self) -> u32 {
        self.transport.resyncs()
    }

    /// The transport (e.g. to inspect the stream).
    pub fn transport(&self) -> &Transport<S> {
        &self.transport
    }

    fn lost_error(&mut self, e: HaplyError) -> DeviceError {
        self.lost = true;
        let what = match &e {
            HaplyError::OutOfStep(_) => "check that no other program uses the port and that the device file's board set-up matches the board",
            _ => "check the USB cable, the board's power supply and that the board still shows up in `haptic2d devices`",
        };
        DeviceError::Lost(format!("Haply board {}: {e}; {what}", self.name))
    }

    fn send(&mut self, tau: &[f32; PORTS]) -> Result<(), DeviceError> {
        self.sent = *tau;
        let n = self.transport.setup().n_motors();
        self.transport
            .send_write(&tau[..n])
            .map_err(|e| self.lost_error(e))
    }
}

impl<S: Read + Write> DeviceIo for HaplyDevice<S> {
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        if self.lost {
            return Err(DeviceError::Lost(format!(
                "Haply board {}: already lost",
                self.name
            )));
        }
        if !self.transport.pending() {
            self.send(&[0.0; PORTS])?;
        }
        match self.transport.read_reply() {
            Ok(r) => {
                if self.transport.resyncs() != self.resyncs_seen {
                    // The board was set up again: torques stay zero until this first valid reply.
                    self.resyncs_seen = self.transport.resyncs();
                }
                self.take_angles(&r.angles_deg);
                Ok(self.q)
            }
            Err(e) => {
                self.valid = false;
                Err(self.lost_error(e))
            }
        }
    }

    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
        if self.lost {
            return Err(DeviceError::Lost(format!(
                "Haply board {}: already lost",
                self.name
            )));
        }
        let mut wire = [0f32; PORTS];
        let mut bad = None;
        for j in 0..self.joints {
            let t = tau[j];
            if !t.is_finite() {
                bad = Some((j, t));
                continue;
            }
            if self.valid {
                wire[self.wire[j]] = t.clamp(-self.torque_limit, self.torque_limit) as f32;
            }
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
        if self.send(&[0.0; PORTS]).is_ok() {
            let _ = self.transport.read_reply();
        }
    }

    fn name(&self) -> &str {
        &self.name
    }
}

impl<S: Read + Write> Drop for HaplyDevice<S> {
    fn drop(&mut self) {
        self.zero_torques();
    }
}
