//! One device of `haptic2d teleop --live` (docs/TELEOP.md, "Two devices in real time"): its I/O
//! (the simulated twin on a [`SimIo`], or a real device from the registry), its [`DeviceEnd`]
//! (the tick's safety stage without a world) and its TDPA port. Per tick the live loop calls
//! [`LiveEnd::read`], [`LiveEnd::sense`], [`LiveEnd::drive`] and [`LiveEnd::write`]; none of them
//! allocates, locks or prints.
//!
//! `sim` is the simulated twin pantograph at the centre of its workspace: as the master, gripped
//! by the simulated hand (300 N/m, 5 N·s/m) whose target `--push` moves; as the slave, touching
//! the simulated environment, a one-sided wall ([`HandModel::Wall`], 2 000 N/m, 2 N·s/m) 5 mm
//! left of its start, as in the lab's teleop.

use std::path::Path;
use std::sync::Arc;

use haptic2d::control::tdpa::PlanarTdpa;
use haptic2d::device::linalg::{V3, V4};
use haptic2d::device::{DeviceEstimate, DeviceParams, HandModel};
use haptic2d::haptic::safety_stage::TickClock;
use haptic2d::haptic::{DeviceEnd, SafetyConfig};
use haptic2d_rt::{DeviceError, DeviceIo, SharedTarget, SimIo};

use crate::end_io::EndIo;
use crate::exit::Failure;
use crate::push_arg::Push;

/// The simulated slave's wall: its surface this far along x from the slave's start (m) …
pub const WALL_X: f64 = -0.005;
/// … its stiffness (N/m) …
pub const WALL_K: f64 = 2000.0;
/// … and damping (N·s/m): the lab's teleop wall.
pub const WALL_B: f64 = 2.0;

/// Which end of the link a device is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Gripped by the operator; feels the slave's contact.
    Master,
    /// Follows the master; touches the environment.
    Slave,
}

impl Role {
    /// `master` or `slave`, for messages.
    pub fn name(self) -> &'static str {
        match self {
            Role::Master => "master",
            Role::Slave => "slave",
        }
    }
}

/// One device of the live teleop (see the module doc).
pub struct LiveEnd {
    /// Master or slave.
    pub role: Role,
    /// The device as named on the command line, e.g. `sim`, `haply:/dev/pts/3`.
    pub name: String,
    /// For the start line: what the device is and where its settings came from.
    pub summary: String,
    io: EndIo,
    /// The device with its safety stage.
    pub end: DeviceEnd,
    /// Its TDPA port (books the force really applied against the rate of the measured pose).
    pub port: PlanarTdpa,
    /// The pose measured at the previous tick (m, m, rad; device frame).
    prev: Option<V3>,
    /// This tick's estimate (`None`: not sensed) and the rate of the measured pose (m/s, rad/s).
    est: Option<DeviceEstimate>,
    rate: V3,
    /// How long this tick's read waited for the device (ns; 0 for the simulated device).
    read_wait_ns: u64,
    /// This tick's torques (N·m; a point device: N), written by [`Self::write`].
    pub tau: V4,
    /// When (s, loop time) non-zero torques were last written, and when zero torques were first
    /// written on a stop (`None`: not yet; the loop's end zeroes again, unrecorded).
    pub last_torque_t: Option<f64>,
    pub zeroed_t: Option<f64>,
    /// The watchdog's limit of consecutive missed deadlines for this device (its device file's
    /// `max_missed_deadlines`; `None`: off, and for the simulated twin).
    pub max_missed_run: Option<u32>,
    /// Largest applied force `|(f_x, f_y)|` (N).
    pub max_force: f64,
    /// The handle's displacement from its origin at the last sensed tick (m, m, rad).
    pub displacement: V3,
    /// Largest distance of the handle from its origin (m).
    pub max_excursion: f64,
}

impl LiveEnd {
    /// Builds and opens the end `spec` (`sim`, `haply:PATH`, `udp:ADDR:PORT`, `inverse3[:URL]`) as
    /// `role` at period `dt` (s), with its device file `file` (a real device only), `allow_remote`
    /// for a UDP device beyond loopback, and `push` (the simulated master's hand). Errors name the
    /// end and say how to fix it.
    pub fn open(
        role: Role,
        spec: &str,
        file: Option<&Path>,
        allow_remote: bool,
        push: Option<Push>,
        dt: f64,
    ) -> Result<Self, Failure> {
        let named = |e: String| Failure::from(format!("--{} {spec}: {e}", role.name()));
        if spec == "sim" {
            if file.is_some() {
                return Err(named(format!(
                    "the simulated twin takes no device file\n    fix: leave out --{}-device-file",
                    role.name()
                )));
            }
            return Self::sim(role, push, dt).map_err(named);
        }
        if spec.starts_with("replay:") {
            return Err(named(
                "a replay cannot be teleoperated\n    fix: sim, haply:PATH, udp:ADDR:PORT or inverse3[:URL]".into(),
            ));
        }
        let r = crate::real_end::open(spec, file, allow_remote, dt).map_err(|f| Failure {
            message: format!("--{} {spec}: {}", role.name(), f.message),
            ..f
        })?;
        let (io, end, name, summary, missed) = (r.io, r.end, r.name, r.summary, r.max_missed_run);
        let mut e = Self::assemble(role, name, summary, EndIo::Real(io), end);
        e.max_missed_run = missed;
        Ok(e)
    }

    /// The simulated twin at the centre of its workspace: the master with the grip and `push`,
    /// the slave against the wall.
    fn sim(role: Role, push: Option<Push>, dt: f64) -> Result<Self, String> {
        let params = DeviceParams::default();
        let start = [params.workspace_center_x, params.workspace_center_y, 0.0];
        let hand = match role {
            Role::Master => HandModel::grip(start),
            Role::Slave => HandModel::Wall {
                surface: start[0] + WALL_X,
                stiffness: WALL_K,
                damping: WALL_B,
            },
        };
        let substeps = ((dt / 0.0005).ceil() as u32).max(1);
        let mut io = SimIo::new(&params, start, hand, dt, substeps)?;
        let push = match (role, push) {
            (Role::Master, Some(p)) => {
                let target = Arc::new(SharedTarget::new(start));
                io.follow(target.clone());
                Some((p, target, start))
            }
            _ => None,
        };
        let safety = SafetyConfig {
            min_stall_time: crate::run_rig::SIM_MIN_STALL_TIME,
            ..SafetyConfig::default()
        };
        let end = DeviceEnd::twin(params, safety, dt)?;
        let summary = match role {
            Role::Master => "simulated twin pantograph gripped by the simulated hand (300 N/m, 5 N·s/m)".to_string(),
            Role::Slave => format!(
                "simulated twin pantograph; a wall {:.0} mm to its left ({WALL_K} N/m, {WALL_B} N·s/m)",
                -WALL_X * 1e3
            ),
        };
        let io = EndIo::Sim { io, push };
        Ok(Self::assemble(role, "sim".into(), summary, io, end))
    }

    fn assemble(role: Role, name: String, summary: String, io: EndIo, end: DeviceEnd) -> Self {
        Self {
            role,
            name,
            summary,
            io,
            end,
            port: PlanarTdpa::default(),
            prev: None,
            est: None,
            rate: [0.0; 3],
            read_wait_ns: 0,
            tau: [0.0; 4],
            last_torque_t: None,
            zeroed_t: None,
            max_missed_run: None,
            max_force: 0.0,
            displacement: [0.0; 3],
            max_excursion: 0.0,
        }
    }

    /// An end on the device `io` with `end` (tests: a fake device).
    #[cfg(test)]
    pub(crate) fn with_io(role: Role, io: Box<dyn DeviceIo + Send>, end: DeviceEnd) -> Self {
        Self::assemble(role, "fake".into(), String::new(), EndIo::Real(io), end)
    }

    fn io(&mut self) -> &mut dyn DeviceIo {
        self.io.io()
    }

    /// Reads the device at time `t` (s; moves the simulated grip's target first), timing the read
    /// of a real device (the wait is the driver's, bounded by its own timeout: see
    /// [`Self::read_wait_ns`]).
    pub fn read(&mut self, t: f64) -> Result<V4, DeviceError> {
        let (q, wait) = self.io.read(t);
        self.read_wait_ns = wait;
        q
    }

    /// How long the last [`Self::read`] waited for the device (ns).
    pub fn read_wait_ns(&self) -> u64 {
        self.read_wait_ns
    }

    /// The device's sensing and input checks on the reading `q` ([`DeviceEnd::sense`]: `elapsed`
    /// s since the previous tick, `device_wait` s of it waiting for devices; the simulated twin
    /// checks the stall on them and senses over one period `dt`, as `run` does). `Some((x, v))`: the
    /// pose from the origin (m, m, rad) and the unfiltered rate of the measured pose over the
    /// period `dt`, `(x_k − x_{k−1})/T` (zero at the first reading), as the lab's teleop uses for
    /// its coupling and ports; `None` when the device could not be sensed (the latch holds why).
    pub fn sense(
        &mut self,
        at: TickClock,
        q: &V4,
        elapsed: f64,
        device_wait: f64,
        dt: f64,
    ) -> Option<(V3, V3)> {
        self.est = (self.io).sense(&mut self.end, at, q, (elapsed, device_wait, dt));
        let est = self.est?;
        let o = self.end.origin().unwrap_or(est.pose);
        let rate = self.prev.map_or([0.0; 3], |p| {
            std::array::from_fn(|i| (est.pose[i] - p[i]) / dt)
        });
        (self.prev, self.rate) = (Some(est.pose), rate);
        let x: V3 = std::array::from_fn(|i| est.pose[i] - o[i]);
        self.displacement = x;
        self.max_excursion = self.max_excursion.max(x[0].hypot(x[1]));
        Some((x, rate))
    }

    /// The port's passivity controller on `f_req` (N, N, N·m) against the far side's energy-in
    /// `far` (J; α capped at `2·m/T` from the device's mass diagonal) when `tdpa`, then the
    /// device's safety stage and torques ([`DeviceEnd::actuate`]); books the force really applied
    /// against the rate [`Self::sense`] gave (zero torque when this tick sensed nothing).
    /// Returns the applied wrench.
    pub fn drive(&mut self, at: TickClock, f_req: &V3, far: &V3, tdpa: bool, dt: f64) -> V3 {
        let v = if self.est.is_some() {
            self.rate
        } else {
            [0.0; 3]
        };
        let f = if tdpa {
            let m = self.end.mass_diagonal();
            let alpha_max = m.map(|mi| 2.0 * mi / dt);
            self.port.control(f_req, &v, far, dt, &alpha_max)
        } else {
            *f_req
        };
        let out = self.end.actuate(at, self.est.as_ref(), &f);
        self.tau = out.tau;
        if tdpa {
            self.port.book(&out.applied, &v, dt);
        } else {
            self.port.observe(&out.applied, &v, dt);
        }
        self.max_force = self.max_force.max(out.applied[0].hypot(out.applied[1]));
        out.applied
    }

    /// Writes this tick's torques at loop time `t` (s).
    pub fn write(&mut self, t: f64) -> Result<(), DeviceError> {
        let tau = self.tau;
        if tau.iter().any(|v| *v != 0.0) {
            self.last_torque_t = Some(t);
        }
        self.io().write_torques(&tau)
    }

    /// Zero torques at loop time `t` (s; `None`: after the loop), written now (a lost device:
    /// best effort) and latched in the device's `zero_torques`.
    pub fn zero(&mut self, t: Option<f64>) {
        self.tau = [0.0; 4];
        if self.zeroed_t.is_none() {
            self.zeroed_t = t;
        }
        let _ = self.io().write_torques(&[0.0; 4]);
        self.io().zero_torques();
    }

    /// The simulated slave's contact: the wall's force on the handle along x (N) and the
    /// penetration (m) at the plant's true state; `None` for a real device or the master.
    pub fn contact(&self) -> Option<(f64, f64)> {
        match (self.io.sim(), self.role) {
            (Some(io), Role::Slave) => {
                let (x, v) = (io.plant().pose(), io.plant().velocity());
                let f = io.hand().wrench(&x, &v, 0.0)[0];
                let pen = match io.hand() {
                    HandModel::Wall { surface, .. } => (surface - x[0]).max(0.0),
                    _ => 0.0,
                };
                Some((f, pen))
            }
            _ => None,
        }
    }
}
