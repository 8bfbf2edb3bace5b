//! The device registry: every real device `haptic2d run` (and any other front end) can drive, by
//! the name of `--device`, with its device file read and checked before anything is opened.
//!
//! # Adding a real device (the extension point)
//!
//! Every real device runs in the one loop of `haptic2d run` (real-time thread, watchdog, safety latch, CSV/MCAP
//! logs, signals and exit codes, the browser display). To add one, e.g. `--device udp:ADDR:PORT`:
//!
//! 1. a variant of [`DeviceChoice`] and its branch in [`DeviceChoice::parse`] (two lines);
//! 2. its arm in [`DeviceChoice::load_real`], calling a glue function in its own file
//!    ([`haply::real_device`], [`udp::real_device`], …) that reads and checks the device file
//!    **without opening anything** and returns a [`RealDevice`]:
//!    - its [`DeviceModel`]: [`DeviceModel::Twin`] (4 joints, MODELS §10, a [`DeviceParams`]),
//!      [`DeviceModel::FiveBar`] (2 joints: the linkage and the motor torque limit; the system is the
//!      2-DOF [`Planar2System`](haptic2d::haptic::planar2::Planar2System)) or
//!      [`DeviceModel::Point`] (a Cartesian device whose driver does its own kinematics: the
//!      handle point in, a force out; the system is the
//!      [`PointSystem`](haptic2d::haptic::PointSystem));
//!    - the device's own reply timeout (`wait_periods`, periods: a silent device is its driver's
//!      [`DeviceError::Lost`](haptic2d_rt::DeviceError::Lost) → exit 4), the watchdog's
//!      missed-deadline limit and the stall limit on the loop's own time;
//!    - optionally a `match_controller` that adapts the gains to the device;
//!    - an `open` closure that opens and hand-shakes the device at the control period and returns
//!      it as a [`DeviceIo`]; a 2-joint driver implements
//!      [`Device2Io`](haptic2d_rt::io::Device2Io) and is wrapped in
//!      [`Joints2`](haptic2d_rt::io::Joints2); a point driver implements [`DeviceIo`] with the
//!      point convention (`q = [x, y, 0, 0]` in m, `τ[0..2]` the force in N).
//!
//! The rig of `haptic2d run` does the rest: the stability gate with the hand released, zero torques
//! until the first valid reading and the start-up ramp of the shared safety stage, the stall check
//! on the loop's own time, the final clamp.

pub mod haply;
pub mod inverse3;
pub mod kinds;
pub mod udp;

use crate::device_safety::DeviceSafety;
use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::device::DeviceParams;
use haptic2d::haptic::{ControllerKind, DeviceEnd, SafetyConfig, WorkspaceSquare};
use haptic2d_rt::DeviceIo;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The device the loop drives.
#[derive(Clone, Debug, PartialEq)]
pub enum DeviceChoice {
    /// The simulated twin pantograph, pushed by the simulated hand.
    Sim,
    /// Recorded encoder angles `q1..q4` (rad) played back from a CSV file, or the encoders of an
    /// MCAP tick log (`.mcap`).
    Replay(PathBuf),
    /// A Haply board: the `PATH` of `haply:PATH`, or `auto` (device file: `--device-file`).
    Haply(String),
    /// A device on the open UDP protocol listening at the `ADDR:PORT` of `udp:ADDR:PORT`.
    Udp(String),
    /// A Haply Inverse3 through the Inverse Service at the `URL` of `inverse3:URL` (`None`: the
    /// device file's, default `http://localhost:10001`).
    Inverse3(Option<String>),
}

impl DeviceChoice {
    /// Parses `--device`: `sim`, `replay:FILE.csv|FILE.mcap` or `haply:PATH|haply:auto`; the error
    /// says how to fix it.
    pub fn parse(s: &str) -> Result<Self, String> {
        if s == "sim" {
            return Ok(DeviceChoice::Sim);
        }
        if let Some(f) = s.strip_prefix("replay:") {
            if f.is_empty() {
                return Err("--device replay:FILE.csv needs a file name".into());
            }
            return Ok(DeviceChoice::Replay(PathBuf::from(f)));
        }
        if let Some(p) = s.strip_prefix("haply:") {
            if p.is_empty() {
                return Err("--device haply: needs a port: haply:PATH (e.g. haply:/dev/ttyACM0) or haply:auto".into());
            }
            return Ok(DeviceChoice::Haply(p.to_string()));
        }
        if let Some(a) = s.strip_prefix("udp:") {
            return Ok(DeviceChoice::Udp(a.to_string()));
        }
        if s == "inverse3" {
            return Ok(DeviceChoice::Inverse3(None));
        }
        if let Some(u) = s.strip_prefix("inverse3:") {
            return Ok(DeviceChoice::Inverse3(Some(u.to_string())));
        }
        Err(format!(
            "--device `{s}` is not available\n    fix: use --device sim (the simulated twin pantograph), replay:FILE.csv, haply:PATH|haply:auto, udp:ADDR:PORT or inverse3[:URL]"
        ))
    }

    /// True for a device that moves a person's hand (anything but the simulation and a replay).
    pub fn is_real(&self) -> bool {
        !matches!(self, DeviceChoice::Sim | DeviceChoice::Replay(_))
    }

    /// For a real device, reads and checks its device file `device_file` (nothing is opened yet);
    /// `None` for the simulated device and a replay. Errors name the file, the field and the fix.
    /// `allow_remote` (`--allow-remote-device`) lets a UDP device be beyond loopback.
    pub fn load_real(
        &self,
        device_file: Option<&Path>,
        allow_remote: bool,
    ) -> Result<Option<RealDevice>, String> {
        Ok(match self {
            DeviceChoice::Sim | DeviceChoice::Replay(_) => None,
            DeviceChoice::Haply(port) => Some(haply::real_device(port, device_file)?),
            DeviceChoice::Udp(addr) => Some(udp::real_device(addr, device_file, allow_remote)?),
            DeviceChoice::Inverse3(url) => {
                Some(inverse3::real_device(url.as_deref(), device_file)?)
            }
        })
    }
}

/// What the haptic system needs to know of a real device.
#[derive(Clone, Debug, PartialEq)]
pub enum DeviceModel {
    /// A twin pantograph (4 joints `q11, q12, q21, q22`; MODELS §10) with these parameters.
    Twin(DeviceParams),
    /// A 2-DOF five-bar (joints `q1, q2` in `q[0..2]`) with this linkage (m) and motor torque limit
    /// `tau_max` (N·m, both motors).
    FiveBar {
        /// The linkage (m).
        linkage: Pantograph2,
        /// Motor torque limit (N·m).
        tau_max: f64,
        /// Centre of the workspace (m, the linkage's frame): where the stability gate linearises.
        center: [f64; 2],
        /// The workspace square of the device file (m, the linkage's frame) with its wall and
        /// trip: the bound the 2-DOF tick applies, as the twin's from its parameters.
        workspace: WorkspaceSquare,
        /// The dynamics `haptic2d device identify` measured (the device file's `[identified]`),
        /// used by the stability gate in place of the built-in estimates; `None`: not measured.
        identified: Option<crate::haply::identified::Identified>,
    },
    /// A Cartesian point device (the handle point `(x, y)` in `q[0..2]`, m; the force `(f_x, f_y)`
    /// in `τ[0..2]`, N): no linkage to model, `J = I` (the Haply Inverse3 in planar mode).
    Point {
        /// Force limit on `|(f_x, f_y)|` (N).
        force_limit: f64,
        /// The workspace square of the device file (m, the device's plane coordinates) with its
        /// wall and trip: the bound the point system applies.
        workspace: WorkspaceSquare,
        /// The handle's apparent mass (kg) and viscous damping (N·s/m) per axis that the stability
        /// gate linearises with (estimates unless the device file says otherwise).
        gate_dynamics: PointDynamics,
    },
}

impl DeviceModel {
    /// The twin's parameters; the defaults for a five-bar or a point device (whose systems do not
    /// use them: the run's `HapticConfig::device` then only carries the defaults).
    pub fn twin_params(&self) -> DeviceParams {
        match self {
            DeviceModel::Twin(p) => *p,
            DeviceModel::FiveBar { .. } | DeviceModel::Point { .. } => DeviceParams::default(),
        }
    }
}

/// The lumped dynamics of a point device's handle along each plane axis, as the stability gate of
/// `haptic2d run` sees them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointDynamics {
    /// Apparent moving mass (kg), > 0.
    pub mass: f64,
    /// Viscous damping (N·s/m), ≥ 0.
    pub damping: f64,
}

/// Opens a real device at the control period: handshake done, ready for the first tick.
pub type OpenDevice = Box<dyn FnOnce(Duration) -> Result<Box<dyn DeviceIo + Send>, String> + Send>;

/// A real device whose device file has been read and checked, not yet opened.
pub struct RealDevice {
    /// Name in messages, e.g. `haply:/dev/ttyACM0`.
    pub name: String,
    /// Its model.
    pub model: DeviceModel,
    /// For the start line: where the parameters came from, the kind, the limits.
    pub summary: String,
    /// The longest the driver waits for the device in one read before it reports it lost
    /// (periods). The stall check leaves this wait to the driver (see `Rig::tick_system` in haptic2d-cli).
    pub wait_periods: f64,
    /// The watchdog's limit of consecutive missed deadlines (`None`: off).
    pub max_missed_run: Option<u32>,
    /// The loop's own delay between two ticks that trips the stall check (periods, ≥ 1; the shared
    /// safety layer's default is 5).
    pub max_stall_periods: f64,
    /// The device file's `[safety]` table: plausibility bounds and the stall floor.
    pub safety: DeviceSafety,
    /// Matches the controller to the device (e.g. the Haply twin's θ gains to its crank); `None`
    /// keeps the controller as chosen.
    pub match_controller: Option<MatchController>,
    /// Opens it.
    pub open: OpenDevice,
}

/// Adjusts a controller's gains to a device.
pub type MatchController = Box<dyn Fn(ControllerKind) -> ControllerKind + Send>;

impl std::fmt::Debug for RealDevice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RealDevice")
            .field("name", &self.name)
            .field("model", &self.model)
            .field("summary", &self.summary)
            .field("wait_periods", &self.wait_periods)
            .field("max_missed_run", &self.max_missed_run)
            .field("max_stall_periods", &self.max_stall_periods)
            .field("safety", &self.safety)
            .finish_non_exhaustive()
    }
}

impl RealDevice {
    /// The safety settings of this device's tick: the shared defaults with the device file's
    /// `[safety]` table, and a stall limit of the loop's allowance plus the device's own reply
    /// timeout (the interval a tick sees includes the wait for the device; see `haptic2d run`'s
    /// rig).
    pub fn safety_config(&self) -> SafetyConfig {
        self.safety.apply(SafetyConfig {
            max_stall_periods: self.max_stall_periods + self.wait_periods,
            ..SafetyConfig::default()
        })
    }

    /// The device as a [`DeviceEnd`] at period `dt` (s): its model with [`Self::safety_config`].
    /// A five-bar's and a point device's handle mass (for a link's damping caps; the tick has no
    /// dynamic model of them) is the device file's identified end mass, else the built-in
    /// estimate of the 2DIY's end mass (the emulator's linkage), or the point device's gate mass.
    /// The five-bar's joint inertia, reflected to the handle, only adds to it: the value is a lower
    /// bound, which keeps a cap `2·m/T` on the stable side.
    pub fn device_end(&self, dt: f64) -> Result<DeviceEnd, String> {
        let safety = self.safety_config();
        match &self.model {
            DeviceModel::Twin(p) => DeviceEnd::twin(*p, safety, dt),
            DeviceModel::FiveBar {
                linkage,
                tau_max,
                center,
                workspace,
                identified,
            } => {
                let mass = match identified {
                    Some(i) if i.end_mass > 0.0 => i.end_mass,
                    _ => {
                        let c = haptic2d::geom::Vec2::new(center[0], center[1]);
                        crate::haply::plant::Plant2::new(*linkage, c)?.m_e
                    }
                };
                let margin = haptic2d::haptic::planar2::Planar2Config::new(*linkage, *tau_max)
                    .min_singularity_margin;
                let tau = [*tau_max; 2];
                DeviceEnd::five_bar(*linkage, tau, margin, *workspace, mass, safety, dt)
            }
            DeviceModel::Point {
                force_limit,
                workspace,
                gate_dynamics,
            } => DeviceEnd::point(*force_limit, *workspace, gate_dynamics.mass, safety, dt),
        }
    }
}
