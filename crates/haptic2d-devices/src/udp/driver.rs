//! [`UdpDevice`]: a device on the open UDP protocol behind `haptic2d-rt`'s [`DeviceIo`], joints
//! `q[0..2]` (the 2-DOF pantograph; `τ[2..4]` ignored).
//!
//! Timing of one tick (the Haply driver's): [`read_encoders`](DeviceIo::read_encoders) waits for the
//! answer to the previous tick's command, at most `reply_wait_periods` of a period (or, with nothing
//! pending, sends a poll — a command without [`FLAG_ENABLE`] — first);
//! [`write_torques`](DeviceIo::write_torques) sends the command and returns. A missed answer is not
//! yet a lost device: the read returns the newest state it has (a late answer counts), so a lost
//! or reordered datagram costs one tick of stale angles. No state for `timeout_periods` periods
//! after a command (measured from the host's send, so a stalled host does not blame the device), or a state with [`STATUS_FAULT`], means the device is lost.
//!
//! Safety in the driver itself: torques are zero until the first valid state; every torque is
//! clamped to the device file's `torque_limit`; a non-finite torque sends a zero command and fails;
//! [`zero_torques`](DeviceIo::zero_torques) sends a [`FLAG_LATCHED`] zero command and `Drop` a
//! [`FLAG_BYE`]. Nothing allocates on the exchange, the MAC check included (only the error paths
//! format messages).
//!
//! Buttons: [`buttons`](DeviceIo::buttons) is `status` bits 8–15 of the newest state used (bit `i`
//! = button `i`, as the device sampled it; the device debounces); a lost device reports none.
//!
//! Authentication: with a key (`protocol.key_file`) the driver speaks version 2 — a session
//! handshake before the first poll, a MAC on every datagram, every drop counted by reason. Without
//! one it speaks version 1, which [`UdpDevice::open`] allows only towards a loopback address.

use std::net::SocketAddr;
use std::time::{Duration, Instant};

use haptic2d::geom::Vec2;
use haptic2d_rt::{DeviceError, DeviceIo};

use super::codec::{State, FLAG_BYE, FLAG_ENABLE, FLAG_LATCHED, FLAG_WRENCH, STATUS_FAULT};
use super::device_file::UdpDeviceFile;
use super::transport::{UdpCounters, UdpTransport};

/// A device on the UDP protocol.
#[derive(Debug)]
pub struct UdpDevice {
    transport: UdpTransport,
    file: UdpDeviceFile,
    wait: Duration,
    timeout: Duration,
    q: [f64; 4],
    valid: bool,
    sent: [f32; 3],
    name: String,
    lost: bool,
    /// The device listens on this machine (a program, e.g. a reference device), not on a network.
    loopback: bool,
    /// The buttons of the newest state used (status bits 8–15).
    buttons: u8,
}

/// The silence after a command that means the device is lost: the device file's
/// `protocol.timeout_periods` periods of `period`, and for a device on loopback at least the
/// `[safety] stall_floor` (0.02 s by default).
///
/// Why the floor on loopback: such a device is a program sharing this machine's CPUs (a reference
/// device, an emulator, a bridge), so whatever stops the host for a while (a loaded machine, a
/// hypervisor taking the virtual machine's CPUs away) stops the device as well. The host tolerates
/// a stall of its own loop up to `stall_floor` before it latches; it must tolerate the same stall
/// of a peer on the same CPUs, or it blames the device for the machine. Measured on this project's
/// CI virtual machine: replies 6.1 ms and 8.4 ms late against 3 periods (3 ms) during hypervisor
/// steal, 1 run in 10 of the UDP tutorials (issue 39). A device across a network keeps the file's
/// timeout: there it bounds how long a stale state drives the torques.
pub fn timeout_for(file: &UdpDeviceFile, period: Duration, loopback: bool) -> Duration {
    let periods = period.mul_f64(file.timeout_periods);
    if loopback {
        periods.max(Duration::from_secs_f64(file.safety.stall_floor))
    } else {
        periods
    }
}

/// How long [`UdpDevice::open`] waits for the device's first state.
pub const OPEN_TIMEOUT: Duration = Duration::from_secs(1);

impl UdpDevice {
    /// Connects to the device listening at `addr`, described by `file`, for a loop at `period`, and
    /// waits (up to [`OPEN_TIMEOUT`], a poll every 50 ms) for its first state, before the first
    /// deadline. `name` (e.g. `udp:127.0.0.1:5005`) appears in messages; errors say what to check.
    pub fn open(
        addr: SocketAddr,
        file: &UdpDeviceFile,
        period: Duration,
        name: &str,
    ) -> Result<Self, String> {
        if file.key.is_none() && !addr.ip().is_loopback() {
            return Err(format!(
                "{name}: {} has no protocol.key_file, and protocol version 1 (unauthenticated: anyone on the network could send states or commands) is allowed on loopback only\n    fix: give the device and {} a shared key (protocol.key_file, docs/DEVICE-PROTOCOL.md §6)",
                file.source, file.source
            ));
        }
        let transport = UdpTransport::connect_with(addr, file.key.clone())
            .map_err(|e| format!("{name}: cannot open a UDP socket towards {addr}: {e}"))?;
        let mut dev = Self {
            transport,
            file: file.clone(),
            wait: period.mul_f64(file.reply_wait_periods),
            timeout: timeout_for(file, period, addr.ip().is_loopback()),
            q: [0.0; 4],
            valid: false,
            sent: [0.0; 3],
            name: name.to_string(),
            lost: false,
            loopback: addr.ip().is_loopback(),
            buttons: 0,
        };
        let start = Instant::now();
        let io = |e: std::io::Error| format!("{name}: UDP error: {e}");
        if !dev
            .transport
            .handshake(start + OPEN_TIMEOUT, Duration::from_millis(50))
            .map_err(io)?
        {
            let c = dev.transport.counters();
            let why = if c.bad_mac > 0 {
                "answers came with a MAC that does not match: the device has another key"
            } else {
                "no answer to the session handshake"
            };
            return Err(format!(
                "{name}: no session with the device within {} ms: {why} ({c})\n    check: that the device runs at {addr} with the same key as {} (protocol version 2, e.g. devices/udp/sim_device.py --bind {addr} --key-file KEY), and that a firewall lets UDP through",
                OPEN_TIMEOUT.as_millis(),
                file.source
            ));
        }
        while start.elapsed() < OPEN_TIMEOUT {
            dev.transport.send(0, [0.0; 3]).map_err(io)?;
            if dev
                .transport
                .wait_answer(Instant::now() + Duration::from_millis(50))
                .map_err(io)?
            {
                break;
            }
        }
        let Some(s) = dev.transport.latest().copied() else {
            return Err(format!(
                "{name}: no state from the device within {} ms ({})\n    check: that the device runs and listens at {addr} (try devices/udp/sim_device.py --bind {addr}), that a firewall lets UDP through, and that it speaks protocol version {} (docs/DEVICE-PROTOCOL.md)",
                OPEN_TIMEOUT.as_millis(),
                dev.transport.counters(),
                dev.transport.version()
            ));
        };
        if s.is_pose() != file.pose_input {
            let (got, want) = if s.is_pose() {
                ("a pose", "joints")
            } else {
                ("joint angles", "pose")
            };
            return Err(format!(
                "{name}: the device sends {got}, but {} says protocol.input = \"{want}\"\n    fix: set protocol.input to match the device",
                file.source
            ));
        }
        dev.take(&s).map_err(|e| e.to_string())?;
        Ok(dev)
    }

    /// Joint angles from a state: directly, or by the linkage's inverse kinematics of a pose.
    fn take(&mut self, s: &State) -> Result<(), DeviceError> {
        if s.status & STATUS_FAULT != 0 {
            self.lost = true;
            self.valid = false;
            self.buttons = 0;
            return Err(DeviceError::Lost(format!(
                "UDP device {}: the device reports a fault (status bit 5); check the device's own log or display",
                self.name
            )));
        }
        let p = s.position;
        if self.file.pose_input {
            let e = Vec2::new(p[0] as f64, p[1] as f64);
            match self.file.linkage.ik(e) {
                Ok(q) => {
                    self.q[0] = q[0];
                    self.q[1] = q[1];
                }
                Err(f) => {
                    self.valid = false;
                    return Err(DeviceError::Io(format!(
                        "UDP device {}: pose ({}, {}) m is out of the linkage's reach ({f}); check [linkage] of {}",
                        self.name, p[0], p[1], self.file.source
                    )));
                }
            }
        } else {
            self.q[0] = p[0] as f64;
            self.q[1] = p[1] as f64;
        }
        self.buttons = s.buttons();
        self.valid = true;
        Ok(())
    }

    /// The network counters.
    pub fn counters(&self) -> &UdpCounters {
        self.transport.counters()
    }

    /// The round trip of the answer the last read received, if it was fresh (ns), once.
    pub fn take_rtt(&mut self) -> Option<u64> {
        self.transport.take_rtt()
    }

    /// The transport (round trip, latest state).
    pub fn transport(&self) -> &UdpTransport {
        &self.transport
    }

    /// The command last sent: joint torques (N·m) or a wrench (N, N, N·m), after clamping.
    pub fn last_sent(&self) -> [f32; 3] {
        self.sent
    }

    fn send(&mut self, flags: u16, cmd: [f32; 3]) -> Result<(), DeviceError> {
        self.sent = cmd;
        match self.transport.send(flags, cmd) {
            Ok(_) => Ok(()),
            Err(e) => {
                self.lost = true;
                Err(DeviceError::Lost(format!(
                    "UDP device {}: send failed: {e}; check the network interface and the address",
                    self.name
                )))
            }
        }
    }

    fn already_lost(&self) -> DeviceError {
        DeviceError::Lost(format!("UDP device {}: already lost", self.name))
    }

    /// The wrench `f = J⁻ᵀ·τ` (N) at the current angles for joint torques `tau` (N·m): solves
    /// `Jᵀ·f = τ` by Cramer's rule. `None` at a singularity.
    fn wrench(&self, tau: [f64; 2]) -> Option<[f64; 2]> {
        let j = self.file.linkage.state([self.q[0], self.q[1]]).ok()?.j;
        // Jᵀ = [[j00, j10], [j01, j11]].
        let (a, b, c, d) = (j[0][0], j[1][0], j[0][1], j[1][1]);
        let det = a * d - b * c;
        if det.abs() < 1e-12 {
            return None;
        }
        Some([
            (d * tau[0] - b * tau[1]) / det,
            (a * tau[1] - c * tau[0]) / det,
        ])
    }
}

impl DeviceIo for UdpDevice {
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        if self.lost {
            return Err(self.already_lost());
        }
        if !self.transport.pending() {
            self.send(0, [0.0; 3])?;
        }
        let deadline = Instant::now() + self.wait;
        // A missed answer (false) is not yet fatal: the newest state stands in for it.
        self.transport.wait_answer(deadline).map_err(|e| {
            DeviceError::Lost(format!("UDP device {}: receive failed: {e}", self.name))
        })?;
        let silent_for = self.transport.silent_for();
        if silent_for > self.timeout {
            self.lost = true;
            self.valid = false;
            self.buttons = 0;
            return Err(DeviceError::Lost(format!(
                "UDP device {}: no state for {:.1} ms after a command (timeout {:.1} ms = protocol.timeout_periods); {}\n    check: {}",
                self.name,
                silent_for.as_secs_f64() * 1e3,
                self.timeout.as_secs_f64() * 1e3,
                self.transport.counters(),
                if self.loopback {
                    "the device is a program on this machine (loopback, no network; its timeout is at least [safety] stall_floor): that it still runs, and that it has real-time priority (the reference devices say so on standard error; on a loaded machine one without it answers late)"
                } else {
                    "that the device still runs and that the network between host and device is up"
                }
            )));
        }
        if let Some(s) = self.transport.latest().copied() {
            self.take(&s)?;
        }
        Ok(self.q)
    }

    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
        if self.lost {
            return Err(self.already_lost());
        }
        if let Some(j) = (0..2).find(|&j| !tau[j].is_finite()) {
            self.send(0, [0.0; 3])?;
            return Err(DeviceError::Io(format!(
                "UDP device {}: non-finite torque τ[{j}] = {}; zero command sent",
                self.name, tau[j]
            )));
        }
        if !self.valid {
            return self.send(0, [0.0; 3]);
        }
        let lim = self.file.torque_limit;
        let t = [tau[0].clamp(-lim, lim), tau[1].clamp(-lim, lim)];
        if self.file.wrench_output {
            match self.wrench(t) {
                Some(f) => self.send(FLAG_ENABLE | FLAG_WRENCH, [f[0] as f32, f[1] as f32, 0.0]),
                None => self.send(FLAG_WRENCH, [0.0; 3]),
            }
        } else {
            self.send(FLAG_ENABLE, [t[0] as f32, t[1] as f32, 0.0])
        }
    }

    fn zero_torques(&mut self) {
        let _ = self.transport.send(FLAG_LATCHED, [0.0; 3]);
        self.sent = [0.0; 3];
        if !self.lost {
            let _ = self
                .transport
                .wait_answer(Instant::now() + self.wait.max(Duration::from_millis(1)));
        }
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn buttons(&self) -> u8 {
        self.buttons
    }
}

impl Drop for UdpDevice {
    fn drop(&mut self) {
        let _ = self.transport.send(FLAG_BYE, [0.0; 3]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_loopback_device_gets_at_least_the_stall_floor_and_a_network_device_the_files_timeout() {
        let f = UdpDeviceFile::reference();
        let t = Duration::from_millis(1);
        assert_eq!(f.timeout_periods, 3.0);
        assert_eq!(f.safety.stall_floor, 0.02);
        // Across a network: the file's 3 periods bound how long a stale state drives the torques.
        assert_eq!(timeout_for(&f, t, false), Duration::from_millis(3));
        // On loopback the device shares the host's CPUs: the host's own stall floor.
        assert_eq!(timeout_for(&f, t, true), Duration::from_millis(20));
        // A file that asks for more than the floor keeps it on loopback too.
        let mut patient = f.clone();
        patient.timeout_periods = 50.0;
        assert_eq!(timeout_for(&patient, t, true), Duration::from_millis(50));
        // A slower loop: 3 periods of 10 ms are beyond the floor already.
        assert_eq!(
            timeout_for(&f, Duration::from_millis(10), true),
            Duration::from_millis(30)
        );
    }
}
