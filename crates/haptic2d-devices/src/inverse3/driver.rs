//! [`Inverse3Device`]: a Haply Inverse3 through its Inverse Service, in planar mode, as a Cartesian
//! point device: it reports the plane point (m) and takes the plane force (N), behind
//! `haptic2d-rt`'s [`DeviceIo`] with the point-device convention of
//! [`DeviceSystem::Point`](haptic2d::haptic::DeviceSystem::Point): `q = [x, y, 0, 0]` (m),
//! `τ = [f_x, f_y, ·, ·]` (N; `τ[2..4]` have no actuator and are ignored). No linkage stands in
//! between: the loop's [`PointSystem`](haptic2d::haptic::PointSystem) renders the force itself.
//!
//! The exchange on the tick is two slot operations: [`read_point`](Inverse3Device::read_point)
//! takes the newest state from the client thread's slot and maps its cursor to the plane;
//! [`write_force`](Inverse3Device::write_force) clamps the plane force to the force limit and puts
//! it in the command slot. Nothing there blocks, allocates or locks (the error paths format their
//! messages).
//!
//! Safety in the driver itself: force is zero until the first valid state and ramps in (the loop's
//! start-up ramp for the plane force, the client's for the virtual plane); every force is clamped
//! to `limits.force_limit` here and once more, with the plane's force, in the client; a
//! non-finite force sends zero and fails; a state older than `service.timeout_periods` periods, or
//! a client that closed, is a lost device (zero force latched); [`zero_force`](Inverse3Device::zero_force)
//! ([`DeviceIo::zero_torques`]) latches zero force (the run loop calls it only on its way out: every
//! later command is zero) and `Drop` stops the client (zero force, then the connection closes).

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};

use haptic2d_rt::clock::now_ns;
use haptic2d_rt::{DeviceError, DeviceIo};

use super::client::{self, ClientConfig, ClientEnds, OPEN_TIMEOUT};
use super::device_file::Inverse3DeviceFile;
use super::planar::{clamp_norm, PlaneMap};
use super::slots::{ClientStatus, ForceCommand, Inverse3Sample};

/// A Haply Inverse3 in planar mode.
pub struct Inverse3Device {
    state: triple_buffer::Output<Inverse3Sample>,
    command: triple_buffer::Input<ForceCommand>,
    status: Arc<ClientStatus>,
    thread: Option<std::thread::JoinHandle<()>>,
    map: PlaneMap,
    timeout_ns: u64,
    timeout: Duration,
    point: [f64; 2],
    sample: Inverse3Sample,
    valid: bool,
    lost: bool,
    latched: bool,
    sent: [f64; 2],
    name: String,
    ws_url: String,
}

impl std::fmt::Debug for Inverse3Device {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Inverse3Device")
            .field("name", &self.name)
            .field("valid", &self.valid)
            .field("lost", &self.lost)
            .finish_non_exhaustive()
    }
}

impl Inverse3Device {
    /// Connects to the Inverse Service of `file` (its `http_url`, `ws_url`) for a loop at `period`,
    /// starts the client thread and waits (up to [`OPEN_TIMEOUT`]) for the first state of an
    /// Inverse3, before the first deadline. `name` (e.g. `inverse3:http://localhost:10001`) appears
    /// in messages; errors say what to check.
    pub fn open(file: &Inverse3DeviceFile, period: Duration, name: &str) -> Result<Self, String> {
        let check = format!(
            "\n    check: that the Haply Inverse Service runs and listens at {} (without a device: haptic2d emulate inverse3), that the Inverse3 is plugged in and powered, and the [service] table of {}",
            file.ws_url, file.source
        );
        let (state_in, state_out) = triple_buffer::triple_buffer(&Inverse3Sample::default());
        let (cmd_in, cmd_out) = triple_buffer::triple_buffer(&ForceCommand::default());
        let status = Arc::new(ClientStatus::default());
        let map = PlaneMap::new(file);
        let timeout = period.mul_f64(file.timeout_periods);
        let thread = client::spawn(
            ClientConfig {
                http_url: file.http_url.clone(),
                ws_url: file.ws_url.clone(),
                period,
                timeout,
                map,
            },
            ClientEnds {
                state: state_in,
                command: cmd_out,
                status: status.clone(),
            },
            name,
        )
        .map_err(|e| format!("{name}: {e}{check}"))?;
        let mut dev = Self {
            state: state_out,
            command: cmd_in,
            status,
            thread: Some(thread),
            map,
            timeout_ns: timeout.as_nanos() as u64,
            timeout,
            point: [0.0; 2],
            sample: Inverse3Sample::default(),
            valid: false,
            lost: false,
            latched: false,
            sent: [0.0; 2],
            name: name.to_string(),
            ws_url: file.ws_url.clone(),
        };
        let start = Instant::now();
        while start.elapsed() < OPEN_TIMEOUT {
            if dev.state.read().seq > 0 {
                break;
            }
            if let Some(r) = dev.status.closed_reason() {
                return Err(format!("{name}: {r}{check}"));
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        if dev.state.read().seq == 0 {
            return Err(format!(
                "{name}: no Inverse3 state from the service within {} ms (connected to {}, but it reported no Inverse3){check}",
                OPEN_TIMEOUT.as_millis(),
                file.ws_url
            ));
        }
        dev.take().map_err(|e| e.to_string())?;
        Ok(dev)
    }

    /// The newest state and its plane point, or the error that ends the run.
    #[inline]
    fn take(&mut self) -> Result<(), DeviceError> {
        let s = *self.state.read();
        let age = now_ns().saturating_sub(s.rx_ns);
        if self.status.closed_reason().is_some() {
            let status = self.status.clone();
            let reason = status.closed_reason().unwrap_or("closed");
            return Err(self.lose(format_args!("{reason}")));
        }
        if s.seq == 0 || age > self.timeout_ns {
            return Err(self.lose(format_args!(
                "no new state for {:.1} ms (timeout {:.1} ms = service.timeout_periods)",
                age as f64 * 1e-6,
                self.timeout.as_secs_f64() * 1e3
            )));
        }
        self.sample = s;
        let u = self.map.planar(&s.position);
        if !(u[0].is_finite() && u[1].is_finite()) {
            // No force follows a reading that is not a point (`write_force` sends zero).
            self.valid = false;
            return Err(DeviceError::Io(format!(
                "Inverse3 {}: the cursor's plane point ({}, {}) m is not finite",
                self.name, u[0], u[1]
            )));
        }
        self.point = u;
        self.valid = true;
        Ok(())
    }

    fn lose(&mut self, why: std::fmt::Arguments<'_>) -> DeviceError {
        self.lost = true;
        self.valid = false;
        self.latched = true;
        self.command.write(ForceCommand {
            planar: [0.0; 2],
            enable: false,
            latched: true,
        });
        DeviceError::Lost(format!(
            "Inverse3 {}: {why}; zero force latched\n    check: that the Haply Inverse Service still runs at {}, the device's USB cable and power",
            self.name, self.ws_url
        ))
    }

    /// The newest state the driver used.
    pub fn sample(&self) -> &Inverse3Sample {
        &self.sample
    }

    /// The plane force last put in the command slot (N, world axes), after clamping.
    pub fn last_sent(&self) -> [f64; 2] {
        self.sent
    }

    /// The handle's angle about the held axis (rad) from the VerseGrip's orientation, where the
    /// service reports one: the device's unit vector along the plane's x axis, rotated by the
    /// quaternion `(w, x, y, z)` and seen in the plane, `atan2(u_y, u_x)` (for the plane x = device
    /// x, y = device y, the yaw `atan2(2(wz + xy), 1 − 2(y² + z²))`). `None` without a VerseGrip.
    pub fn grip_angle(&self) -> Option<f64> {
        handle_angle(&self.map, self.sample.orientation?)
    }
}

/// [`Inverse3Device::grip_angle`] for the mapping `map` and the quaternion `q = (w, x, y, z)`.
pub fn handle_angle(map: &PlaneMap, q: [f64; 4]) -> Option<f64> {
    let [w, x, y, z] = q;
    let (i, s) = map.axis(0);
    let mut v = [0.0; 3];
    v[i] = s;
    // v' = v + 2w(q×v) + 2q×(q×v), q = (x, y, z).
    let c = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let t = c([x, y, z], v);
    let u = c([x, y, z], t);
    let r: [f64; 3] = std::array::from_fn(|k| v[k] + 2.0 * w * t[k] + 2.0 * u[k]);
    let p = map.planar(&r);
    (p[0].hypot(p[1]) > 1e-9).then(|| p[1].atan2(p[0]))
}

impl Inverse3Device {
    /// The cursor's plane point `(x, y)` (m, the plane's axes in the device frame: see
    /// [`PlaneMap::planar`]) from the newest state. A stale state, a closed client or a device
    /// already lost is [`DeviceError::Lost`] (zero force latched). Never allocates on success.
    #[inline]
    pub fn read_point(&mut self) -> Result<[f64; 2], DeviceError> {
        if self.lost {
            return Err(DeviceError::Lost(format!(
                "Inverse3 {}: already lost",
                self.name
            )));
        }
        self.take()?;
        Ok(self.point)
    }

    /// Commands the plane force `f = (f_x, f_y)` (N): clamped to `limits.force_limit` keeping its
    /// direction, then put in the command slot with the virtual plane enabled. A non-finite
    /// component sends zero and fails; before a valid state, zero is sent; after a zero command
    /// ([`Self::zero_force`]) every command is zero. Never allocates on success.
    #[inline]
    pub fn write_force(&mut self, f: &[f64; 2]) -> Result<(), DeviceError> {
        if self.lost {
            return Err(DeviceError::Lost(format!(
                "Inverse3 {}: already lost",
                self.name
            )));
        }
        if let Some(j) = (0..2).find(|&j| !f[j].is_finite()) {
            self.put([0.0; 2], false);
            return Err(DeviceError::Io(format!(
                "Inverse3 {}: non-finite force f[{j}] = {} N; zero force sent",
                self.name, f[j]
            )));
        }
        if !self.valid {
            self.put([0.0; 2], false);
            return Ok(());
        }
        self.put(clamp_norm(*f, self.map.force_limit()), true);
        Ok(())
    }

    /// Latches zero force: this and every later command is zero, with the virtual plane off.
    pub fn zero_force(&mut self) {
        self.sent = [0.0; 2];
        self.latched = true;
        self.command.write(ForceCommand {
            planar: [0.0; 2],
            enable: false,
            latched: true,
        });
    }
}

/// The loop's device interface with the point-device convention (see the module doc).
impl DeviceIo for Inverse3Device {
    /// `[x, y, 0, 0]`: the plane point (m), [`Inverse3Device::read_point`].
    #[inline]
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        let [x, y] = self.read_point()?;
        Ok([x, y, 0.0, 0.0])
    }

    /// `τ[0..2]` is the plane force (N), [`Inverse3Device::write_force`]; `τ[2..4]` is ignored (no
    /// actuator: the point system's are always zero).
    #[inline]
    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
        self.write_force(&[tau[0], tau[1]])
    }

    fn zero_torques(&mut self) {
        self.zero_force();
    }

    fn name(&self) -> &str {
        &self.name
    }

    /// The VerseGrip's angle ([`Inverse3Device::grip_angle`]): the loop's twist target.
    fn handle_angle(&self) -> Option<f64> {
        self.grip_angle()
    }
}

impl Inverse3Device {
    #[inline]
    fn put(&mut self, f: [f64; 2], enable: bool) {
        // After a zero command every command stays zero and latched (the client keeps seeing it,
        // however many commands a period the loop writes).
        let on = !self.latched;
        self.sent = if on { f } else { [0.0; 2] };
        self.command.write(ForceCommand {
            planar: self.sent,
            enable: enable && on,
            latched: !on,
        });
    }
}

impl Drop for Inverse3Device {
    fn drop(&mut self) {
        self.zero_force();
        self.status.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_handle_angle_is_the_grip_yaw_about_the_held_axis() {
        let map = PlaneMap::new(&Inverse3DeviceFile::shipped()); // world x, y = device x, y
        let a: f64 = 0.5; // rad about +z: q = (cos a/2, 0, 0, sin a/2)
        let q = [(a / 2.0).cos(), 0.0, 0.0, (a / 2.0).sin()];
        assert!((handle_angle(&map, q).unwrap() - a).abs() < 1e-12);
        assert!(handle_angle(&map, [1.0, 0.0, 0.0, 0.0]).unwrap().abs() < 1e-12);
        // A plane on device x and −z: a turn about +y takes x towards −z, i.e. +θ in the plane.
        let text = super::super::device_file::DEFAULT_FILE
            .replace("axes = [\"x\", \"y\"]", "axes = [\"x\", \"-z\"]");
        let map = PlaneMap::new(&Inverse3DeviceFile::from_toml(&text, "f").unwrap());
        let q = [(a / 2.0).cos(), 0.0, (a / 2.0).sin(), 0.0];
        assert!((handle_angle(&map, q).unwrap() - a).abs() < 1e-12);
        // A grip turned so that the plane's x axis points along the held axis: no angle.
        let h = std::f64::consts::FRAC_PI_4;
        let map = PlaneMap::new(&Inverse3DeviceFile::shipped());
        assert_eq!(handle_angle(&map, [h.cos(), 0.0, -h.sin(), 0.0]), None);
    }
}
