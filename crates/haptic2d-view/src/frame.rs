//! The `Frame` message: the state of the running world at one instant, sent to every viewer at about
//! 60 Hz.
//!
//! The haptic loop fills a preallocated [`Frame`] with [`Frame::capture`] (no allocation once the
//! vectors have their capacity: they are cleared and refilled, never rebuilt) and publishes it through
//! the triple buffer of [`ViewHub`](crate::ViewHub); the server thread serialises the latest one.
//!
//! Every position is in the **world** frame (m, rad). Device points are mapped from the device frame
//! with the translation `device_to_world` of [`FrameInputs`] (world = device + offset), the same
//! offset the [`SceneInfo`](crate::SceneInfo) reports.

use haptic2d::contact::ContactState;
use haptic2d::device::TwinKinematics;
use haptic2d::world::World;
use serde::Serialize;

/// Contacts listed per frame at most; the rest are only counted in [`Frame::contacts_total`].
pub const MAX_FRAME_CONTACTS: usize = 256;

/// One contact record (a vertex–edge pair in contact), as drawn by the page.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ContactView {
    /// Body owning the vertex (index into the scene's bodies).
    pub body_a: u32,
    /// Body owning the edge.
    pub body_b: u32,
    /// `"colliding"` (resolved by an impulse this sample) or `"continuous"`.
    pub state: &'static str,
    /// World position of the vertex `V` (m).
    pub point: [f64; 2],
    /// Outward unit normal of the edge (world).
    pub normal: [f64; 2],
    /// Unit tangent of the edge (world); the friction force on A acts along `+tangent·f_t`.
    pub tangent: [f64; 2],
    /// Signed distance of the vertex from the edge line (m), negative when penetrating.
    pub depth: f64,
    /// World position of the god-object on the edge (m).
    pub god_object: [f64; 2],
    /// Normal force of the last sample on A along `+normal` (N, ≥ 0).
    pub f_n: f64,
    /// Friction force of the last sample on A along `+tangent` (N).
    pub f_t: f64,
}

/// The twin-pantograph linkage at the current handle pose, in world coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct DeviceView {
    /// False when the pose could not be resolved (outside the reachable workspace): draw nothing.
    pub valid: bool,
    /// Handle pose `(x, y, θ)` in the world frame (m, m, rad): `P_1` plus the offset, and θ.
    pub handle: [f64; 3],
    /// Handle pose in the device frame (m, m, rad), as the encoders see it.
    pub handle_device: [f64; 3],
    /// Elbows `E_11, E_12, E_21, E_22` (m, world).
    pub elbows: [[f64; 2]; 4],
    /// Endpoints `P_1` (handle shaft) and `P_2` (crank pin) (m, world).
    pub endpoints: [[f64; 2]; 2],
}

/// Energy bookkeeping of the world (the world's ledger) plus the passivity observer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Energies {
    /// Kinetic energy of all dynamic bodies (J).
    pub kinetic: f64,
    /// Energy stored in contact and friction springs (J).
    pub stored: f64,
    /// Cumulative work of applied loads and drives (J).
    pub applied_work: f64,
    /// Kinetic energy removed by impacts so far (J).
    pub impact_loss: f64,
    /// Frictional impact sets whose energy check scaled an impulse so far (count).
    pub impact_energy_fallbacks: u64,
    /// `E_now − (E_0 + W_applied)` (J): positive means the simulation generated energy.
    pub excess: f64,
    /// Passivity-observer energy `E_obs` (J), when the loop runs one (§12).
    pub passivity: Option<f64>,
}

/// Live timing of the haptic loop over the last window (see [`LiveTiming`](crate::LiveTiming)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LoopTiming {
    /// Target rate (Hz).
    pub rate_hz: f64,
    /// Achieved rate over the last window (Hz).
    pub achieved_hz: f64,
    /// Median lateness over the last window (µs).
    pub lateness_p50_us: f64,
    /// 99th-percentile lateness over the last window (µs).
    pub lateness_p99_us: f64,
    /// Largest lateness over the last window (µs).
    pub lateness_max_us: f64,
    /// Median compute time of a tick over the last window (µs).
    pub compute_p50_us: f64,
    /// 99th-percentile compute time over the last window (µs).
    pub compute_p99_us: f64,
    /// Ticks that ended after the next deadline, since the start.
    pub overruns: u64,
    /// Deadlines skipped since the start.
    pub skipped: u64,
    /// Ticks executed since the start.
    pub ticks: u64,
}

/// What the loop knows beyond the world, for one frame.
#[derive(Clone, Copy, Debug)]
pub struct FrameInputs<'a> {
    /// True while the loop is paused (the world is not stepped).
    pub paused: bool,
    /// Index of the body driven by the controller (the slave), if any.
    pub slave: Option<usize>,
    /// The hand target pose `(x, y, θ)` in the world frame (m, m, rad): where the page's pointer put
    /// the (simulated) hand.
    pub hand_target: [f64; 3],
    /// Drive wrench on the slave `f_cs` (N, N, N·m).
    pub drive: [f64; 3],
    /// The device kinematics and the handle pose in the **device** frame (m, m, rad), when a
    /// twin-pantograph device (real or simulated) is in the loop.
    pub device: Option<(&'a TwinKinematics, [f64; 3])>,
    /// Translation from the device frame to the world frame (m): world = device + offset.
    pub device_to_world: [f64; 2],
    /// Passivity-observer energy `E_obs` (J), if the loop runs one.
    pub passivity_energy: Option<f64>,
    /// Loop timing (from [`LiveTiming::snapshot`](crate::LiveTiming::snapshot)).
    pub timing: LoopTiming,
    /// Name of the controller in the loop (`"four-channel"`, `"coupling"`, …).
    pub controller: &'static str,
}

impl Default for FrameInputs<'_> {
    fn default() -> Self {
        Self {
            paused: false,
            slave: None,
            hand_target: [0.0; 3],
            drive: [0.0; 3],
            device: None,
            device_to_world: [0.0; 2],
            passivity_energy: None,
            timing: LoopTiming::default(),
            controller: "none",
        }
    }
}

/// The state of the world at one instant, as sent to the page (`{"type": "frame", …}`).
///
/// `Clone` keeps the vectors' capacity, so the three buffers of the triple buffer made from one
/// preallocated frame are all preallocated.
#[derive(Debug, Default, PartialEq, Serialize)]
pub struct Frame {
    /// Frame counter (set by the hub when publishing).
    pub seq: u64,
    /// Sequence number of the [`SceneInfo`](crate::SceneInfo) this frame belongs to (set by the hub).
    pub scene_seq: u64,
    /// Simulated time of the world `k·T` (s).
    pub t: f64,
    /// Sample index `k` of the world.
    pub tick: u64,
    /// True while the loop is paused.
    pub paused: bool,
    /// Name of the normal (wall) law of the world.
    pub wall_law: &'static str,
    /// Name of the friction model of the world.
    pub friction: &'static str,
    /// Impact friction mode of the world (`"none"` or `"coulomb"`).
    pub impact_friction: &'static str,
    /// Name of the controller.
    pub controller: &'static str,
    /// Pose `[x, y, θ]` of every body (m, m, rad), indexed like the scene's bodies.
    pub bodies: Vec<[f64; 3]>,
    /// Twist `[vx, vy, ω]` of every body (m/s, m/s, rad/s).
    pub velocities: Vec<[f64; 3]>,
    /// Contact records (at most [`MAX_FRAME_CONTACTS`]).
    pub contacts: Vec<ContactView>,
    /// Number of contact records in the world (may exceed `contacts.len()`).
    pub contacts_total: u32,
    /// Sum of the normal forces of all contacts (N).
    pub contact_force_n: f64,
    /// Sum of the absolute friction forces of all contacts (N).
    pub contact_force_t: f64,
    /// Index of the slave body, if any.
    pub slave: Option<u32>,
    /// The hand target pose (m, m, rad, world).
    pub hand_target: [f64; 3],
    /// Drive wrench on the slave `f_cs` (N, N, N·m).
    pub drive: [f64; 3],
    /// Contact wrench on the slave (N, N, N·m): minus `f_e`.
    pub slave_contact: [f64; 3],
    /// The device linkage, when a device is in the loop.
    pub device: Option<DeviceView>,
    /// Energies (J).
    pub energy: Energies,
    /// Loop timing.
    pub timing: LoopTiming,
    /// The study trial being run (`haptic2d study run --observer browser`), set by the hub
    /// ([`ViewHub::set_study`](crate::ViewHub::set_study)); absent outside a study.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub study: Option<StudyView>,
}

/// What the page shows of a study trial (`{"study": {…}}` in a frame).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct StudyView {
    /// The trial presented (from 1; 0 before the first).
    pub trial: u32,
    /// Trials planned in the session (an upper bound for adaptive methods).
    pub planned: u32,
    /// Trials answered in the session so far (resumed ones included).
    pub done: u32,
    /// The interval presented (1 to `intervals`; 0 outside a presentation).
    pub interval: u8,
    /// Intervals per trial (2 or 3).
    pub intervals: u8,
    /// `"starting"` (waiting for the next trial), `"break"` (a rest break before the trial: the
    /// world is held with zero force until the page's `continue_study`), `"free_space"` (the next interval's stimulus is
    /// installed once the handle leaves the wall), `"presenting"`, `"answer"` (waiting for the
    /// answer), `"stopping"` (the session ends).
    pub phase: &'static str,
    /// Seconds left in the interval presented (s).
    pub remaining_s: f64,
    /// The task: `"2afc"`, `"3afc"`, `"same-different"` (which buttons the page shows) or
    /// `"magnitude"` (a number entry).
    pub task: &'static str,
    /// Answers refused so far (an old trial, a choice the task has not, outside the answer phase).
    pub refused: u32,
    /// The session's last answer was saved for this trial (0: none yet).
    pub last_saved: u32,
    /// Magnitude estimation: the number the first interval (the reference) stands for (0 in the
    /// other tasks).
    pub modulus: f64,
}

impl Clone for Frame {
    fn clone(&self) -> Self {
        fn keep<T: Clone>(v: &Vec<T>) -> Vec<T> {
            let mut out = Vec::with_capacity(v.capacity());
            out.extend_from_slice(v);
            out
        }
        Self {
            bodies: keep(&self.bodies),
            velocities: keep(&self.velocities),
            contacts: keep(&self.contacts),
            ..*self
        }
    }
}

impl Frame {
    /// An empty frame with room for `bodies` bodies and `contacts` contacts (capped at
    /// [`MAX_FRAME_CONTACTS`]), so that capturing never allocates.
    pub fn with_capacity(bodies: usize, contacts: usize) -> Self {
        Self {
            wall_law: "",
            friction: "",
            impact_friction: "",
            controller: "",
            bodies: Vec::with_capacity(bodies),
            velocities: Vec::with_capacity(bodies),
            contacts: Vec::with_capacity(contacts.min(MAX_FRAME_CONTACTS)),
            ..Self::default()
        }
    }

    /// A frame preallocated for `world`: its bodies and [`MAX_FRAME_CONTACTS`] contacts.
    pub fn for_world(world: &World) -> Self {
        Self::with_capacity(world.bodies.len(), MAX_FRAME_CONTACTS)
    }

    /// Overwrites this frame with the state of `world` and `inputs` (every field except `seq` and
    /// `scene_seq`, which the hub sets). Reuses the vectors: no allocation once their capacity
    /// covers the world's bodies and the contact count (at most [`MAX_FRAME_CONTACTS`]).
    pub fn capture(&mut self, world: &World, inputs: &FrameInputs<'_>) {
        self.t = world.time();
        self.tick = world.tick();
        self.paused = inputs.paused;
        self.wall_law = world.normal.name();
        self.impact_friction = world.impact_friction().name();
        self.friction = world.friction.name();
        self.controller = inputs.controller;

        // Bodies.
        self.bodies.clear();
        self.velocities.clear();
        for b in &world.bodies {
            self.bodies.push([b.pose.pos.x, b.pose.pos.y, b.pose.angle]);
            self.velocities.push([b.vel.x, b.vel.y, b.omega]);
        }

        // Contacts.
        self.contacts.clear();
        let (mut total, mut f_n, mut f_t) = (0u32, 0.0, 0.0);
        for c in world.contact_records() {
            total += 1;
            f_n += c.f_n;
            f_t += c.f_t.abs();
            if self.contacts.len() < MAX_FRAME_CONTACTS {
                let g = c.god_object();
                self.contacts.push(ContactView {
                    body_a: c.body_a as u32,
                    body_b: c.body_b as u32,
                    state: match c.state {
                        Some(ContactState::Colliding) => "colliding",
                        _ => "continuous",
                    },
                    point: [c.point.x, c.point.y],
                    normal: [c.n.x, c.n.y],
                    tangent: [c.t().x, c.t().y],
                    depth: c.d[0],
                    god_object: [g.x, g.y],
                    f_n: c.f_n,
                    f_t: c.f_t,
                });
            }
        }
        self.contacts_total = total;
        self.contact_force_n = f_n;
        self.contact_force_t = f_t;

        // Slave and hand.
        let slave = inputs.slave.filter(|&i| i < world.bodies.len());
        self.slave = slave.map(|i| i as u32);
        self.hand_target = inputs.hand_target;
        self.drive = inputs.drive;
        self.slave_contact = slave.map_or([0.0; 3], |i| {
            let w = world.contact_wrench(i);
            [w.force.x, w.force.y, w.torque]
        });

        // Device linkage (twin-pantograph kinematics at the handle pose).
        self.device = inputs
            .device
            .map(|(kin, pose)| device_view(kin, pose, inputs.device_to_world));

        // Energies and timing.
        let l = world.ledger();
        self.energy = Energies {
            kinetic: l.kinetic,
            stored: l.stored,
            applied_work: l.applied_work,
            impact_loss: l.impact_loss,
            impact_energy_fallbacks: l.impact_energy_fallbacks,
            excess: l.excess(),
            passivity: inputs.passivity_energy,
        };
        self.timing = inputs.timing;
    }
}

/// The linkage at handle pose `pose` (device frame), shifted into the world by `offset` (m).
pub fn device_view(kin: &TwinKinematics, pose: [f64; 3], offset: [f64; 2]) -> DeviceView {
    let w = |p: haptic2d::geom::Vec2| [p.x + offset[0], p.y + offset[1]];
    match kin.configuration(&pose) {
        Ok(cfg) => DeviceView {
            valid: true,
            handle: [pose[0] + offset[0], pose[1] + offset[1], pose[2]],
            handle_device: pose,
            elbows: cfg.e.map(w),
            endpoints: cfg.p.map(w),
        },
        Err(_) => DeviceView {
            valid: false,
            handle: [pose[0] + offset[0], pose[1] + offset[1], pose[2]],
            handle_device: pose,
            ..DeviceView::default()
        },
    }
}
