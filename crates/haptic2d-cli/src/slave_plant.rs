//! The slave of `haptic2d serve-world`: a scene's body (the world side of the split loop) or a
//! device (`serve-world --device DEV`: the slave device of a bilateral teleoperation across a
//! network, whose master is `haptic2d run --device DEV --world udp:…`; docs/TELEOP.md).
//!
//! Every period the world side asks the slave for its pose and twist from its start
//! ([`SlavePlant::sense`]), computes the coupling force and its port's passivity controller, and
//! applies the force over the period ([`SlavePlant::apply`]): a body is driven and the world
//! stepped; a device goes through its [`DeviceEnd`] (the same safety stage as every device's in
//! `run`: ramp, workspace wall, saturation, limit cycle, final gate) to its motors. A device's
//! latch or loss ends the session ([`SlavePlant::stop`]). None of this allocates.

use haptic2d::device::linalg::V3;
use haptic2d::device::DeviceEstimate;
use haptic2d::geom::Vec2;
use haptic2d::haptic::{DeviceEnd, SafetyTrip};
use haptic2d::world::World;
use haptic2d_rt::{DeviceError, DeviceIo, TickInfo, TickInterval};

use crate::end_io::EndIo;

/// A scene's body driven by the coupling.
pub struct BodySlave {
    /// The world.
    pub world: World,
    /// The slave body's index.
    pub slave: usize,
    /// Its pose at the start (m, m, rad).
    pub origin: V3,
}

/// Why a slave device stopped the session.
#[derive(Clone, Debug)]
pub enum SlaveStop {
    /// Its safety stage latched (stall, plausibility, workspace, limit cycle, singularity, gate).
    Safety(SafetyTrip),
    /// It stopped answering, or a read or write failed (the driver's words).
    Lost(DeviceError),
}

/// A device driven by the coupling, with its safety stage.
pub struct DeviceSlave {
    io: EndIo,
    end: DeviceEnd,
    axes: [bool; 3],
    interval: TickInterval,
    /// The last read's wait for the device and the previous tick's (ns).
    read_wait_ns: (u64, u64),
    est: Option<DeviceEstimate>,
    /// Why it stopped, once it has.
    pub stop: Option<SlaveStop>,
}

impl DeviceSlave {
    /// The opened device `io` and its end.
    pub fn new(io: Box<dyn DeviceIo + Send>, end: DeviceEnd) -> Self {
        Self {
            io: EndIo::Real(io),
            axes: end.axes(),
            end,
            interval: TickInterval::new(),
            read_wait_ns: (0, 0),
            est: None,
            stop: None,
        }
    }
}

/// What the slave really received over the period.
#[derive(Clone, Copy, Debug)]
pub struct Applied {
    /// The force really applied (N, N, N·m): a device's after its ramp, saturation and gate.
    pub force: V3,
    /// The rate the port books it against (m/s, m/s, rad/s): a body's true displacement over the
    /// world step divided by the period; a device's filtered twist at the reading.
    pub rate: V3,
    /// True when `rate` is the plant's true motion (a body), so that a ledger on it is the plant's.
    pub exact: bool,
    /// The magnitude of the wall's force on a body (N); `None` for a device (no force sensor).
    pub wall: Option<f64>,
}

/// The slave of the world side.
#[allow(clippy::large_enum_variant)] // one per run, never moved in the loop
pub enum SlavePlant {
    /// A scene's body.
    Body(BodySlave),
    /// A device.
    Device(DeviceSlave),
}

impl SlavePlant {
    /// The slave's pose from its start (m, m, rad) and twist (m/s, m/s, rad/s) this period;
    /// `None` when a device could not be read or sensed (then [`Self::stop`] says why). A device
    /// renders its axes only (θ is zero on a 2-DOF device).
    pub fn sense(&mut self, info: &TickInfo) -> Option<(V3, V3)> {
        match self {
            SlavePlant::Body(b) => {
                let body = &b.world.bodies[b.slave];
                let o = b.origin;
                Some((
                    [
                        body.pose.pos.x - o[0],
                        body.pose.pos.y - o[1],
                        body.pose.angle - o[2],
                    ],
                    [body.vel.x, body.vel.y, body.omega],
                ))
            }
            SlavePlant::Device(d) => d.sense(info),
        }
    }

    /// Applies `f` (N, N, N·m) over the period to the slave sensed at `x` (from [`Self::sense`]).
    pub fn apply(&mut self, info: &TickInfo, f: &V3, x: &V3) -> Applied {
        let dt = info.period_s;
        match self {
            SlavePlant::Body(b) => {
                b.world.set_drive(b.slave, Vec2::new(f[0], f[1]), f[2]);
                b.world.step();
                let p = &b.world.bodies[b.slave].pose;
                let after = [
                    p.pos.x - b.origin[0],
                    p.pos.y - b.origin[1],
                    p.angle - b.origin[2],
                ];
                let w = b.world.contact_wrench(b.slave).force;
                Applied {
                    force: *f,
                    rate: std::array::from_fn(|i| (after[i] - x[i]) / dt),
                    exact: true,
                    wall: Some(w.x.hypot(w.y)),
                }
            }
            SlavePlant::Device(d) => d.apply(info, f),
        }
    }

    /// The passivity controller's damping caps `2·m/T` per axis (N·s/m, N·s/m, N·m·s/rad) at
    /// period `dt` (s): the body's mass and inertia, or the device's mass at its last reading.
    pub fn alpha_max(&self, dt: f64) -> V3 {
        match self {
            SlavePlant::Body(b) => {
                let body = &b.world.bodies[b.slave];
                [body.mass, body.mass, body.inertia].map(|m| 2.0 * m / dt)
            }
            SlavePlant::Device(d) => d.end.mass_diagonal().map(|m| 2.0 * m / dt),
        }
    }

    /// Why a slave device stopped, if it has (a body never does).
    pub fn stop(&self) -> Option<&SlaveStop> {
        match self {
            SlavePlant::Body(_) => None,
            SlavePlant::Device(d) => d.stop.as_ref(),
        }
    }

    /// Zero torques on a slave device (best effort; nothing on a body): the end of a session.
    pub fn zero(&mut self) {
        if let SlavePlant::Device(d) = self {
            d.io.io().zero_torques();
        }
    }
}

impl DeviceSlave {
    fn sense(&mut self, info: &TickInfo) -> Option<(V3, V3)> {
        let at = (info.deadline_index, info.t_s);
        let (q, wait) = self.io.read(info.t_s);
        self.read_wait_ns = (wait, self.read_wait_ns.0);
        let elapsed = self.interval.update(info) as f64 * 1e-9;
        let q = match q {
            Ok(q) => q,
            Err(e) => {
                self.lose(e);
                return None;
            }
        };
        let wait = self.read_wait_ns.1 as f64 * 1e-9;
        let timing = (elapsed, wait, info.period_s);
        self.est = self.io.sense(&mut self.end, at, &q, timing);
        let e = self.est?;
        let o = self.end.origin().unwrap_or(e.pose);
        let mask = |v: V3| -> V3 { std::array::from_fn(|i| if self.axes[i] { v[i] } else { 0.0 }) };
        Some((
            mask(std::array::from_fn(|i| e.pose[i] - o[i])),
            mask(e.velocity),
        ))
    }

    fn apply(&mut self, info: &TickInfo, f: &V3) -> Applied {
        let at = (info.deadline_index, info.t_s);
        let f: V3 = std::array::from_fn(|i| if self.axes[i] { f[i] } else { 0.0 });
        if matches!(self.stop, Some(SlaveStop::Lost(_))) {
            return Applied {
                force: [0.0; 3],
                rate: [0.0; 3],
                exact: false,
                wall: None,
            };
        }
        let out = self.end.actuate(at, self.est.as_ref(), &f);
        if let Err(e) = self.io.io().write_torques(&out.tau) {
            self.lose(e);
        } else if let (None, Some(trip)) = (&self.stop, self.end.trip_info()) {
            self.io.io().zero_torques();
            self.stop = Some(SlaveStop::Safety(trip));
        }
        Applied {
            force: out.applied,
            rate: self.est.map_or([0.0; 3], |e| e.velocity),
            exact: false,
            wall: None,
        }
    }

    fn lose(&mut self, e: DeviceError) {
        self.io.io().zero_torques();
        if self.stop.is_none() {
            self.stop = Some(SlaveStop::Lost(e));
        }
    }
}
