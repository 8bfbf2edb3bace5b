//! [`Planar2System`]: a 2-DOF device (a Haply 2DIY five-bar) in the 3-DOF world (issue 12 item 3).
//!
//! The device holds the slave body at a **grasp point** `r_g` (body frame, m; default the centre). The
//! controllers of §11 act on x and y only: the master pose is `(E_world, θ_s)` and its twist
//! `(Ė_world, ω_s)`, i.e. the θ channel always sees zero error, so the body's rotation is left to the
//! world (contacts turn it about the grasp point). The translational drive `f_cs` acts at the grasp
//! point, so the slave receives the force `f_cs` and the torque `(R·r_g) × f_cs` about its centre.
//!
//! One tick, in the order of §0.5:
//!
//! ```text
//! 1–2. q (rad) → E, J, margin (five-bar)           ⇒ handle point, filtered velocity
//! 3–6. world.begin_step                              ⇒ slave pose, contact wrench
//! 7.   controller on (x, y) of the grasp point      ⇒ f_cm (device), f_cs (slave)
//! 8b.  workspace bound (wall, trip) at the handle    ⇒ f_cm += wall
//! 9.   τ = Jᵀ f_cm, direction-preserving saturation, start-up ramp, safety gate
//! 10.  f_cs at the grasp point, world.finish_step
//! 11.  record
//! ```
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

use crate::device::pantograph2::Pantograph2;
use crate::device::{CartesianDevice, DeviceFault, Pantograph2Device};
use crate::geom::Vec2;
use crate::world::World;

use super::config::{find_slave, ControllerKind};
use super::controller::Controller;
use super::record::{TickRecord, FLAG_SAFETY};
use super::safety::{Safety, SafetyConfig, SafetyReason, SafetyTrip};
use super::safety_stage::SafetyStage;
use super::workspace::{WorkspaceBound, WorkspaceSquare};

mod steps;

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

/// A 2-DOF device coupled to the slave body of a world.
#[derive(Clone, Debug)]
pub struct Planar2System {
    config: Planar2Config,
    controller: Controller,
    world: World,
    slave: usize,
    /// The five-bar at the Cartesian boundary: handle point, filtered velocity, `τ = Jᵀ·f`.
    device: Pantograph2Device,
    /// The shared safety steps: stall, plausibility, workspace bound, limit cycle, ramp, gate.
    safety: SafetyStage,
    /// World point of the grasp at start (m): the first handle position maps here.
    world_origin: Vec2,
    device_origin: Option<Vec2>,
    /// The page's twist target `θ_t` (rad), `None` = off (see the module doc).
    twist_target: Option<f64>,
    /// Torsion stiffness `K_t` (N·m/rad) and damping `B_t` (N·m·s/rad) of the twist target.
    twist_gains: (f64, f64),
    dt: f64,
    record: TickRecord,
}

impl Planar2System {
    /// Builds the system around `world` (its period is the tick period). Errors name the setting.
    pub fn new(mut world: World, config: Planar2Config) -> Result<Self, String> {
        let dt = world.params.dt;
        for (i, t) in config.tau_max.iter().enumerate() {
            if !(t.is_finite() && *t > 0.0) {
                return Err(format!(
                    "tau_max[{i}] = {t} N·m: must be a finite number > 0"
                ));
            }
        }
        if !config.grasp.iter().all(|v| v.is_finite()) {
            return Err(format!("grasp = {:?} m: must be finite", config.grasp));
        }
        if !(config.velocity_cutoff_hz.is_finite() && config.velocity_cutoff_hz > 0.0) {
            return Err("velocity_cutoff_hz must be > 0 Hz (default 50)".into());
        }
        config.safety.validate()?;
        config.workspace.validate()?;
        let slave = find_slave(&world, config.slave.as_deref())?;
        let body = &world.bodies[slave];
        let controller = Controller::build(config.controller, &world, slave, dt)?;
        let world_origin = grasp_world(&world, slave, config.grasp);
        let wn = 2.0 * std::f64::consts::PI * TWIST_TARGET_HZ;
        let twist_gains = (body.inertia * wn * wn, 2.0 * body.inertia * wn);
        if !config.keep_slave_loads {
            world.loads.retain(|l| l.body != slave);
        }
        Ok(Self {
            device: Pantograph2Device::new(
                config.linkage,
                config.tau_max,
                config.min_singularity_margin,
                config.velocity_cutoff_hz,
                dt,
            ),
            // The final gate clamps to the smaller motor limit (the saturation above already scales
            // each motor to its own) and trips above it by the default margin.
            safety: SafetyStage::new(
                config.safety,
                Safety::new(
                    config.min_singularity_margin,
                    config.tau_max[0].min(config.tau_max[1]),
                    config.safety.torque_trip_margin,
                ),
                WorkspaceBound::of_square(&config.workspace, dt),
                dt,
            ),
            twist_target: None,
            twist_gains,
            config,
            controller,
            world,
            slave,
            world_origin,
            device_origin: None,
            dt,
            record: TickRecord::default(),
        })
    }

    /// Sets the twist target `θ_t` (rad, unwrapped like the body's angle), or turns it off (`None`);
    /// a non-finite angle turns it off.
    pub fn set_twist_target(&mut self, theta: Option<f64>) {
        self.twist_target = theta.filter(|t| t.is_finite());
    }

    /// The twist target (rad), `None` when off.
    pub fn twist_target(&self) -> Option<f64> {
        self.twist_target
    }

    /// Torsion stiffness `K_t` (N·m/rad) and damping `B_t` (N·m·s/rad) of the twist target.
    pub fn twist_gains(&self) -> (f64, f64) {
        self.twist_gains
    }

    /// One sample taken on time (one period after the previous one): see [`Self::tick_elapsed`].
    pub fn tick(&mut self, q: &[f64; 2]) -> Planar2Output {
        self.tick_elapsed(q, self.dt)
    }

    /// One sample from the motor angles `q` (rad) to the motor torques (N·m), `elapsed` seconds
    /// after the previous tick (the loop's own interval, measured by the caller). A tick later than the
    /// stall limit ([`SafetyConfig::stall_limit`]) trips the latch with [`SafetyReason::Stall`] in this
    /// same tick (the device held its last torques unsupervised for that long); a NaN interval
    /// counts as a stall. The device's velocity filter differentiates over the measured interval
    /// (as the twin's does); the world steps by the fixed period `T`.
    pub fn tick_elapsed(&mut self, q: &[f64; 2], elapsed: f64) -> Planar2Output {
        self.tick_timed(q, elapsed, f64::NAN)
    }

    /// [`Self::tick_elapsed`] with the part of `elapsed` the loop spent waiting for the device's
    /// reply, `device_wait` (s; NaN = unknown), so that a stall says whether the host or the device
    /// was late. Never allocates.
    pub fn tick_timed(&mut self, q: &[f64; 2], elapsed: f64, device_wait: f64) -> Planar2Output {
        let t = self.world.time();
        let mut flags = 0u32;
        self.supervise_input(q, elapsed, device_wait); // 0
        let mut handle = self.sense(q, elapsed, &mut flags); // 1–2
        let slave = self.contact_stage(); // 3–6
        handle.x_m[2] = slave.theta;
        handle.v_m[2] = slave.omega;
        let (mut f_cm, mut f_cs) = self.teleoperate(&handle, &slave); // 7
        self.workspace_wall(&handle, &mut f_cm); // 8b
        let (tau4, gated) = self.motor_torques(&handle, &f_cm, &mut flags); // 9
        if gated {
            f_cs = [0.0; 3];
            f_cm = [0.0; 3];
        }
        self.integrate(&f_cs, &slave); // 10
        self.record_tick(t, &handle, &slave, (f_cm, f_cs), tau4, flags); // 11
        Planar2Output {
            torques: [tau4[0], tau4[1]],
            tripped: self.safety.is_latched(),
            record: self.record,
        }
    }

    /// The start-up ramp factor of the next tick, `min(1, n / N)` with `n` the ticks since the first
    /// valid reading (exactly 0 before and at it), `N = round(ramp_time / T)`; 1 without a ramp.
    #[inline]
    pub fn ramp(&self) -> f64 {
        self.safety.ramp()
    }

    /// A paused sample: the handle is still read (its filter keeps tracking), no controller runs,
    /// the world stands still and the torques are zero; the next running tick re-anchors the
    /// device↔world translation at the handle and ramps the torques in again from zero. Never
    /// allocates.
    pub fn tick_paused(&mut self, q: &[f64; 2]) -> Planar2Output {
        let (k, t) = (self.world.tick(), self.world.time());
        self.safety.supervise_paused((k, t), q);
        let mut x_m = [f64::NAN; 3];
        let mut margin = f64::NAN;
        match self.device.sense(q, &[0.0; 4], self.dt) {
            Ok(e) => {
                let point = Vec2::new(e.pose[0], e.pose[1]);
                let origin = self.device_origin.unwrap_or(point);
                let p = point - origin + self.world_origin;
                x_m = [p.x, p.y, 0.0];
                margin = self.device.margin();
            }
            Err(f) => self.safety.trip((k, t), SafetyReason::Device(f)),
        }
        let mut tau4 = [0.0; 4];
        let mut flags = 0u32;
        if self.safety.gate((k, t), &mut tau4, false) {
            flags |= FLAG_SAFETY;
        }
        self.realign();
        let body = &self.world.bodies[self.slave];
        x_m[2] = body.pose.angle;
        let cw = self.world.contact_wrench(self.slave);
        let ledger = self.world.ledger();
        self.record = TickRecord {
            t,
            x_m,
            x_s: [body.pose.pos.x, body.pose.pos.y, body.pose.angle],
            v_s: [body.vel.x, body.vel.y, body.omega],
            f_e: [-cw.force.x, -cw.force.y, -cw.torque],
            contacts: self.world.contacts().contact_count() as u32,
            kinetic: ledger.kinetic,
            stored: ledger.stored,
            applied_work: ledger.applied_work,
            margin,
            flags,
            ..TickRecord::default()
        };
        Planar2Output {
            torques: [0.0; 2],
            tripped: self.safety.is_latched(),
            record: self.record,
        }
    }

    /// Forgets the alignment: the next running tick maps the measured handle point onto the slave's
    /// current grasp point and restarts the ramp and the stall clock.
    fn realign(&mut self) {
        self.device_origin = None;
        self.world_origin = grasp_world(&self.world, self.slave, self.config.grasp);
        self.safety.restart_ramp();
        self.safety.restart_clock();
    }

    /// Re-arms the safety latch (an explicit user action): the next tick re-aligns and ramps in from
    /// zero, as at start-up.
    pub fn reset_safety(&mut self) {
        self.safety.rearm();
        self.realign();
    }

    /// The stall check of [`Self::tick_elapsed`] on its own (see
    /// [`HapticSystem::check_stall`](super::HapticSystem::check_stall)): trips when `elapsed` (s;
    /// `device_wait` s of it waiting for the device, NaN = unknown) exceeds the stall limit `max(max_stall_periods·T, min_stall_time)`.
    /// Returns true when it tripped. Never allocates.
    pub fn check_stall(&mut self, elapsed: f64, device_wait: f64) -> bool {
        let at = (self.world.tick(), self.world.time());
        self.safety.check_stall(at, elapsed, device_wait)
    }

    /// The workspace bound the tick applies (every 2-DOF system has one).
    pub fn workspace(&self) -> &WorkspaceBound {
        self.safety.workspace()
    }

    /// Switches the teleoperation controller to `kind` from its reset state; the gains are checked
    /// against the slave's mass as in [`Self::new`], and on error the running controller is kept.
    pub fn set_controller(&mut self, kind: ControllerKind) -> Result<(), String> {
        self.controller = Controller::build(kind, &self.world, self.slave, self.dt)?;
        self.config.controller = kind;
        Ok(())
    }

    /// Mutable access to the world (e.g. to switch its laws between ticks).
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }

    /// The sample period `T` (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Latches the safety stop from outside (e.g. the device was lost): zero torques from now on.
    pub fn trip_device(&mut self, fault: DeviceFault) {
        let at = (self.world.tick(), self.world.time());
        self.safety.trip(at, SafetyReason::Device(fault));
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
    }
    /// Index of the slave body.
    pub fn slave(&self) -> usize {
        self.slave
    }
    /// The latched safety trip, if any.
    pub fn safety_trip(&self) -> Option<SafetyTrip> {
        self.safety.trip_info()
    }
    /// The record of the last tick.
    pub fn last_record(&self) -> &TickRecord {
        &self.record
    }
    /// The configuration.
    pub fn config(&self) -> &Planar2Config {
        &self.config
    }
    /// Handle position (m, board frame) that maps to the slave's grasp point at start, once measured.
    pub fn device_origin(&self) -> Option<Vec2> {
        self.device_origin
    }
    /// World point of the grasp at start (m).
    pub fn world_origin(&self) -> Vec2 {
        self.world_origin
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
