//! `haptic2d run --world udp:HOST:PORT --key FILE` (alias: `haptic2d remote-device --world …`): the
//! device side of the haptic loop split at a network (issue 41, docs/TELEOP.md). It runs the device (the simulated twin
//! pantograph and its simulated hand, or any real device of the registry: a Haply board, a UDP
//! device, an Inverse3) as a [`DeviceEnd`] with its local safety, and renders the force the world side
//! sends through the master port's TDPA passivity controller — or, with `--link wave`, the force
//! of the lab's wave master ([`WaveMaster`], one per axis) from the returning waves, under their
//! energy budget. Every period:
//!
//! ```text
//! encoders → pose, twist (DeviceEnd::sense)                  stall, joint plausibility (SafetyStage)
//! newest world message (authenticated, by sequence number)    lost link: none for --link-timeout-ms → latch
//! force → TDPA master port (energy in from the world)          (DeviceEnd::actuate:) workspace bound
//!   (wave: F = −(b·v − √(2b)·w), w the newest wave within the world's wave energy sent)
//! → torques (saturation) → limit cycle, ramp, gate → motors   book the force really applied
//!
//! The safety steps are the shared `SafetyStage`, the same as every device's in `run`; a device
//! sends only the axes it renders (x and y on a five-bar or a point device).
//! send: handle pose and twist from the start pose, the applied force, the port's energies
//! ```
//!
//! Any latch zeroes the torques in the same period, stops the loop and says why (exit 3). `run`
//! dispatches here on `--world` before building its rig: `run`'s own tick is one `HapticSystem`
//! holding device and world together (crates/haptic2d/src/haptic/), which this split does not
//! change; the device side is this loop, with the same `SafetyStage` as that tick.

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

use haptic2d::control::tdpa::{planar_balance, PlanarTdpa};
use haptic2d::device::linalg::{V3, V4};
use haptic2d::device::DeviceParams;
use haptic2d::haptic::safety::{SafetyConfig, SafetyReason};
use haptic2d::haptic::DeviceEnd;
use haptic2d_devices::world_link::message::{link_flags, FLAG_BYE, FLAG_LATCHED, FLAG_WAVE};
use haptic2d_devices::world_link::{
    LinkEndpoint, PortMessage, KIND_TO_DEVICE, KIND_TO_WORLD, PORT_LEN,
};
use haptic2d_lab::network::wave::{WaveMaster, WaveMsg};
use haptic2d_rt::clock::now_ns;
use haptic2d_rt::{
    DeviceError, LoopConfig, SharedTarget, SimIo, TickControl, TickInfo, TickInterval,
};

use crate::end_io::EndIo;
use crate::exit::{Failure, Status};
use crate::hand_arg::HandSpec;
use crate::outln;
use crate::push_arg::Push;
use crate::world_link_arg::{energies, report_link, wave_totals, EndWording};
use crate::world_link_arg::{LinkArgs, LinkStats, Outbox};

/// Examples of `remote-device --help`.
pub const EXAMPLES: &[crate::Example] = &[
    (
        "The simulated device held still, for 10 s, against a world side on this machine (the same as `haptic2d run --world udp:127.0.0.1:7420 --key world.key --duration 10`)",
        "haptic2d remote-device --world udp:127.0.0.1:7420 --key world.key",
    ),
    (
        "The grip pushes 15 mm left from 0.6 s; 5 % loss injected on what this end sends",
        "haptic2d remote-device --world udp:127.0.0.1:7420 --key k --push -0.015,0,0.05,0.6 --loss 0.05",
    ),
    (
        "A scripted hand push (hold 1 s, 2 N left for 1 s), at normal scheduling",
        "haptic2d remote-device --world udp:10.0.0.2:7420 --key k --hand script:1,-2,0,0,1 --no-rt",
    ),
];

/// The device side's own options, shared by `run --world` and its alias `remote-device`.
#[derive(clap::Args, Debug, Clone)]
pub struct DeviceSideArgs {
    /// A scripted push by the gripping hand (`--hand follow`: a spring–damper, 300 N/m, 5 N·s/m):
    /// from time AT (s) its target moves from the start pose by (DX, DY) (m) at SPEED (m/s), then
    /// stays; e.g. `-0.015,0,0.05,0.6` pushes 15 mm to the left from 0.6 s (with --world only).
    #[arg(long, value_name = "DX,DY,SPEED,AT", allow_hyphen_values = true)]
    pub push: Option<String>,
    /// A tick later than this many periods after the previous one is a stall (the latch trips;
    /// with --world only: `run`'s own tick has its stall limit in the watchdog).
    #[arg(long, default_value_t = 5.0)]
    pub max_stall_periods: f64,
    /// Wait at most this long (s) for the world side's WELCOME (with --world only).
    #[arg(long, default_value_t = 5.0)]
    pub connect_timeout: f64,
    #[command(flatten)]
    pub link: LinkArgs,
}

impl DeviceSideArgs {
    /// True when any of these options was given (`run` accepts them with `--world` only).
    pub fn any_given(&self) -> bool {
        self.push.is_some()
            || self.max_stall_periods != 5.0
            || self.connect_timeout != 5.0
            || self.link.any_given()
    }
}

/// `remote-device`'s options: an alias of `run --device sim --world udp:HOST:PORT` kept for the
/// scripts that use it.
#[derive(clap::Args, Debug)]
pub struct RemoteDeviceArgs {
    /// The world side: `udp:HOST:PORT` of a `haptic2d serve-world`.
    #[arg(long, value_name = "udp:HOST:PORT")]
    pub world: String,
    /// The simulated operator (as `run --hand`): follow | free | constant:FX,FY,TAU | sine:… |
    /// script:HOLD,FX,FY,TAU,PUSH[,RFX,RFY,RTAU].
    #[arg(long, default_value = "follow")]
    pub hand: String,
    /// Run for this long (s).
    #[arg(long, default_value_t = 10.0)]
    pub duration: f64,
    /// Loop rate (Hz); the world side must run at the same rate.
    #[arg(long, default_value_t = 1000.0)]
    pub rate: f64,
    /// Normal scheduling instead of real-time priority for the device loop.
    #[arg(long)]
    pub no_rt: bool,
    #[command(flatten)]
    pub side: DeviceSideArgs,
}

/// One device side to run, from `run --world` or `remote-device`.
struct Plan<'a> {
    world: &'a str,
    /// `--device`: `sim` or a real device of the registry.
    device: &'a str,
    /// A real device's own device file (`--device-file`).
    device_file: Option<&'a std::path::Path>,
    /// `--allow-remote-device` (a UDP device beyond loopback).
    allow_remote: bool,
    hand: &'a str,
    /// Run length (s); `None`: until a signal.
    duration: Option<f64>,
    rate: f64,
    rt: bool,
    spin_us: Option<f64>,
    side: &'a DeviceSideArgs,
}

/// Why the device side latched zero torques.
#[derive(Clone, Debug)]
enum Latch {
    /// The core's safety latch (stall, gate, workspace, device fault, singularity).
    Safety(SafetyReason),
    /// No datagram from the world for `silent` s (limit `limit` s).
    LostLink { silent: f64, limit: f64 },
    /// The world side closed the session.
    WorldClosed,
    /// The world side runs the other kind of link (waves against forces): `true` if it runs waves.
    Mismatch { world_waves: bool },
    /// The device stopped answering, or a read or write failed (the driver's words).
    DeviceLost(DeviceError),
}

/// The device side's state, owned by the loop.
struct DeviceSide {
    /// The simulated twin (whose plant's true motion is known, for the plants' ledger) with its
    /// grip's push, or a real device of the registry.
    io: EndIo,
    /// The device with the tick's safety steps, the same as every device's (stall, joint
    /// plausibility, workspace bound, limit cycle, ramp, final gate).
    end: DeviceEnd,
    /// The axes the device renders (x, y, θ): the others send and apply nothing.
    axes: [bool; 3],
    tdpa: bool,
    /// The wave master per axis with `--link wave`, and what it sent last.
    wave: Option<[WaveMaster; 3]>,
    wave_out: [WaveMsg; 3],
    /// With waves: the measured pose at the start of the period just ended, and the force
    /// really applied over it (booked one period late, on the measured displacement).
    prev_pose_for_books: Option<V3>,
    prev_applied: V3,

    ports: PlanarTdpa,
    /// The port's energy as the plant really received it: the applied force times the simulated
    /// plant's true displacement over the period (the simulated device only).
    plant_ledger: PlanarTdpa,
    ep: LinkEndpoint,
    outbox: Outbox,
    stats: LinkStats,
    interval: TickInterval,
    /// Time the last read waited for a real device, and the previous tick's (ns).
    read_wait_ns: (u64, u64),
    timeout_periods: u64,
    first_timeout_periods: u64,
    last: Option<PortMessage>,
    last_k: u64,
    last_arrival_ns: u64,
    seq: u32,
    ticks: u64,
    buf: [u8; PORT_LEN],
    max_force: f64,
    /// Largest distance of the handle from its start pose (m).
    max_excursion: f64,
    latch: Option<(f64, Latch)>,
}

impl DeviceSide {
    fn tick(&mut self, info: &TickInfo) -> TickControl {
        let (k, dt, t) = (info.deadline_index, info.period_s, info.t_s);
        let at = (k, t);
        let q = match self.read(t) {
            Ok(q) => q,
            Err(e) => return self.stop(t, Latch::DeviceLost(e)),
        };
        let est = self.sense(info, &q);
        let fresh = match self.receive(k, t, dt) {
            Ok(m) => m,
            Err(stop) => return stop,
        };
        let Some(est) = est else {
            // Not sensed: the latch holds the fault; zero torques and stop below.
            self.end.actuate(at, None, &[0.0; 3]);
            return self.finish(t);
        };
        let (x, v) = (est.pose, est.velocity);
        let origin = self.end.origin().unwrap_or(x);
        let f_net = self.port_force(&x, &v, &origin, fresh, dt);
        // Local safety: the workspace bound, the torques, the ramp, the gate.
        let out = self.end.actuate(at, Some(&est), &self.mask(f_net));
        let applied = self.mask(out.applied);
        self.prev_applied = applied;
        if self.wave.is_some() {
            // Booked at the next period, on the displacement measured over this one.
        } else if self.tdpa {
            self.ports.book(&applied, &v, dt);
        } else {
            self.ports.observe(&applied, &v, dt);
        }
        self.max_force = self.max_force.max(applied[0].hypot(applied[1]));
        let d = (x[0] - origin[0]).hypot(x[1] - origin[1]);
        self.max_excursion = self.max_excursion.max(d);
        let before = self.plant_pose();
        if let Err(e) = self.io.io().write_torques(&out.tau) {
            return self.stop(t, Latch::DeviceLost(e));
        }
        if let (Some(b), Some(a)) = (before, self.plant_pose()) {
            let moved: V3 = std::array::from_fn(|i| (a[i] - b[i]) / dt);
            self.plant_ledger.observe(&applied, &moved, dt);
        }
        self.send(k, &x, &origin, &v, &applied, 0);
        self.ticks += 1;
        self.finish(t)
    }

    /// Reads the device at loop time `t` (s), timing the wait of a real one (left out of the stall
    /// check, as in `run`).
    fn read(&mut self, t: f64) -> Result<V4, DeviceError> {
        let (q, wait) = self.io.read(t);
        self.read_wait_ns = (wait, self.read_wait_ns.0);
        q
    }

    /// Steps 0–2 of the device ([`EndIo::sense`]): the stall check on the loop's own time (the
    /// interval less the previous read's wait), the pose and twist.
    fn sense(&mut self, info: &TickInfo, q: &V4) -> Option<haptic2d::device::DeviceEstimate> {
        let at = (info.deadline_index, info.t_s);
        let elapsed = self.interval.update(info) as f64 * 1e-9;
        let wait = self.read_wait_ns.1 as f64 * 1e-9;
        (self.io).sense(&mut self.end, at, q, (elapsed, wait, info.period_s))
    }

    /// The simulated plant's true pose (m, m, rad); `None` on a real device.
    fn plant_pose(&self) -> Option<V3> {
        self.io.sim().map(|s| s.plant().pose())
    }

    /// The force to render this period from the world's newest message: through the master
    /// port's passivity controller, or the wave master's force (the ramp, the saturation and the
    /// gate come after, in [`DeviceEnd::actuate`]).
    fn port_force(
        &mut self,
        x: &V3,
        v: &V3,
        origin: &V3,
        fresh: Option<PortMessage>,
        dt: f64,
    ) -> V3 {
        // (Unlike the lab's teleop, the port keeps the filtered velocity: measured over the split
        // loop, the plants' true ledger showed no gain from the unfiltered rate; docs/TELEOP.md.)
        let (f_req, far) = self
            .last
            .map_or(([0.0; 3], [0.0; 3]), |m| (self.mask(m.force), m.energy_in));
        let moved: Option<V3> = self
            .prev_pose_for_books
            .map(|p| std::array::from_fn(|i| (x[i] - p[i]) / dt));
        self.prev_pose_for_books = Some(*x);
        if let Some(wm) = &mut self.wave {
            // Waves. First the period just ended, as the plant received it: the force really
            // applied over it and the measured displacement (the waves sent are those, one period
            // late; the wave drawn beyond what the budget granted is a debt).
            if let Some(mv) = moved {
                for i in 0..3 {
                    self.wave_out[i] =
                        wm[i].book(x[i] - origin[i], mv[i], self.prev_applied[i], dt);
                }
                self.ports.observe(&self.prev_applied, &mv, dt);
            }
            // Then this period's force: the newest returning wave (once), within the world's
            // wave energy sent, and the damping b·v on the filtered velocity (as the TDPA port's;
            // the unfiltered rate of the pose gave the same plants' ledger and a larger debt).
            std::array::from_fn(|i| {
                let msg = fresh.map(|m| WaveMsg {
                    wave: m.wave[i],
                    energy: m.wave_energy[i],
                    x: m.wave_x[i],
                });
                wm[i].force(v[i], msg, dt)
            })
        } else if self.tdpa {
            let m = self.end.mass_diagonal();
            let alpha_max = m.map(|m| 2.0 * m / dt);
            self.ports.control(&f_req, v, &far, dt, &alpha_max)
        } else {
            f_req
        }
    }

    /// `w` on the axes the device renders, zero on the others.
    fn mask(&self, w: V3) -> V3 {
        std::array::from_fn(|i| if self.axes[i] { w[i] } else { 0.0 })
    }

    /// Stops on a latch of the safety stage, else continues.
    fn finish(&mut self, t: f64) -> TickControl {
        match self.end.trip_info() {
            Some(trip) => self.stop(trip.t.min(t), Latch::Safety(trip.reason)),
            None => TickControl::Continue,
        }
    }

    /// The world's newest message this period, if one arrived, and the lost-link check: `Err`
    /// holds the stop (the world closed the link, runs the other link kind, or fell silent).
    fn receive(&mut self, k: u64, t: f64, dt: f64) -> Result<Option<PortMessage>, TickControl> {
        let fresh = self.ep.poll(KIND_TO_DEVICE);
        if let Some(m) = fresh {
            let now = now_ns();
            self.stats.arrived(now, m.echo_time_ns, m.echo_age_ns);
            (self.last, self.last_k, self.last_arrival_ns) = (Some(m), k, now);
            // The link kind first: a world that stopped on the mismatch says goodbye with it.
            let world_waves = m.flags & FLAG_WAVE != 0;
            if world_waves != self.wave.is_some() {
                return Err(self.stop(t, Latch::Mismatch { world_waves }));
            }
            if m.flags & FLAG_BYE != 0 {
                return Err(self.stop(t, Latch::WorldClosed));
            }
        }
        let silent = k.saturating_sub(self.last_k);
        let limit = if self.last.is_some() {
            self.timeout_periods
        } else {
            self.first_timeout_periods
        };
        if silent > limit {
            let lost = Latch::LostLink {
                silent: silent as f64 * dt,
                limit: limit as f64 * dt,
            };
            return Err(self.stop(t, lost));
        }
        Ok(fresh)
    }

    fn send(&mut self, k: u64, x: &V3, origin: &V3, v: &V3, force: &V3, flags: u32) {
        self.seq = self.seq.wrapping_add(1);
        let now = now_ns();
        let (w, we, wx) = (
            self.wave_out.map(|o| o.wave),
            self.wave_out.map(|o| o.energy),
            self.wave_out.map(|o| o.x),
        );
        let msg = PortMessage {
            seq: self.seq,
            flags: flags | self.method_flags(),
            time_ns: now,
            echo_time_ns: self.last.map_or(0, |m| m.time_ns),
            echo_age_ns: u32::try_from(now.saturating_sub(self.last_arrival_ns))
                .unwrap_or(u32::MAX),
            echo_seq: self.last.map_or(0, |m| m.seq),
            pose: self.mask(std::array::from_fn(|i| x[i] - origin[i])),
            twist: self.mask(*v),
            force: *force,
            energy_in: self.ports.energy_in(),
            energy_out: self.ports.energy_out(),
            wave: w,
            wave_energy: we,
            wave_x: wx,
        };
        let buf = &mut self.buf;
        (self.outbox).seal_and_send(&mut self.ep, &msg, KIND_TO_WORLD, k, buf);
    }

    /// `FLAG_TDPA` or `FLAG_WAVE` as this end runs.
    fn method_flags(&self) -> u32 {
        link_flags(self.tdpa, self.wave.is_some())
    }

    /// Latches zero torques, says so to the world, and stops the loop.
    fn stop(&mut self, t: f64, why: Latch) -> TickControl {
        self.io.io().zero_torques();
        if self.latch.is_none() {
            self.latch = Some((t, why));
        }
        TickControl::Stop
    }

    /// Tells the world side the session is over (three times, past the impairment: a lost BYE
    /// only makes the world wait for its silence timeout).
    fn bye(&mut self, latched: bool) {
        let flags = FLAG_BYE | if latched { FLAG_LATCHED } else { 0 } | self.method_flags();
        for _ in 0..3 {
            self.seq = self.seq.wrapping_add(1);
            let msg = PortMessage {
                seq: self.seq,
                flags,
                time_ns: now_ns(),
                energy_in: self.ports.energy_in(),
                energy_out: self.ports.energy_out(),
                wave_energy: self.wave_out.map(|o| o.energy),
                ..PortMessage::default()
            };
            msg.seal(
                self.ep.key(),
                KIND_TO_WORLD,
                self.ep.session(),
                &mut self.buf,
            );
            self.ep.send(&self.buf);
        }
    }
}

fn world_addr(s: &str) -> Result<&str, String> {
    s.strip_prefix("udp:")
        .filter(|a| a.contains(':'))
        .ok_or_else(|| {
            format!("--world {s}: expected udp:HOST:PORT\n    fix: e.g. --world udp:127.0.0.1:7420")
        })
}

/// Runs `remote-device` (the same as `run --device sim --world …`).
pub fn run(a: &RemoteDeviceArgs) -> Result<Status, Failure> {
    run_device_side(&Plan {
        world: &a.world,
        device: "sim",
        device_file: None,
        allow_remote: false,
        hand: &a.hand,
        duration: Some(a.duration),
        rate: a.rate,
        rt: !a.no_rt,
        spin_us: None,
        side: &a.side,
    })
}

/// Runs `run --world udp:HOST:PORT`: the device side of the split loop. `run`'s options that
/// belong to a local world (its log, display feeds, controller, passivity on the device port) are
/// refused with the reason. The device is the simulated twin or any real device of the registry
/// (`--device haply:…`, `udp:…`, `inverse3…`, with its `--device-file`).
pub fn run_from_run(a: &crate::cmd_run::RunArgs, world: &str) -> Result<Status, Failure> {
    let refuse = |what: &str| -> Result<Status, Failure> {
        Err(Failure::from(format!(
            "--world {world}: {what} does not apply to the device side of a split loop (the world, its controller and its logs are on the world side, `haptic2d serve-world`)\n    fix: leave it out, or run without --world"
        )))
    };
    if a.device.starts_with("replay:") {
        return Err(Failure::from(format!(
            "--world {world} --device {}: a replay renders no force; the device side needs a device that moves\n    fix: --device sim, haply:PATH, udp:ADDR:PORT or inverse3",
            a.device
        )));
    }
    if a.log.is_some() {
        return refuse("--log");
    }
    if a.foxglove.is_some() {
        return refuse("--foxglove");
    }
    if a.passivity {
        return refuse("--passivity (the link has its own passivity controller, --link)");
    }
    if a.controller_file.is_some() || a.controller != "four-channel" {
        return refuse("--controller / --controller-file");
    }
    if a.device_file.is_some() && a.device == "sim" {
        return refuse("--device-file with --device sim (the simulated twin runs its defaults)");
    }
    crate::cmd_run::check_rate(a.rate)?;
    run_device_side(&Plan {
        world,
        device: &a.device,
        device_file: a.device_file.as_deref(),
        allow_remote: a.allow_remote_device,
        hand: a.hand.as_deref().unwrap_or("follow"),
        duration: a.duration,
        rate: a.rate,
        rt: !a.no_rt,
        spin_us: a.spin_us,
        side: &a.remote,
    })
}

/// Checks `--duration` (s) and builds the safety settings with `--max-stall-periods`.
fn check_run_settings(
    duration: Option<f64>,
    max_stall_periods: f64,
) -> Result<SafetyConfig, Failure> {
    if let Some(d) = duration {
        if !(d.is_finite() && d > 0.0 && d <= crate::cmd_run::MAX_RUN_DURATION_S) {
            return Err(Failure::from(format!("--duration must be > 0 s (got {d})")));
        }
    }
    let safety_config = SafetyConfig {
        max_stall_periods,
        ..SafetyConfig::default()
    };
    safety_config.validate().map_err(Failure::from)?;
    Ok(safety_config)
}

/// The simulated twin at rest at the workspace centre, gripped by `hand` (whose target `--push`
/// moves), as a device side's I/O and end.
fn sim_device(p: &Plan, hand: &HandSpec, safety: SafetyConfig, dt: f64) -> Result<Opened, Failure> {
    let params = DeviceParams::default();
    let start = [params.workspace_center_x, params.workspace_center_y, 0.0];
    let substeps = ((dt / 0.0005).ceil() as u32).max(1);
    let mut io =
        SimIo::new(&params, start, hand.model(start), dt, substeps).map_err(Failure::from)?;
    let push = match &p.side.push {
        None => None,
        Some(v) if *hand == HandSpec::Follow => {
            let target = Arc::new(SharedTarget::new(start));
            io.follow(target.clone());
            Some((Push::parse(v).map_err(Failure::from)?, target, start))
        }
        Some(_) => {
            return Err(Failure::from(format!(
                "--push moves the gripping hand's target: it needs --hand follow (got --hand {})",
                p.hand
            )))
        }
    };
    let mut end = DeviceEnd::twin(params, safety, dt).map_err(Failure::from)?;
    if let haptic2d::haptic::EndDevice::Twin(d) = end.device_mut() {
        d.reset(start[2]);
    }
    let what = format!("simulated twin pantograph, hand {}", p.hand);
    Ok((EndIo::Sim { io, push }, end, what))
}

/// A device side's I/O (with the `--push` of a simulated hand), its end and a description.
type Opened = (EndIo, DeviceEnd, String);

/// A real device of the registry, its device file read and checked, then opened at period `dt`.
fn real_device(p: &Plan, dt: f64) -> Result<Opened, Failure> {
    if p.side.push.is_some() || p.hand != "follow" {
        return Err(Failure::from(format!(
            "--push and --hand move the simulated hand: with --device {} the hand is yours\n    fix: leave them out",
            p.device
        )));
    }
    let r = crate::real_end::open(p.device, p.device_file, p.allow_remote, dt)?;
    let what = format!("{} ({})", r.name, r.summary);
    let (io, end) = (r.io, r.end);
    Ok((EndIo::Real(io), end, what))
}

fn run_device_side(p: &Plan) -> Result<Status, Failure> {
    let a = p.side;
    let key = a.link.key().map_err(Failure::from)?;
    let addr = world_addr(p.world).map_err(Failure::from)?;
    let hand = HandSpec::parse(p.hand).map_err(Failure::from)?;
    let safety_config = check_run_settings(p.duration, a.max_stall_periods)?;
    let dt = 1.0 / p.rate;
    let (io, end, what) = if p.device == "sim" {
        sim_device(p, &hand, safety_config, dt)?
    } else {
        real_device(p, dt)?
    };
    let stop = haptic2d_rt::signal::install_stop_signals().map_err(Failure::error)?;
    let ep = LinkEndpoint::connect(
        addr,
        &key,
        Duration::from_secs_f64(a.connect_timeout.max(0.1)),
    )
    .map_err(Failure::error)?;
    outln!(
        "device side: session {:016x} with the world at {}, {what}, {} Hz, link {}, impairment: {}; no display (the world is on the world side)",
        ep.session(),
        ep.peer(),
        p.rate,
        a.link.method(),
        a.link.describe(p.rate)
    );
    let timeout_periods = (a.link.link_timeout_ms * 1e-3 * p.rate).ceil() as u64;
    let mut side = DeviceSide {
        io,
        axes: end.axes(),
        end,
        tdpa: a.link.tdpa(),
        wave: a.link.wave().map(|w| w.map(WaveMaster::new)),
        wave_out: [WaveMsg::default(); 3],
        prev_pose_for_books: None,
        prev_applied: [0.0; 3],
        ports: PlanarTdpa::default(),
        plant_ledger: PlanarTdpa::default(),
        outbox: a.link.outbox(p.rate),
        // Round trips and arrival intervals of up to an hour are kept (beyond, counted only).
        stats: LinkStats::with_capacity(
            ((p.duration.unwrap_or(3600.0).min(3600.0) + 1.0) * p.rate) as usize,
        ),
        ep,
        interval: TickInterval::new(),
        read_wait_ns: (0, 0),
        timeout_periods,
        // The first message needs the world's start and both delays on top.
        first_timeout_periods: timeout_periods.max((p.rate as u64).max(1))
            + 2 * (a.link.delay_ms * 1e-3 * p.rate) as u64,
        last: None,
        last_k: 0,
        last_arrival_ns: 0,
        seq: 0,
        ticks: 0,
        buf: [0; PORT_LEN],
        max_force: 0.0,
        max_excursion: 0.0,
        latch: None,
    };
    let config = LoopConfig {
        rate_hz: p.rate,
        duration: p.duration.map(Duration::from_secs_f64),
        rt: p.rt,
        spin_us: p.spin_us.unwrap_or((0.4e6 / p.rate).min(400.0)),
        ..LoopConfig::default()
    };
    config.validate().map_err(Failure::from)?;
    let summary = crate::rt_thread::run_on_rt_thread(&config, &stop, |info| side.tick(&info))?;
    side.io.io().zero_torques();
    side.bye(side.latch.is_some());
    Ok(report(&mut side, &summary, stop.load(Ordering::Relaxed)))
}

fn report(
    side: &mut DeviceSide,
    summary: &haptic2d_rt::TimingSummary,
    interrupted: bool,
) -> Status {
    if let Some(w) = summary.rt.as_ref().and_then(|r| r.warning()) {
        outln!("{w}");
    }
    outln!("{summary}");
    let mine = side.ports.totals();
    outln!("master port (device): {}", energies(mine));

    let plant = side.plant_ledger.totals();
    if side.plant_pose().is_some() {
        outln!(
            "master port (plant, true displacement): energy in {:.6} J, out {:.6} J",
            plant.0,
            plant.1
        );
    } else {
        outln!("master port (plant, true displacement): not known (a real device; the books above are the encoders')");
    }
    let per_axis = |p: &PlanarTdpa| -> [f64; 3] {
        let (i, o) = (p.energy_in(), p.energy_out());
        std::array::from_fn(|k| o[k] - i[k])
    };
    let (b, pl) = (per_axis(&side.ports), per_axis(&side.plant_ledger));
    outln!(
        "master port, out − in per axis (x, y, θ): books {:.6}, {:.6}, {:.6} J; plant {:.6}, {:.6}, {:.6} J",
        b[0], b[1], b[2], pl[0], pl[1], pl[2]
    );
    if let Some(m) = side.last {
        let (i, o) = (
            m.energy_in.iter().sum::<f64>(),
            m.energy_out.iter().sum::<f64>(),
        );
        outln!("world port (slave, as last received): energy in {i:.6} J, out {o:.6} J");
        let bal = planar_balance((mine.0, mine.1), (i, o));
        outln!(
            "network: energy created {:.6} J (out − in over both ports; ≤ 0 is passive)",
            bal.created
        );
    }
    let waves = (side.wave.as_ref()).map(|wm| {
        let budgets = wm.iter().map(|m| m.budget());
        wave_totals(budgets, &side.wave_out, side.last.as_ref())
    });
    let end = EndWording {
        peer: "world",
        peer_waves: "returning waves: the world",
        used_note: "",
    };
    report_link(
        &end,
        waves,
        &side.ep.counters,
        side.outbox.dropped(),
        format_args!("largest force on the handle {:.3} N", side.max_force),
    );
    outln!("link: {}", side.stats.describe());
    outln!(
        "handle: largest excursion {:.1} mm from the start pose",
        side.max_excursion * 1e3
    );
    match side.latch.clone() {
        None if interrupted => {
            outln!("stopped: interrupted by a signal (SIGINT or SIGTERM)");
            Status::Interrupted
        }
        None => {
            outln!("stopped: the duration ended; no safety stop");
            Status::Clean
        }
        Some((t, why)) => {
            let what = match why {
                Latch::Safety(r) => format!("safety stop: {r}"),
                Latch::LostLink { silent, limit } => format!(
                    "safety stop: lost link: no datagram from the world for {:.0} ms (limit {:.0} ms)",
                    silent * 1e3,
                    limit * 1e3
                ),
                Latch::WorldClosed => "safety stop: the world side closed the session".into(),
                Latch::Mismatch { world_waves } => format!(
                    "safety stop: link mismatch: the world side runs {}, this side {} (both ends need the same --link)",
                    if world_waves { "wave variables" } else { "force/velocity (tdpa or none)" },
                    if world_waves { "force/velocity (tdpa or none)" } else { "wave variables" },
                ),
                Latch::DeviceLost(e) => {
                outln!("stopped: {e} at t = {t:.3} s; torques set to zero and latched");
                return Status::DeviceLost;
            }
            };
            outln!("stopped: {what} at t = {t:.3} s; torques set to zero and latched");
            Status::SafetyStop
        }
    }
}
