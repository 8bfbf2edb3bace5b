//! `haptic2d run`: the haptic loop — device, controller and world at the control rate on a real-time
//! thread, with CSV logging on another thread, the live display in the browser (unless
//! `--headless`), and a timing summary at exit.

use crate::device_arg;
use crate::hand_arg::HandSpec;
use crate::run_rig::{DeviceChoice, Rig};
use crate::run_view::{self, LoadedScene};
use crate::scene_arg;
use haptic2d::control::passivity::PlanarPassivity;
use haptic2d::haptic::{ControllerKind, HapticConfig, TickRecord};
use haptic2d_rt::signal::install_ctrlc_stop;
use haptic2d_rt::{
    run_loop, telemetry_channel, CsvLogger, DeviceError, LoggerConfig, LoopConfig, SafetyInput,
    TickControl, Watchdog, WatchdogConfig,
};
use std::net::SocketAddr;
use std::path::PathBuf;
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
    /// Teleoperation controller: four-channel or coupling.
    #[arg(long, default_value = "four-channel")]
    pub controller: String,
    /// Passivity observer/controller on the device port (§12).
    #[arg(long)]
    pub passivity: bool,
    /// Simulated hand (simulated device only): follow | free | constant:FX,FY,TAU |
    /// sine:FPK,FREQ[,DIRX,DIRY] | script:HOLD,FX,FY,TAU,PUSH[,RFX,RFY,RTAU]. Default: follow.
    #[arg(long, allow_hyphen_values = true)]
    pub hand: Option<String>,
    /// Device: sim (simulated twin pantograph), replay:FILE.csv (recorded encoders q1..q4, rad),
    /// haply:PATH or haply:auto (a Haply board; --device-file a Haply device file, headless).
    #[arg(long, default_value = "sim")]
    pub device: String,
    /// Device parameters (TOML: top-level fields or a [device] table; template:
    /// devices/twin-pantograph.toml). Wins over the scene's [device] table; fields left out keep
    /// the spec defaults. Used by the simulated device and to read a replay's encoders.
    #[arg(long, value_name = "FILE.toml")]
    pub device_file: Option<PathBuf>,
    /// Write every tick's record to this CSV file.
    #[arg(long)]
    pub log: Option<PathBuf>,
    /// Address of the live display (open http://ADDR:PORT/ in a browser). Bound to a non-loopback
    /// address, commands from the page need the token printed at startup.
    #[arg(long, default_value = "127.0.0.1:8080")]
    pub bind: String,
    /// Real-time scheduling (SCHED_FIFO, mlockall, core pinning) — the default; where it is not
    /// permitted the loop says so in one line and runs with normal scheduling.
    #[arg(long, overrides_with = "no_rt")]
    pub rt: bool,
    /// Normal scheduling: do not ask for real-time privileges.
    #[arg(long, overrides_with = "rt")]
    pub no_rt: bool,
    /// Spin before each deadline (µs): the loop sleeps until this long before the deadline, then
    /// busy-waits. Longer spins absorb late wake-ups at the cost of CPU time. Default: 40 % of the
    /// period, at most 400 µs (400 µs at 1 kHz, 40 µs at 10 kHz); see docs/PERFORMANCE.md.
    #[arg(long)]
    pub spin_us: Option<f64>,
}

/// Runs the haptic loop.
pub fn run(a: &RunArgs) -> Result<(), String> {
    // Validate every option before anything starts.
    if !(a.rate.is_finite() && a.rate > 0.0) {
        return Err(format!(
            "--rate must be a positive number of Hz, got {}",
            a.rate
        ));
    }
    if let Some(d) = a.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(format!(
                "--duration must be a positive number of seconds, got {d}"
            ));
        }
    }
    let bind: SocketAddr = a.bind.parse().map_err(|e| {
        format!(
            "--bind `{}` is not an ADDRESS:PORT ({e})\n    fix: e.g. --bind 127.0.0.1:8080 or --bind 0.0.0.0:8080",
            a.bind
        )
    })?;
    let controller =
        ControllerKind::from_name(&a.controller).map_err(|e| format!("--controller: {e}"))?;
    let device = DeviceChoice::parse(&a.device)?;
    let hand = match (&device, &a.hand) {
        (DeviceChoice::Replay(_), Some(_)) => {
            return Err(
                "--hand applies to the simulated device only (a replay plays recorded motion)"
                    .into(),
            )
        }
        (_, Some(h)) => HandSpec::parse(h)?,
        (_, None) => HandSpec::Follow,
    };
    let scene = scene_arg::load(&a.scene, Some(a.rate))?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let device_setting = device_arg::resolve(a.device_file.as_deref(), &scene, 1.0 / a.rate)?;
    let config = HapticConfig {
        device: device_setting.params,
        controller,
        passivity: a.passivity.then(PlanarPassivity::default),
        ..HapticConfig::default()
    };
    let scene_name = scene.name.clone();
    let loaded = LoadedScene {
        name: scene.name,
        description: scene.description,
        world: scene.world.clone(),
    };
    let hand_name = match device {
        DeviceChoice::Sim => a.hand.as_deref().unwrap_or("follow").to_string(),
        DeviceChoice::Replay(_) => "-".to_string(),
    };
    let mut rig = Rig::new(scene.world, &scene.source, config, device, hand)?;

    // The display: bound before the loop starts, so that a taken port is an error now.
    let (server, mut view) = if a.headless {
        (None, None)
    } else {
        let (server, view) = run_view::start(bind, &rig, loaded, a.rate)?;
        println!("{}", server.banner());
        (Some(server), Some(view))
    };

    // Telemetry: every record to the logger (if any).
    let capacity = ((a.rate * 2.0) as usize).max(4096);
    let (mut tx, rx, _latest) = telemetry_channel(capacity, TickRecord::default())?;
    let logger = match &a.log {
        Some(p) => Some(CsvLogger::spawn_file(rx, p, LoggerConfig::default())?),
        None => {
            drop(rx);
            None
        }
    };
    let logging = logger.is_some();
    let mut watchdog = Watchdog::new(WatchdogConfig {
        // The tick's own safety latch checks the kinematics and the singularity margin; this one
        // adds what only the loop sees: a lost device and missed deadlines.
        // A simulated or replayed device does not move between ticks, so a late tick cannot hurt
        // anyone: missed deadlines are counted in the summary but do not stop the run. (A hardware
        // driver will keep the default limit of 10 consecutive misses.)
        min_singularity_margin: 0.0,
        max_missed_run: None,
    })?;
    let stop = install_ctrlc_stop()?;
    let loop_config = LoopConfig {
        rate_hz: a.rate,
        duration: a.duration.map(Duration::from_secs_f64),
        rt: !a.no_rt,
        spin_us: a.spin_us.unwrap_or((0.4e6 / a.rate).min(400.0)),
        ..LoopConfig::default()
    };
    loop_config.validate()?;
    println!(
        "running {scene_name}: device {} (parameters: {}), controller {}{}, hand {hand_name}, {} Hz{}; Ctrl-C stops",
        rig.io.name(),
        device_setting.origin,
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

    // The loop, on its own thread; everything it touches is moved in and handed back at the end.
    let mut ended: Option<String> = None;
    let summary = std::thread::scope(|s| {
        let handle = std::thread::Builder::new()
            .name("haptic2d-rt".into())
            .spawn_scoped(s, || {
                run_loop(&loop_config, &stop, |info| {
                    // The page's commands, between ticks.
                    if let Some(v) = view.as_mut() {
                        v.apply_commands(&mut rig);
                    }
                    let Rig { system, io, .. } = &mut rig;
                    let (q, lost) = match io.read_encoders() {
                        Ok(q) => (q, None),
                        Err(e) => ([f64::NAN; 4], Some(e)),
                    };
                    let out = if view.as_ref().is_some_and(|v| v.paused()) {
                        system.tick_paused(&q)
                    } else {
                        system.tick(&q)
                    };
                    let mut tau = out.torques;
                    let safety = SafetyInput {
                        deadline_missed: info.missed_deadline(),
                        device_lost: lost.is_some(),
                        pose: if lost.is_some() {
                            [0.0; 3]
                        } else {
                            out.record.x_m
                        },
                        ..SafetyInput::nominal(info.index)
                    };
                    let guard = watchdog.guard(&safety, &mut tau);
                    if let Some(e) = lost {
                        io.zero_torques();
                        ended = Some(match e {
                            DeviceError::EndOfData => "the replay ended".to_string(),
                            e => e.to_string(),
                        });
                        return TickControl::Stop;
                    }
                    if let Err(e) = io.write_torques(&tau) {
                        io.zero_torques();
                        ended = Some(e.to_string());
                        return TickControl::Stop;
                    }
                    let mut rec = out.record;
                    rec.tau = tau;
                    if logging {
                        tx.publish(rec);
                    } else {
                        tx.set_latest(rec);
                    }
                    if let Err(f) = guard {
                        io.zero_torques();
                        ended = Some(f.to_string());
                        return TickControl::Stop;
                    }
                    if out.tripped {
                        io.zero_torques();
                        return TickControl::Stop;
                    }
                    if let Some(v) = view.as_mut() {
                        v.after_tick(&info, &rig);
                    }
                    TickControl::Continue
                })
            })
            .map_err(|e| format!("cannot start the real-time loop thread: {e}"))?;
        handle
            .join()
            .map_err(|_| "the real-time loop thread panicked".to_string())?
    })?;
    drop(tx);
    drop(view);
    if let Some(s) = server {
        s.shutdown();
    }

    // Report.
    if let Some(w) = summary.rt.as_ref().and_then(|r| r.warning()) {
        eprintln!("{w}");
    }
    println!("{summary}");
    println!(
        "on time: {:.3} % of {} deadlines ({} ticks, {} skipped, {} overruns)",
        summary.on_time_fraction * 100.0,
        summary.deadlines,
        summary.ticks,
        summary.skipped,
        summary.overruns
    );
    let system = &rig.system;
    if let Some(trip) = system.safety_trip() {
        println!("{trip}");
    }
    if let Some(msg) = &ended {
        println!("stopped: {msg}");
    }
    let w = system.world();
    let b = &w.bodies[system.slave()];
    println!(
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
        let report = l.finish()?;
        println!(
            "{report} to {}",
            a.log
                .as_ref()
                .map_or(String::new(), |p| p.display().to_string())
        );
    }
    Ok(())
}
