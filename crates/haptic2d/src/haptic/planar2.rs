//! [`Planar2System`]: a 2-DOF device (a Haply 2DIY five-bar) in the 3-DOF world (issue 12 item 3).
//!
//! The device holds the slave body at a **grasp point** `r_g` (body frame, m; default the centre). The
//! controllers of §11 act on x and y only: the master pose is `(E_world, θ_s)` and its twist
//! `(Ė_world, ω_s)`, i.e. the θ channel always sees zero error, so the body's rotation is left to the
//! world (contacts turn it about the grasp point). The translational drive `f_cs` acts at the grasp
//! point, so the slave receives the force `f_cs` and the torque `(R·r_g) × f_cs` about its centre.
//!
//! The tick is the one of [`Haptic`] (`tick.rs`), the same as the twin pantograph's; this file
//! holds what a 2-DOF device does differently, as its [`GraspCoupling`]: the handle point `E(q)`
//! (θ = 0) mapped by a translation, θ and ω taken from the slave, the singularity margin checked at
//! the reading (step 2b), `f_cm` and `f_cs` on x and y only, and the drive at the grasp point.
//!
//! **Twist target** (the display's wheel / Q–E): a 2-DOF device cannot turn the body, so the page
//! may set a target angle `θ_t` for a virtual torsion spring-damper on the slave,
//! `τ_t = K_t·(θ_t − θ) − B_t·ω`, world side only (no motor torque). It is sized from the slave's
//! inertia `I` as a critically damped 5 Hz mode, `K_t = I·ω_n²`, `B_t = 2·I·ω_n` (`ω_n = 2π·5`
//! rad/s): its explicit damping number `B_t·T/I = 2·ω_n·T` is 0.063 at 1 kHz, far below the
//! semi-implicit limit of 2. With a fixed target it is a passive spring-damper (its stored energy
//! `½·K_t·(θ_t − θ)²` plus the body's kinetic energy never rises); moving the target is work done by
//! the page, which the ledger books as applied work like any drive. Off (`None`) until the page sets
//! a target; dropped while the safety latch holds.
//!
//! There is no hand-wrench observer on a 2DIY (no model of its dynamics): `f_h = 0` is given to the
//! controller, so the four-channel controller runs without its C2 channel. The device↔world mapping is
//! a translation set at the **first measured handle position** (the slave starts aligned with the
//! handle wherever the user holds it). Never allocates, locks or does I/O in [`Planar2System::tick`].
//!
//! The record keeps the 2-DOF conventions: `x_m` is the handle point in world coordinates (θ the
//! slave's; NaN without a reading), `v_m` its velocity (zero while paused), `w_h` zero,
//! `closure_error` 0, `v_s` the slave's twist after the step, and `f_cm` zero when the gate zeroed the
//! torques.

use crate::control::four_channel::TeleopSignals;
use crate::device::linalg::{M3, V3};
use crate::device::pantograph2::Pantograph2;
use crate::device::{CartesianDevice, DeviceEstimate, Pantograph2Device};
use crate::geom::{cross, perp, Vec2};
use crate::world::World;

use super::config::{find_slave, ControllerKind};
use super::controller::Controller;
use super::coupling::{DeviceCoupling, SlaveState};
use super::record::TickRecord;
use super::safety::{Safety, SafetyConfig};
use super::safety_stage::SafetyStage;
use super::tick::{Haptic, TickOutput};
use super::workspace::{WorkspaceBound, WorkspaceSquare};

/// Natural frequency of the twist target's torsion spring on the slave (Hz), critically damped.
pub const TWIST_TARGET_HZ: f64 = 5.0;

/// Settings of a [`Planar2System`].
#[derive(Clone, Debug, PartialEq)]
pub struct Planar2Config {
    /// The linkage (m).
    pub linkage: Pantograph2,
    /// Motor torque limits `(τ_1, τ_2)` (N·m), each > 0.
    pub tau_max: [f64; 2],
    /// Teleoperation controller (§11), acting on x and y.
    pub controller: ControllerKind,
    /// Name of the slave body; `None` = the first dynamic body.
    pub slave: Option<String>,
    /// Grasp point in the slave's body frame (m). Default `(0, 0)`, the centre.
    pub grasp: [f64; 2],
    /// Velocity low-pass cut-off (Hz), §10.7. Default 50.
    pub velocity_cutoff_hz: f64,
    /// The shared safety settings (§ DESIGN 7, [`SafetyConfig`]): the start-up ramp (torques scale
    /// by `min(1, n·T / ramp_time)` at the `n`-th tick after the first valid reading, so the first
    /// tick's torques are exactly zero), the stall limit and the torque trip margin — the same
    /// layer and the same defaults as the twin pantograph's [`HapticSystem`](super::HapticSystem).
    pub safety: SafetyConfig,
    /// Trip below this singularity margin (dimensionless `|sin|` of the distal links). Default 0.1.
    pub min_singularity_margin: f64,
    /// Keep the scene's loads on the slave body. Default false (the hand drives it).
    pub keep_slave_loads: bool,
    /// The workspace square of the device file (device frame) with its wall and trip, the same
    /// bound as the twin pantograph's ([`WorkspaceBound`], applied by the shared [`SafetyStage`]).
    /// Every 2-DOF system has one: [`Self::new`] gives the linkage's reach square
    /// ([`WorkspaceSquare::five_bar`]); a device file's `[workspace]` (the 2DIY's, the Inverse3's)
    /// replaces it.
    pub workspace: WorkspaceSquare,
}

impl Planar2Config {
    /// A configuration for `linkage` with torque limit `tau_max` (N·m) on both motors and the
    /// defaults above.
    pub fn new(linkage: Pantograph2, tau_max: f64) -> Self {
        Self {
            linkage,
            tau_max: [tau_max; 2],
            controller: ControllerKind::default(),
            slave: None,
            grasp: [0.0; 2],
            velocity_cutoff_hz: 50.0,
            safety: SafetyConfig::default(),
            min_singularity_margin: 0.1,
            keep_slave_loads: false,
            workspace: WorkspaceSquare::five_bar(&linkage),
        }
    }
}

/// What one 2-DOF tick hands back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Planar2Output {
    /// Motor torques `(τ_1, τ_2)` (N·m) to write now; zero when latched.
    pub torques: [f64; 2],
    /// True when the safety latch is set.
    pub tripped: bool,
    /// The tick's record (`tau[2..4]` zero; `x_m` the handle point in world coordinates).
    pub record: TickRecord,
}

/// A 2-DOF device coupled to the slave body of a world: `Haptic<GraspCoupling>`, the one tick of
/// [`Haptic`] over a five-bar held at a grasp point.
pub type Planar2System = Haptic<GraspCoupling>;

/// A 2-DOF device as the tick drives it (see the module doc): the device `D` (the five-bar
/// [`Pantograph2Device`], or the pass-through [`PointDevice`](crate::device::PointDevice)), the
/// translation from the device to the world (anchored at the first reading), the grasp point, the
/// twist target, and the system's settings `S` as given.
#[derive(Clone, Debug)]
pub struct GraspCoupling<D = Pantograph2Device, S = Planar2Config> {
    pub(super) settings: S,
    /// Grasp point in the slave's body frame (m).
    grasp: [f64; 2],
    /// The device at the Cartesian boundary: handle point, filtered velocity, `τ = Jᵀ·f`.
    device: D,
    /// World point of the grasp at start (m): the first handle position maps here.
    world_origin: Vec2,
    device_origin: Option<Vec2>,
    /// The page's twist target `θ_t` (rad), `None` = off (see the module doc).
    twist_target: Option<f64>,
    /// Torsion stiffness `K_t` (N·m/rad) and damping `B_t` (N·m·s/rad) of the twist target.
    twist_gains: (f64, f64),
}

impl<D, S> GraspCoupling<D, S> {
    /// The handle point of reading `e` in world coordinates (m): `E − E_0 + G_0`, with `E_0` the
    /// anchored handle point (this one before the anchor) and `G_0` the grasp point at the anchor.
    fn handle_world(&self, e: &DeviceEstimate) -> Vec2 {
        let point = Vec2::new(e.pose[0], e.pose[1]);
        let origin = self.device_origin.unwrap_or(point);
        point - origin + self.world_origin
    }
}

impl<D: CartesianDevice<Joints = [f64; 2]>, S> DeviceCoupling for GraspCoupling<D, S> {
    type Device = D;
    const MARGIN_AT_SENSE: bool = true;

    fn device(&self) -> &D {
        &self.device
    }
    fn device_mut(&mut self) -> &mut D {
        &mut self.device
    }

    /// Anchors the translation: the handle point maps onto the grasp point found at the last
    /// [`Self::unalign`] (or at construction).
    fn align(&mut self, e: &DeviceEstimate, _world: &World, _slave: usize) -> bool {
        if self.device_origin.is_some() {
            return false;
        }
        self.device_origin = Some(Vec2::new(e.pose[0], e.pose[1]));
        true
    }

    fn unalign(&mut self, world: &World, slave: usize) {
        self.device_origin = None;
        self.world_origin = grasp_world(world, slave, self.grasp);
    }

    /// The slave held at the grasp point: its position `c + R·r_g` and velocity `v + ω × R·r_g`.
    fn slave_state(&self, world: &World, i: usize) -> SlaveState {
        let mut s = SlaveState::at_centre(world, i);
        let body = &world.bodies[i];
        let (c, theta, omega) = (body.pose.pos, body.pose.angle, body.omega);
        let r = rotate(theta, self.grasp);
        let (pg, vg) = (c + r, body.vel + omega * perp(r));
        s.x_s = [pg.x, pg.y, theta];
        s.v_s = [vg.x, vg.y, omega];
        s.r = r;
        s
    }

    /// x and y of the handle point against the grasp point; the θ channel sees no error (the
    /// handle's θ and ω are the slave's), no hand-wrench estimate, no environment torque.
    fn teleop_signals(&self, e: &DeviceEstimate, s: &SlaveState, _m_dev: &M3) -> TeleopSignals {
        let p = self.handle_world(e);
        TeleopSignals {
            x_m: [p.x, p.y, s.x_s[2]],
            v_m: [e.velocity[0], e.velocity[1], s.v_s[2]],
            f_h: [0.0; 3],
            x_s: s.x_s,
            v_s: s.v_s,
            f_e: [s.f_e[0], s.f_e[1], 0.0],
            master_mass: self.device.mass_matrix(),
        }
    }

    /// No motor turns the handle: the moment is dropped.
    fn constrain(&self, f: &mut V3) {
        f[2] = 0.0;
    }

    /// The map is a translation: wrenches are the same in both frames.
    fn wrench_to_device(&self, f: &V3) -> V3 {
        *f
    }
    fn wrench_to_world(&self, f: &V3) -> V3 {
        *f
    }

    /// The force at the grasp point gives the torque `(R·r_g) × f` about the centre, plus the twist
    /// target's torsion spring-damper (world side only; dropped while latched).
    fn drive(&self, f_cs: &V3, s: &SlaveState, latched: bool) -> (Vec2, f64) {
        let f = Vec2::new(f_cs[0], f_cs[1]);
        let twist = match self.twist_target {
            Some(th) if !latched => {
                let (k, b) = self.twist_gains;
                k * (th - s.centre[2]) - b * s.centre_twist[2]
            }
            _ => 0.0,
        };
        (f, cross(s.r, f) + twist)
    }

    fn record(
        &self,
        rec: &mut TickRecord,
        est: Option<&DeviceEstimate>,
        world: &World,
        slave: usize,
        paused: bool,
        gated: bool,
    ) {
        let (theta, omega) = (rec.x_s[2], rec.v_s[2]);
        rec.x_m = est.map_or([f64::NAN, f64::NAN, theta], |e| {
            let p = self.handle_world(e);
            [p.x, p.y, theta]
        });
        rec.v_m = match (paused, est) {
            (true, _) => [0.0; 3],
            (false, Some(e)) => [e.velocity[0], e.velocity[1], omega],
            (false, None) => [0.0, 0.0, omega],
        };
        rec.w_h = [0.0; 3];
        rec.closure_error = 0.0;
        let body = &world.bodies[slave];
        rec.v_s = [body.vel.x, body.vel.y, body.omega];
        if gated {
            rec.f_cm = [0.0; 3];
        }
    }
}

/// The settings every 2-DOF system shares, whatever its device: the controller, the slave and the
/// grasp point, the velocity filter, the safety settings and the workspace square (the fields of
/// [`Planar2Config`] of the same names).
#[derive(Clone, Debug, PartialEq)]
pub struct GraspConfig {
    /// Teleoperation controller (§11), acting on x and y.
    pub controller: ControllerKind,
    /// Name of the slave body; `None` = the first dynamic body.
    pub slave: Option<String>,
    /// Grasp point in the slave's body frame (m). Default `(0, 0)`, the centre.
    pub grasp: [f64; 2],
    /// Velocity low-pass cut-off (Hz), §10.7. Default 50.
    pub velocity_cutoff_hz: f64,
    /// The shared safety settings ([`SafetyConfig`]): ramp, stall limit, trip margin.
    pub safety: SafetyConfig,
    /// Keep the scene's loads on the slave body. Default false (the hand drives it).
    pub keep_slave_loads: bool,
    /// The workspace square of the device file (device frame, m) with its wall and trip.
    pub workspace: WorkspaceSquare,
}

impl GraspConfig {
    /// The defaults above around the workspace square `workspace`.
    pub fn new(workspace: WorkspaceSquare) -> Self {
        Self {
            controller: ControllerKind::default(),
            slave: None,
            grasp: [0.0; 2],
            velocity_cutoff_hz: 50.0,
            safety: SafetyConfig::default(),
            keep_slave_loads: false,
            workspace,
        }
    }
}

impl From<&Planar2Config> for GraspConfig {
    fn from(c: &Planar2Config) -> Self {
        Self {
            controller: c.controller,
            slave: c.slave.clone(),
            grasp: c.grasp,
            velocity_cutoff_hz: c.velocity_cutoff_hz,
            safety: c.safety,
            keep_slave_loads: c.keep_slave_loads,
            workspace: c.workspace,
        }
    }
}

/// A 2-DOF system around `world` for the device `device(dt)` held at a grasp point with the shared
/// settings `p`, the singularity limit `min_margin` (the device's own measure) and the final gate's
/// limit `gate_limit` (N·m, or N on a point device); `settings` is kept as given. Errors name the
/// setting.
pub(super) fn grasp_system<D, S>(
    mut world: World,
    device: impl FnOnce(f64) -> D,
    settings: S,
    p: &GraspConfig,
    (min_margin, gate_limit): (f64, f64),
) -> Result<Haptic<GraspCoupling<D, S>>, String>
where
    D: CartesianDevice<Joints = [f64; 2]>,
{
    let dt = world.params.dt;
    if !p.grasp.iter().all(|v| v.is_finite()) {
        return Err(format!("grasp = {:?} m: must be finite", p.grasp));
    }
    if !(p.velocity_cutoff_hz.is_finite() && p.velocity_cutoff_hz > 0.0) {
        return Err("velocity_cutoff_hz must be > 0 Hz (default 50)".into());
    }
    p.safety.validate()?;
    p.workspace.validate()?;
    let slave = find_slave(&world, p.slave.as_deref())?;
    let body = &world.bodies[slave];
    let controller = Controller::build(p.controller, &world, slave, dt)?;
    let world_origin = grasp_world(&world, slave, p.grasp);
    let wn = 2.0 * std::f64::consts::PI * TWIST_TARGET_HZ;
    let twist_gains = (body.inertia * wn * wn, 2.0 * body.inertia * wn);
    if !p.keep_slave_loads {
        world.loads.retain(|l| l.body != slave);
    }
    let safety = SafetyStage::new(
        p.safety,
        Safety::new(min_margin, gate_limit, p.safety.torque_trip_margin),
        WorkspaceBound::of_square(&p.workspace, dt),
        dt,
    );
    let coupling = GraspCoupling {
        settings,
        grasp: p.grasp,
        device: device(dt),
        world_origin,
        device_origin: None,
        twist_target: None,
        twist_gains,
    };
    Ok(Haptic::assemble(
        coupling, controller, None, world, slave, safety,
    ))
}

impl Planar2System {
    /// Builds the system around `world` (its period is the tick period). Errors name the setting.
    pub fn new(world: World, config: Planar2Config) -> Result<Self, String> {
        for (i, t) in config.tau_max.iter().enumerate() {
            if !(t.is_finite() && *t > 0.0) {
                return Err(format!(
                    "tau_max[{i}] = {t} N·m: must be a finite number > 0"
                ));
            }
        }
        // The final gate clamps to the smaller motor limit (the saturation already scales each
        // motor to its own) and trips above it by the default margin.
        let gate_limit = config.tau_max[0].min(config.tau_max[1]);
        let (linkage, tau_max) = (config.linkage, config.tau_max);
        let (min_margin, cutoff) = (config.min_singularity_margin, config.velocity_cutoff_hz);
        let device = |dt| Pantograph2Device::new(linkage, tau_max, min_margin, cutoff, dt);
        let common = GraspConfig::from(&config);
        grasp_system(world, device, config, &common, (min_margin, gate_limit))
    }
}

/// The settings a 2-DOF system keeps ([`Planar2Config`], [`PointConfig`](super::PointConfig)): the
/// controller they name follows [`Haptic::set_controller`].
pub trait GraspSettings {
    /// The teleoperation controller of the settings.
    fn controller_mut(&mut self) -> &mut ControllerKind;
}

impl GraspSettings for Planar2Config {
    fn controller_mut(&mut self) -> &mut ControllerKind {
        &mut self.controller
    }
}

impl<D: CartesianDevice<Joints = [f64; 2]>, S: GraspSettings> Haptic<GraspCoupling<D, S>> {
    /// Switches the teleoperation controller to `kind` from its reset state; the gains are checked
    /// against the slave's mass as when built, and on error the running controller is kept.
    pub fn set_controller(&mut self, kind: ControllerKind) -> Result<(), String> {
        self.controller = Controller::build(kind, &self.world, self.slave, self.dt)?;
        *self.coupling.settings.controller_mut() = kind;
        Ok(())
    }

    /// The configuration.
    pub fn config(&self) -> &S {
        &self.coupling.settings
    }
    /// Sets the twist target `θ_t` (rad, unwrapped like the body's angle), or turns it off (`None`);
    /// a non-finite angle turns it off.
    pub fn set_twist_target(&mut self, theta: Option<f64>) {
        self.coupling.twist_target = theta.filter(|t| t.is_finite());
    }

    /// The twist target (rad), `None` when off.
    pub fn twist_target(&self) -> Option<f64> {
        self.coupling.twist_target
    }

    /// Torsion stiffness `K_t` (N·m/rad) and damping `B_t` (N·m·s/rad) of the twist target.
    pub fn twist_gains(&self) -> (f64, f64) {
        self.coupling.twist_gains
    }

    /// One sample taken on time (one period after the previous one): see [`Self::tick_elapsed`].
    pub fn tick(&mut self, q: &[f64; 2]) -> Planar2Output {
        self.tick_elapsed(q, self.dt)
    }

    /// One sample from the motor angles `q` (rad) to the motor torques (N·m), `elapsed` seconds
    /// after the previous tick (the loop's own interval, measured by the caller). A tick later than the
    /// stall limit ([`SafetyConfig::stall_limit`]) trips the latch with
    /// [`SafetyReason::Stall`](super::SafetyReason::Stall) in this same tick (the device held its
    /// last torques unsupervised for that long); a NaN interval counts as a stall. The device's
    /// velocity filter differentiates over the measured interval (as the twin's does); the world
    /// steps by the fixed period `T`.
    pub fn tick_elapsed(&mut self, q: &[f64; 2], elapsed: f64) -> Planar2Output {
        self.tick_timed(q, elapsed, f64::NAN)
    }

    /// [`Self::tick_elapsed`] with the part of `elapsed` the loop spent waiting for the device's
    /// reply, `device_wait` (s; NaN = unknown): [`Haptic::haptic_tick`]. Never allocates.
    pub fn tick_timed(&mut self, q: &[f64; 2], elapsed: f64, device_wait: f64) -> Planar2Output {
        narrow(self.haptic_tick(q, elapsed, device_wait))
    }

    /// The start-up ramp factor of the next tick, `min(1, n / N)` with `n` the ticks since the first
    /// valid reading (exactly 0 before and at it), `N = round(ramp_time / T)`; 1 without a ramp.
    #[inline]
    pub fn ramp(&self) -> f64 {
        self.safety.ramp()
    }

    /// A paused sample ([`Haptic::haptic_tick_paused`]): the handle is still read (its filter keeps
    /// tracking), no controller runs, the world stands still and the torques are zero; the next
    /// running tick re-anchors the device↔world translation at the handle and ramps the torques in
    /// again from zero. Never allocates.
    pub fn tick_paused(&mut self, q: &[f64; 2]) -> Planar2Output {
        narrow(self.haptic_tick_paused(q))
    }

    /// Handle position (m, board frame) that maps to the slave's grasp point at start, once measured.
    pub fn device_origin(&self) -> Option<Vec2> {
        self.coupling.device_origin
    }
    /// World point of the grasp at start (m).
    pub fn world_origin(&self) -> Vec2 {
        self.coupling.world_origin
    }
}

/// A tick's output in the 2-DOF shape: the two motor torques.
#[inline]
fn narrow(o: TickOutput) -> Planar2Output {
    Planar2Output {
        torques: [o.torques[0], o.torques[1]],
        tripped: o.tripped,
        record: o.record,
    }
}

/// `R(θ)·r` (m).
#[inline]
fn rotate(theta: f64, r: [f64; 2]) -> Vec2 {
    let (s, c) = theta.sin_cos();
    Vec2::new(c * r[0] - s * r[1], s * r[0] + c * r[1])
}

/// The grasp point of body `i` in world coordinates (m).
fn grasp_world(world: &World, i: usize, grasp: [f64; 2]) -> Vec2 {
    let b = &world.bodies[i];
    b.pose.pos + rotate(b.pose.angle, grasp)
}
