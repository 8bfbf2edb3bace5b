//! `haptic2d run`: the haptic loop — device, controller and world at the control rate on a real-time
//! thread, with CSV logging on another thread, the live display in the browser (unless
//! `--headless`), and a timing summary at exit.

use crate::device_arg;
use crate::exit::{Failure, Status};
use crate::foxglove_live::FoxgloveServer;
use crate::hand_arg::HandSpec;
use crate::loop_end::LoopEnd;
use crate::run_log::{self, RunLogger};
use crate::run_rig::{DeviceChoice, RealOpenError, Rig};
use crate::run_view::{self, LiveView, LoadedScene};
use crate::scene_arg;
use crate::worst_step::WorstStep;
use haptic2d::control::passivity::PlanarPassivity;
use haptic2d::device::DeviceFault;
use haptic2d::haptic::{ControllerKind, HapticConfig, SafetyReason};
use haptic2d::scene::MAX_RATE_HZ;
use haptic2d_rt::mcap::{LoggedTick, McapSetup};
use haptic2d_rt::signal::install_stop_signals;
use haptic2d_rt::telemetry::{ring_capacity, MAX_RING_BYTES};
use haptic2d_rt::{
    telemetry_channel, DeviceError, LoopConfig, SnapshotRx, TelemetryTx, TickControl, TickInfo,
    TimingSummary, Watchdog,
};
use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Options of `haptic2d run`.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    /// A scene file path, or a built-in scene name (see `haptic2d scenes`).
    #[arg(default_value = "box-in-walls")]
    pub scene: String,
    /// No display: do not start the browser display server.
    #[arg(long)]
    pub headless: bool,
    /// Stop after this many seconds (default: run until Ctrl-C).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Control rate (Hz); also the world's rate.
    #[arg(long, default_value_t = 1000.0, allow_negative_numbers = true)]
    pub rate: f64,
    /// Teleoperation controller: four-channel (default: stable with the hand released),
    /// four-channel-spec (the paper's gains, unstable released), four-channel-damped or coupling.
    #[arg(long, default_value = "four-channel")]
    pub controller: String,
    /// Controller architecture and gains from a file (wins over --controller; examples in
    /// controllers/, e.g. controllers/paper-4ch.toml).
    #[arg(long, value_name = "FILE.toml")]
    pub controller_file: Option<PathBuf>,
    /// Passivity observer/controller on the device port (§12).
    #[arg(long)]
    pub passivity: bool,
    /// Simulated hand (simulated device only): follow | free | constant:FX,FY,TAU |
    /// sine:FPK,FREQ[,DIRX,DIRY] | script:HOLD,FX,FY,TAU,PUSH[,RFX,RFY,RTAU]. Default: follow.
    /// constant and sine push from t = 0, while the torques still ramp in (0.5 s): on box-in-walls a
    /// push of 2 N runs the handle past the workspace edge, a safety stop (exit 3); script waits
    /// HOLD seconds first (e.g. script:0.6,-2,0,0,1).
    #[arg(long, allow_hyphen_values = true)]
    pub hand: Option<String>,
    /// Device: sim (simulated twin pantograph), replay:FILE.csv (recorded encoders q1..q4, rad),
    /// replay:FILE.mcap (the encoders of a `--log FILE.mcap` recording), haply:PATH or haply:auto
    /// (a Haply board; --device-file a Haply device file, default haply-2diy-gen3), udp:ADDR:PORT (a
    /// device on the open UDP protocol, docs/DEVICE-PROTOCOL.md; --device-file a UDP device file,
    /// default devices/udp-pantograph.toml), inverse3[:URL] (a Haply Inverse3 through its Inverse
    /// Service, default http://localhost:10001; --device-file default devices/inverse3.toml).
    #[arg(long, default_value = "sim")]
    pub device: String,
    /// Device parameters (TOML: top-level fields or a [device] table; template:
    /// devices/twin-pantograph.toml). Wins over the scene's [device] table; fields left out keep
    /// the spec defaults. Used by the simulated device and to read a replay's encoders.
    #[arg(long, value_name = "FILE.toml")]
    pub device_file: Option<PathBuf>,
    /// Write every tick's record to this file: MCAP when it ends in .mcap (every tick, plus bodies,
    /// contacts, energy and a Foxglove scene; docs/LOGS.md), else CSV.
    #[arg(long)]
    pub log: Option<PathBuf>,
    /// Address of the live display (open http://ADDR:PORT/ in a browser). Commands are accepted
    /// only from the page it serves; bound to a non-loopback address, they also need the token
    /// printed at startup (see docs/DISPLAY.md).
    #[arg(long, default_value = "127.0.0.1:8080")]
    pub bind: String,
    /// Commands from the display need the token printed at startup on a loopback --bind too (off
    /// loopback they always do): for a machine shared with other users.
    #[arg(long)]
    pub require_token: bool,
    /// Real-time scheduling (SCHED_FIFO, mlockall, core pinning) — the default; where it is not
    /// permitted the loop says so in one line and runs with normal scheduling.
    #[arg(long, overrides_with = "no_rt")]
    pub rt: bool,
    /// Normal scheduling: do not ask for real-time privileges.
    #[arg(long, overrides_with = "rt")]
    pub no_rt: bool,
    /// Foxglove live view: serve the Foxglove WebSocket protocol on ADDR:PORT (or PORT, on
    /// loopback; alone: 127.0.0.1:8765), decimated to --foxglove-rate. See docs/LOGS.md.
    #[arg(long, value_name = "ADDR:PORT", num_args = 0..=1, default_missing_value = "127.0.0.1:8765")]
    pub foxglove: Option<String>,
    /// Let --foxglove listen beyond loopback (e.g. 0.0.0.0:8765): anyone who can reach the machine
    /// can then read the telemetry, the scene and the device files (a warning is printed).
    #[arg(long)]
    pub foxglove_allow_remote: bool,
    /// Rate of the Foxglove live view (Hz, at most 1000).
    #[arg(long, default_value_t = crate::foxglove_live::DEFAULT_LIVE_RATE_HZ, allow_negative_numbers = true)]
    pub foxglove_rate: f64,
    /// Spin before each deadline (µs): the loop sleeps until this long before the deadline, then
    /// busy-waits. Longer spins absorb late wake-ups at the cost of CPU time. Default: 40 % of the
    /// period, at most 400 µs (400 µs at 1 kHz, 40 µs at 10 kHz); see docs/PERFORMANCE.md.
    #[arg(long)]
    pub spin_us: Option<f64>,
    /// Drive a real device even if `haptic2d stability` finds the configuration unstable with the
    /// hand released.
    #[arg(long)]
    pub allow_unstable: bool,
    /// Let `--device udp:ADDR:PORT` be beyond loopback (a warning is printed; the device file
    /// needs a protocol.key_file). Multicast and broadcast addresses are refused regardless.
    #[arg(long)]
    pub allow_remote_device: bool,
    /// The world across a network: `udp:HOST:PORT` of a `haptic2d serve-world SCENE` (docs/TELEOP.md).
    /// This process is then the device side of the split loop (the simulated device and --hand, or
    /// a real device with its --device-file; its local safety and the link's passivity controller);
    /// SCENE is the world side's, not read here.
    #[arg(long, value_name = "udp:HOST:PORT")]
    pub world: Option<String>,
    /// The device side's options (with --world only).
    #[command(
        flatten,
        next_help_heading = "The device side of a split loop (with --world)"
    )]
    pub remote: crate::cmd_remote_device::DeviceSideArgs,
}

/// `--duration` upper bound (s): about 116 days, far beyond any session, and small enough that the
/// deadline count and `Duration` conversions never overflow.
pub const MAX_RUN_DURATION_S: f64 = 1e7;

/// The options of `haptic2d run`, checked: every number in range, every name resolved.
struct RunOptions {
    bind: SocketAddr,
    foxglove: Option<SocketAddr>,
    controller: ControllerKind,
    device: DeviceChoice,
    hand: HandSpec,
}

/// Runs the haptic loop: validate the options, build the rig, start the display and the logger,
/// run the loop until the duration ends, a signal arrives or the tick stops it, then report.
pub fn run(a: &RunArgs) -> Result<Status, Failure> {
    if let Some(split) = split_loop(a) {
        return split;
    }
    let opts = validate_options(a)?;
    let scene = scene_arg::load(&a.scene, Some(a.rate))?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    // A real device's --device-file is its own (e.g. a Haply file): read and checked now, opened
    // after the stability gate.
    let real = opts
        .device
        .load_real(a.device_file.as_deref(), a.allow_remote_device)?;
    let device_setting = match &real {
        Some(r) => device_arg::DeviceSetting {
            params: r.model.twin_params(),
            origin: r.summary.clone(),
        },
        None => device_arg::resolve(a.device_file.as_deref(), &scene, 1.0 / a.rate)?,
    };
    let mut config = HapticConfig {
        device: device_setting.params,
        controller: opts.controller,
        passivity: a.passivity.then(PlanarPassivity::default),
        ..HapticConfig::default()
    };
    // The gains the device will run with (e.g. the Haply twin's θ gains matched to its crank).
    if let Some(m) = real.as_ref().and_then(|r| r.match_controller.as_ref()) {
        config.controller = m(config.controller);
    }
    // A real device only starts with a configuration that is stable with the hand released (§11.4).
    if let (Some(r), false) = (&real, a.allow_unstable) {
        crate::cmd_stability::check_real_device(&r.model, &config, &scene.world)?;
    }
    let scene_name = scene.name.clone();
    let loaded = LoadedScene {
        name: scene.name,
        description: scene.description,
        world: scene.world.clone(),
    };
    let hand_name = match opts.device {
        DeviceChoice::Sim => a.hand.as_deref().unwrap_or("follow").to_string(),
        _ => "-".to_string(),
    };
    let mut rig = match real {
        None => Rig::new(scene.world, &scene.source, config, opts.device, opts.hand)?,
        Some(r) => Rig::with_real(scene.world, &scene.source, config, opts.device, r).map_err(
            |e| match e {
                RealOpenError::Config(m) => Failure::from(m),
                RealOpenError::Open(m) => Failure {
                    status: Status::DeviceLost,
                    message: m,
                },
            },
        )?,
    };

    // The display's controller and scene switches pass the same gate as the start (§11.4).
    if !a.allow_unstable {
        rig.enforce_released_stability();
    }

    // The display: bound before the loop starts, so that a taken port is an error now.
    let (server, view) = if a.headless {
        (None, None)
    } else {
        let (server, view) = run_view::start(opts.bind, &rig, loaded, a.rate, a.require_token)?;
        crate::outln!("{}", server.banner());
        (Some(server), Some(view))
    };
    let scene_meta = run_log::scene_strings(
        &a.scene,
        &scene_name,
        a.device_file.as_deref(),
        &[
            ("rate_hz", a.rate.to_string()),
            ("controller", rig.config.controller.name().to_string()),
            ("device", rig.io.name().to_string()),
            ("hand", hand_name.clone()),
            ("passivity", a.passivity.to_string()),
        ],
    );
    let live_setup = McapSetup::for_world(rig.system.world(), scene_meta.clone(), true);
    let (tx, logger, latest) = start_telemetry(a, rig.system.world(), scene_meta)?;
    let foxglove = match opts.foxglove {
        Some(addr) => Some(start_foxglove(a, addr, latest, live_setup)?),
        None => None,
    };
    let watchdog = make_watchdog(&rig)?;
    let stop = install_stop()?;
    let loop_config = make_loop_config(a)?;
    print_banner(a, &rig, &scene_name, &device_setting.origin, &hand_name);
    // The world's first contact stage before the loop, not in its first tick (a pile:1000's
    // sample 0 builds every contact: about four settled samples).
    rig.system.prime();

    let mut state = LoopState {
        rig: &mut rig,
        view,
        watchdog,
        logging: logger.is_some(),
        capture_world: logger.as_ref().is_some_and(RunLogger::captures_world) || foxglove.is_some(),
        logged: LoggedTick::default(),
        tx,
        end: None,
        worst: WorstStep::default(),
    };
    let summary = crate::rt_thread::run_on_rt_thread(&loop_config, &stop, |info| state.tick(&info));
    // Zero torques before anything else (Ctrl-C, the end of --duration, a failure alike); the port
    // closes when the rig is dropped, after the report.
    state.rig.io.zero_torques();
    let summary = summary?;
    let end = state.end.take();
    let worst = state.worst;
    drop(state);
    if let Some(s) = server {
        s.shutdown();
    }
    if let Some(f) = foxglove {
        crate::outln!("{}", f.shutdown());
    }
    let interrupted = stop.load(Ordering::SeqCst);
    report(a, &rig, &summary, worst, end, interrupted, logger)
}

/// The ticks whose world step the work budgets cut (one world step a tick): the chain damper's
/// (MODELS §6.7), and the impact solver's phases (§7.7, counted in phases, not ticks). Nothing
/// when neither cut.
fn print_budget_cuts(world: &haptic2d::world::World) {
    if let Some(line) = crate::cmd_simulate::chain_budget_line(world) {
        crate::outln!("  {line}");
    }
    let impacts = world.contacts().impact_budget();
    if impacts.phases_cut > 0 || impacts.phases_capped > 0 {
        crate::outln!(
            "  impact solver: {} phases stopped by the sweep budget ([contact] impact_sweeps), {} given fewer sweeps by the sample's row budget ([contact] impact_budget)",
            impacts.phases_cut,
            impacts.phases_capped
        );
    }
}

/// After a host-side stall of a `SCHED_FIFO` loop: whether the kernel's real-time throttling
/// explains it (`haptic2d_rt::throttle`).
fn print_throttle_hint(reason: &SafetyReason, summary: &TimingSummary) {
    let fifo = summary
        .rt
        .as_ref()
        .is_some_and(|r| r.scheduler.is_applied());
    if let SafetyReason::Stall {
        elapsed,
        device_wait,
        ..
    } = reason
    {
        let host = elapsed - device_wait.max(0.0);
        let limit = fifo.then(haptic2d_rt::throttle::rt_limit).flatten();
        if let Some(note) = haptic2d_rt::throttle::hint(host, limit) {
            crate::outln!("{note}");
        }
    }
}

/// The line that starts a run: scene, device and where its parameters came from, controller,
/// hand, rate and duration.
fn print_banner(a: &RunArgs, rig: &Rig, scene_name: &str, origin: &str, hand_name: &str) {
    crate::outln!(
        "running {scene_name}: device {} (parameters: {origin}), controller {}{}, hand {hand_name}, {} Hz{}; Ctrl-C stops",
        rig.io.name(),
        rig.config.controller.name(),
        if a.passivity {
            " + passivity controller"
        } else {
            ""
        },
        a.rate,
        match a.duration {
            Some(d) => format!(" for {d} s"),
            None => String::new(),
        }
    );
}

/// `run --world udp:HOST:PORT`: the device side of a split loop (`cmd_remote_device`); split-loop
/// options without `--world` are refused. `None`: a local run.
fn split_loop(a: &RunArgs) -> Option<Result<Status, Failure>> {
    match &a.world {
        Some(w) => Some(crate::cmd_remote_device::run_from_run(a, w)),
        None if a.remote.any_given() => Some(Err("--key, --push, --link and the other options of a split loop need --world udp:HOST:PORT\n    fix: add --world udp:HOST:PORT (a `haptic2d serve-world`), or leave them out".into())),
        None => None,
    }
}

/// Starts the live Foxglove server on `addr` and prints its banner (and the warning of an address
/// beyond loopback).
fn start_foxglove(
    a: &RunArgs,
    addr: std::net::SocketAddr,
    latest: SnapshotRx<LoggedTick>,
    live_setup: McapSetup,
) -> Result<FoxgloveServer, Failure> {
    let f = FoxgloveServer::start(
        addr,
        latest,
        live_setup,
        a.foxglove_rate,
        a.foxglove_allow_remote,
    )?;
    if let Some(w) = crate::foxglove_live::remote_warning(f.addr()) {
        eprintln!("{w}");
    }
    crate::outln!("{}", f.banner());
    Ok(f)
}

/// Step 1: checks every option before anything starts (errors are bad input).
fn validate_options(a: &RunArgs) -> Result<RunOptions, Failure> {
    check_rate(a.rate)?;
    if let Some(d) = a.duration {
        if !(d.is_finite() && d > 0.0 && d <= MAX_RUN_DURATION_S) {
            return Err(format!(
                "--duration must be a positive number of seconds up to {MAX_RUN_DURATION_S:e}, got {d}\n    fix: e.g. --duration 10, or leave it out to run until Ctrl-C"
            )
            .into());
        }
    }
    let bind: SocketAddr = a.bind.parse().map_err(|e| {
        format!(
            "--bind `{}` is not an ADDRESS:PORT ({e})\n    fix: e.g. --bind 127.0.0.1:8080 or --bind 0.0.0.0:8080",
            a.bind
        )
    })?;
    let foxglove = a.foxglove.as_deref().map(parse_foxglove).transpose()?;
    if let Some(addr) = foxglove {
        crate::foxglove_live::check_address(addr, a.foxglove_allow_remote)?;
    }
    let (controller, _) =
        crate::controller_file::resolve(&a.controller, a.controller_file.as_deref())?;
    let device = DeviceChoice::parse(&a.device)?;
    let hand = match (&device, &a.hand) {
        (DeviceChoice::Replay(_), Some(_)) => {
            return Err(
                "--hand applies to the simulated device only (a replay plays recorded motion)"
                    .into(),
            )
        }
        (d, Some(_)) if d.is_real() => {
            return Err(
                "--hand applies to the simulated device only: on a real device your hand is the hand (give --hand to `haptic2d emulate haply`)"
                    .into(),
            )
        }
        (_, Some(h)) => HandSpec::parse(h)?,
        (_, None) => HandSpec::Follow,
    };
    Ok(RunOptions {
        bind,
        foxglove,
        controller,
        device,
        hand,
    })
}

/// `--foxglove`: `ADDR:PORT`, or a bare `PORT` on loopback.
fn parse_foxglove(s: &str) -> Result<SocketAddr, Failure> {
    if let Ok(port) = s.parse::<u16>() {
        return Ok(SocketAddr::from(([127, 0, 0, 1], port)));
    }
    s.parse().map_err(|e| {
        format!("--foxglove `{s}` is not an ADDRESS:PORT or a PORT ({e})\n    fix: e.g. --foxglove 127.0.0.1:8765")
            .into()
    })
}

/// `--rate`: positive, finite and at most the world's documented maximum rate.
pub(crate) fn check_rate(rate: f64) -> Result<(), Failure> {
    if !(rate.is_finite() && rate > 0.0 && rate <= MAX_RATE_HZ) {
        return Err(format!(
            "--rate must be a positive number of Hz up to {MAX_RATE_HZ:e}, got {rate}\n    fix: e.g. --rate 1000"
        )
        .into());
    }
    Ok(())
}

/// The telemetry ends of a run: producer, logger, latest snapshot.
type Telemetry = (
    TelemetryTx<LoggedTick>,
    Option<RunLogger>,
    SnapshotRx<LoggedTick>,
);

/// Step 2: the telemetry channel, and the logger draining it when `--log` is given (CSV, or MCAP
/// for a `.mcap` file, which also describes `world` and `scene`). The ring holds 2 s of records at
/// the loop rate, at least 4096, and never more than [`MAX_RING_BYTES`] of memory.
fn start_telemetry(
    a: &RunArgs,
    world: &haptic2d::world::World,
    scene: BTreeMap<String, String>,
) -> Result<Telemetry, Failure> {
    let capacity = ring_capacity::<LoggedTick>(a.rate, 2.0, 4096, MAX_RING_BYTES);
    let (tx, rx, latest) = telemetry_channel(capacity, LoggedTick::default())?;
    let logger = match &a.log {
        Some(p) => Some(RunLogger::start(p, rx, world, scene)?),
        None => {
            drop(rx);
            None
        }
    };
    Ok((tx, logger, latest))
}

/// Step 3: the loop's watchdog.
fn make_watchdog(rig: &Rig) -> Result<Watchdog, Failure> {
    // The tick's own latch checks the kinematics, the singularity margin, the workspace bound and
    // stalls; the watchdog adds what only the loop sees (a lost device, missed deadlines) and gets
    // the tick's real margin and closure status (Rig::safety_input).
    Ok(Watchdog::new(rig.watchdog_config())?)
}

/// Step 4: SIGINT and SIGTERM set the stop flag; the loop ends after its current tick.
fn install_stop() -> Result<Arc<AtomicBool>, Failure> {
    Ok(install_stop_signals()?)
}

/// Step 5: the loop's timing.
fn make_loop_config(a: &RunArgs) -> Result<LoopConfig, Failure> {
    let loop_config = LoopConfig {
        rate_hz: a.rate,
        duration: a.duration.map(Duration::from_secs_f64),
        rt: !a.no_rt,
        spin_us: a.spin_us.unwrap_or((0.4e6 / a.rate).min(400.0)),
        ..LoopConfig::default()
    };
    loop_config.validate()?;
    Ok(loop_config)
}

/// Everything one tick touches, owned by the loop thread while it runs.
struct LoopState<'r> {
    rig: &'r mut Rig,
    view: Option<LiveView>,
    watchdog: Watchdog,
    tx: TelemetryTx<LoggedTick>,
    /// True when a logger drains the ring (else only the latest snapshot is kept).
    logging: bool,
    /// True when the telemetry carries the world (bodies, contacts): an MCAP log.
    capture_world: bool,
    /// The record being filled, reused every tick.
    logged: LoggedTick,
    /// Why the tick stopped the loop, if it did.
    end: Option<LoopEnd>,
    /// The slowest world step so far and its stages.
    worst: WorstStep,
}

impl LoopState<'_> {
    /// One tick, timed: the slowest one keeps its world step's stage times ([`WorstStep`]).
    fn tick(&mut self, info: &TickInfo) -> TickControl {
        let start = std::time::Instant::now();
        let control = self.tick_untimed(info);
        let took = start.elapsed();
        self.worst
            .observe(self.rig.system.world(), took, info.index, info.t_s);
        control
    }

    /// One haptic tick: the page's commands, device read, system tick, watchdog, device write,
    /// telemetry, then the display. Allocation-free in steady state.
    fn tick_untimed(&mut self, info: &TickInfo) -> TickControl {
        // The page's commands, between ticks.
        if let Some(v) = self.view.as_mut() {
            v.apply_commands(self.rig);
        }
        let paused = self.view.as_ref().is_some_and(|v| v.paused());
        let (q, lost) = match self.rig.read() {
            Ok(q) => (q, None),
            // A replay's data ended: a clean end, decided before the system runs (a tick on the
            // missing sample's NaN joints would trip the latch with "non-finite device input").
            Err(DeviceError::EndOfData) => {
                self.rig.io.zero_torques();
                self.end = Some(LoopEnd::ReplayEnded);
                return TickControl::Stop;
            }
            Err(e) => ([f64::NAN; 4], Some(e)),
        };
        let out = self.rig.tick_system(&q, info, paused);
        let mut tau = out.torques;
        let safety = self.rig.safety_input(info, &out, lost.is_some());
        let Rig { system, io, .. } = &mut *self.rig;
        let guard = self.watchdog.guard(&safety, &mut tau);
        // A lost reading, or (MODELS §0.5 step 12) a world that diverged in this tick, stops the
        // loop before its torques reach the device.
        if let Some(end) = lost
            .map(LoopEnd::read_failed)
            .or_else(|| LoopEnd::diverged(system.world()))
        {
            io.zero_torques();
            self.end = Some(end);
            return TickControl::Stop;
        }
        if let Err(e) = io.write_torques(&tau) {
            io.zero_torques();
            self.end = Some(LoopEnd::DeviceLost(e.to_string()));
            return TickControl::Stop;
        }
        let mut rec = out.record;
        rec.tau = tau;
        let world = self.capture_world.then(|| system.world());
        self.logged.capture(info, &q, &rec, world);
        if self.logging {
            self.tx.publish(self.logged);
        } else {
            self.tx.set_latest(self.logged);
        }
        if let Some(end) = LoopEnd::after_write(guard, out.tripped) {
            io.zero_torques();
            self.end = Some(end);
            return TickControl::Stop;
        }
        if let Some(v) = self.view.as_mut() {
            v.after_tick(info, self.rig);
        }
        TickControl::Continue
    }
}

/// The exit status of a run that stopped for `end` (`None`: the duration ended, or a signal when
/// `interrupted`), and the "stopped: …" line to print, if any. A stop the tick recorded wins over a
/// signal that arrived in the same tick.
fn end_status(end: Option<&LoopEnd>, interrupted: bool) -> (Status, Option<String>) {
    match end {
        Some(LoopEnd::ReplayEnded) => (Status::Clean, Some("the replay ended".into())),
        Some(LoopEnd::DeviceLost(msg)) => (
            Status::DeviceLost,
            Some(format!("{msg}\n    torques were set to zero and latched")),
        ),
        Some(LoopEnd::Watchdog(msg)) => (Status::SafetyStop, Some(msg.clone())),
        // The latch's own report (`system.safety_trip()`) is printed above.
        Some(LoopEnd::SafetyLatch) => (Status::SafetyStop, None),
        Some(LoopEnd::WorldDiverged(msg)) => (Status::Diverged, Some(msg.clone())),
        None if interrupted => (
            Status::Interrupted,
            Some("interrupted by a signal (SIGINT or SIGTERM)".into()),
        ),
        None => (Status::Clean, None),
    }
}

/// Step 7: prints the timing summary, why the loop stopped, the final state and the log report,
/// and returns the exit status.
fn report(
    a: &RunArgs,
    rig: &Rig,
    summary: &TimingSummary,
    worst: WorstStep,
    end: Option<LoopEnd>,
    interrupted: bool,
    logger: Option<RunLogger>,
) -> Result<Status, Failure> {
    if let Some(w) = summary.rt.as_ref().and_then(|r| r.warning()) {
        eprintln!("{w}");
    }
    crate::outln!("{summary}");
    if let Some(line) = worst.line() {
        crate::outln!("  {line}");
    }
    print_budget_cuts(rig.system.world());
    crate::outln!(
        "on time: {:.3} % of {} deadlines ({} ticks, {} skipped, {} overruns)",
        summary.on_time_fraction * 100.0,
        summary.deadlines,
        summary.ticks,
        summary.skipped,
        summary.overruns
    );
    let system = &rig.system;
    if let Some(trip) = system.safety_trip() {
        // A lost device's last tick runs the system on NaN joints, so the latch trips too; its
        // "non-finite device input" is the lost reading, not a second fault: not printed.
        let lost_reading = matches!(end, Some(LoopEnd::DeviceLost(_)))
            && matches!(trip.reason, SafetyReason::Device(DeviceFault::NonFinite));
        if !lost_reading {
            crate::outln!("{trip}");
        }
        print_throttle_hint(&trip.reason, summary);
    }
    let (status, why) = end_status(end.as_ref(), interrupted);
    if let Some(why) = why {
        crate::outln!("stopped: {why}");
    }
    let w = system.world();
    let b = &w.bodies[system.slave()];
    crate::outln!(
        "final: t = {:.3} s, {} at ({:.5} m, {:.5} m, {:.4} rad), {} contacts, kinetic {:.3e} J",
        w.time(),
        b.name,
        b.pose.pos.x,
        b.pose.pos.y,
        b.pose.angle,
        w.contacts().contact_count(),
        w.ledger().kinetic
    );
    if let Some(l) = logger {
        let report = l.finish(summary).map_err(Failure::error)?;
        crate::outln!(
            "{report} to {}",
            a.log
                .as_ref()
                .map_or(String::new(), |p| p.display().to_string())
        );
    }
    Ok(status)
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic2d_rt::DeviceIo;

    /// A device that answers `good` reads, then reports itself lost.
    struct Flaky {
        good: u32,
        q: [f64; 4],
        zeroed: bool,
    }

    impl DeviceIo for Flaky {
        fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
            if self.good == 0 {
                return Err(DeviceError::Lost("USB cable pulled".into()));
            }
            self.good -= 1;
            Ok(self.q)
        }
        fn write_torques(&mut self, _tau: &[f64; 4]) -> Result<(), DeviceError> {
            Ok(())
        }
        fn zero_torques(&mut self) {
            self.zeroed = true;
        }
        fn name(&self) -> &str {
            "flaky"
        }
    }

    fn state_with(rig: &mut Rig) -> LoopState<'_> {
        let (tx, _rx, _latest) = telemetry_channel(16, LoggedTick::default()).unwrap();
        let watchdog = make_watchdog(rig).unwrap();
        LoopState {
            rig,
            view: None,
            watchdog,
            tx,
            logging: false,
            capture_world: false,
            logged: LoggedTick::default(),
            end: None,
            worst: WorstStep::default(),
        }
    }

    fn info(index: u64) -> TickInfo {
        TickInfo {
            index,
            deadline_index: index,
            t_s: index as f64 * 1e-3,
            period_s: 1e-3,
            period_ns: 1_000_000,
            lateness_ns: 0,
            skipped: 0,
            deadline_ns: 0,
        }
    }

    #[test]
    fn a_lost_device_stops_the_loop_with_exit_status_4() {
        let scene = scene_arg::load("box-in-walls", Some(1000.0)).unwrap();
        let config = HapticConfig::default();
        let mut rig = Rig::new(
            scene.world,
            &scene.source,
            config,
            DeviceChoice::Sim,
            HandSpec::Follow,
        )
        .unwrap();
        // The simulated device's own start pose, read twice, then lost.
        let q = rig.io.read_encoders().unwrap();
        rig.io = Box::new(Flaky {
            good: 2,
            q,
            zeroed: false,
        });
        let mut state = state_with(&mut rig);
        assert_eq!(state.tick(&info(0)), TickControl::Continue);
        assert_eq!(state.tick(&info(1)), TickControl::Continue);
        assert_eq!(state.tick(&info(2)), TickControl::Stop);
        let end = state.end.take();
        assert!(matches!(&end, Some(LoopEnd::DeviceLost(m)) if m.contains("USB cable pulled")));
        let (status, why) = end_status(end.as_ref(), false);
        assert_eq!(status, Status::DeviceLost);
        assert_eq!(status.code(), 4);
        assert!(why.unwrap().contains("device lost"));
    }

    /// A device that answers every read and counts the writes and zeroings it gets.
    struct Counting {
        q: [f64; 4],
        writes: std::sync::Arc<std::sync::atomic::AtomicU32>,
        zeroed: std::sync::Arc<std::sync::atomic::AtomicBool>,
    }

    impl DeviceIo for Counting {
        fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
            Ok(self.q)
        }
        fn write_torques(&mut self, _tau: &[f64; 4]) -> Result<(), DeviceError> {
            self.writes
                .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            Ok(())
        }
        fn zero_torques(&mut self) {
            self.zeroed
                .store(true, std::sync::atomic::Ordering::Relaxed);
        }
        fn name(&self) -> &str {
            "counting"
        }
    }

    #[test]
    fn a_world_that_diverges_stops_the_loop_before_its_torques_are_written_with_status_6() {
        use std::sync::atomic::Ordering::Relaxed;
        let scene = scene_arg::load("box-in-walls", Some(1000.0)).unwrap();
        let mut rig = Rig::new(
            scene.world,
            &scene.source,
            HapticConfig::default(),
            DeviceChoice::Sim,
            HandSpec::Follow,
        )
        .unwrap();
        let q = rig.io.read_encoders().unwrap();
        let writes = std::sync::Arc::new(std::sync::atomic::AtomicU32::new(0));
        let zeroed = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        rig.io = Box::new(Counting {
            q,
            writes: writes.clone(),
            zeroed: zeroed.clone(),
        });
        let slave = rig
            .system
            .world()
            .bodies
            .iter()
            .position(|b| b.is_dynamic())
            .unwrap();
        let mut state = state_with(&mut rig);
        assert_eq!(state.tick(&info(0)), TickControl::Continue);
        assert_eq!(writes.load(Relaxed), 1);
        // A non-finite slave velocity: the world's own check (MODELS §0.5 step 12) stops it.
        state.rig.system.world_mut().bodies[slave].vel.x = f64::NAN;
        assert_eq!(state.tick(&info(1)), TickControl::Stop);
        assert_eq!(
            writes.load(Relaxed),
            1,
            "no torques written after the divergence"
        );
        assert!(zeroed.load(Relaxed), "the torques were zeroed");
        let end = state.end.take();
        let (status, why) = end_status(end.as_ref(), false);
        assert_eq!(status, Status::Diverged);
        assert_eq!(status.code(), 6);
        let why = why.unwrap();
        assert!(
            why.contains("the world diverged") && why.contains("vx = NaN"),
            "{why}"
        );
    }

    #[test]
    fn every_way_a_run_ends_has_its_documented_status() {
        let cases = [
            (Some(LoopEnd::ReplayEnded), false, 0),
            (Some(LoopEnd::DeviceLost("x".into())), false, 4),
            (Some(LoopEnd::Watchdog("x".into())), false, 3),
            (Some(LoopEnd::SafetyLatch), false, 3),
            // A safety stop in the tick the signal arrived is still a safety stop.
            (Some(LoopEnd::SafetyLatch), true, 3),
            (Some(LoopEnd::WorldDiverged("x".into())), false, 6),
            (None, true, 130),
            (None, false, 0),
        ];
        for (end, interrupted, code) in cases {
            assert_eq!(end_status(end.as_ref(), interrupted).0.code(), code);
        }
    }
}
