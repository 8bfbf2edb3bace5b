//! `haptic2d run --device haply:PATH|haply:auto`: the haptic loop on a Haply board (a 2DIY, or the
//! twin pantograph of two 2DIY linkages), headless. Same loop as the simulated device, plus what
//! hardware needs: the handshake before the first deadline, zero torques until the first valid reply
//! and the start-up ramp, the watchdog's missed-deadline limit, a lost device → latch, zero torques
//! sent, exit 4 with a message naming the device and what to check; Ctrl-C → zero torques before the
//! port closes, exit 130.

use crate::cmd_run::RunArgs;
use crate::haply_arg::{exit, fail, load_file, port_of};
use crate::scene_arg;
use haptic2d::haptic::{ControllerKind, TickRecord};
use haptic2d_devices::haply::serial::open_port;
use haptic2d_devices::haply::{HaplyDevice, HaplyKind, HaplySystem};
use haptic2d_rt::signal::install_ctrlc_stop;
use haptic2d_rt::{
    run_loop, telemetry_channel, CsvLogger, DeviceIo, LoggerConfig, LoopConfig, SafetyInput,
    TickControl, TickInterval, Watchdog, WatchdogConfig,
};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// How the loop ended.
enum End {
    Lost(String),
    Tripped(String),
}

/// Runs the loop on a Haply board.
pub fn run(a: &RunArgs) -> ExitCode {
    match run_inner(a) {
        Ok(code) => ExitCode::from(code),
        Err((code, msg)) => fail(code, &msg),
    }
}

fn run_inner(a: &RunArgs) -> Result<u8, (u8, String)> {
    let bad = |m: String| (exit::BAD_INPUT, m);
    if !(a.rate.is_finite() && a.rate > 0.0) {
        return Err(bad(format!(
            "--rate must be a positive number of Hz, got {}",
            a.rate
        )));
    }
    if let Some(d) = a.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(bad(format!(
                "--duration must be a positive number of seconds, got {d}"
            )));
        }
    }
    if a.hand.is_some() {
        return Err(bad(
            "--hand applies to the simulated device only: on a Haply board your hand is the hand (give --hand to `haptic2d emulate haply`)".into(),
        ));
    }
    if a.passivity {
        return Err(bad(
            "--passivity is not available with a Haply device yet".into()
        ));
    }
    let controller =
        ControllerKind::from_name(&a.controller).map_err(|e| bad(format!("--controller: {e}")))?;
    let file = load_file(a.device_file.as_deref()).map_err(bad)?;
    let path = port_of(&a.device, &file).map_err(bad)?;
    let scene = scene_arg::load(&a.scene, Some(a.rate)).map_err(bad)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let scene_name = scene.name.clone();
    let mut system = HaplySystem::new(scene.world, &file, controller, [0.0; 2])
        .map_err(|e| bad(format!("scene {} with {}: {e}", scene.source, file.source)))?;
    if !a.headless {
        eprintln!(
            "note: the live display is not available with a Haply device yet; running headless"
        );
    }

    // Open and hand-shake before the first deadline.
    let period = Duration::from_secs_f64(1.0 / a.rate);
    let name = format!("haply:{path}");
    let port = open_port(&path).map_err(|e| (exit::DEVICE_LOST, e))?;
    let mut dev =
        HaplyDevice::open(port, &file, period, &name).map_err(|e| (exit::DEVICE_LOST, e))?;

    let capacity = ((a.rate * 2.0) as usize).max(4096);
    let (mut tx, rx, _latest) =
        telemetry_channel(capacity, TickRecord::default()).map_err(|e| (exit::ERROR, e))?;
    let logger = match &a.log {
        Some(p) => Some(
            CsvLogger::spawn_file(rx, p, LoggerConfig::default()).map_err(|e| (exit::ERROR, e))?,
        ),
        None => {
            drop(rx);
            None
        }
    };
    let logging = logger.is_some();
    // Hardware: the watchdog's missed-deadline limit stays on (board.max_missed_deadlines,
    // default 10 consecutive misses).
    let mut watchdog = Watchdog::new(WatchdogConfig {
        min_singularity_margin: 0.0,
        max_missed_run: file.max_missed_deadlines,
        // The stall check stays off here: a read blocks up to the device file's timeout, which
        // is the lost-device path (exit 4); the board's missed-deadline limit still applies.
        max_stall_periods: None,
    })
    .map_err(|e| (exit::ERROR, e))?;
    let stop = install_ctrlc_stop().map_err(|e| (exit::ERROR, e))?;
    let loop_config = LoopConfig {
        rate_hz: a.rate,
        duration: a.duration.map(Duration::from_secs_f64),
        rt: !a.no_rt,
        spin_us: a.spin_us.unwrap_or((0.4e6 / a.rate).min(400.0)),
        ..LoopConfig::default()
    };
    loop_config.validate().map_err(bad)?;
    let kind = match file.kind {
        HaplyKind::TwoDiy { .. } => "2-DOF 2DIY",
        HaplyKind::Twin(_) => "twin pantograph",
    };
    println!(
        "running {scene_name}: device {name} ({}, {kind}, torque limit {} N·m), controller {}, {} Hz{}; Ctrl-C stops",
        file.source,
        file.torque_limit,
        controller.name(),
        a.rate,
        a.duration.map_or(String::new(), |d| format!(" for {d} s"))
    );

    let mut ended: Option<End> = None;
    let mut interval = TickInterval::new();
    let summary = run_loop(&loop_config, &stop, |info| {
        // Wake-to-wake interval: the watchdog trips on a stall longer than max_stall_periods.
        let elapsed_periods = interval.update(&info) as f64 / info.period_ns as f64;
        let q = match dev.read_encoders() {
            Ok(q) => q,
            Err(e) => {
                let mut tau = [0.0; 4];
                let _ = watchdog.guard(
                    &SafetyInput {
                        device_lost: true,
                        ..SafetyInput::nominal(info.index)
                    },
                    &mut tau,
                );
                dev.zero_torques();
                ended = Some(End::Lost(e.to_string()));
                return TickControl::Stop;
            }
        };
        let out = system.tick(&q);
        let mut tau = out.torques;
        let guard = watchdog.guard(
            &SafetyInput {
                deadline_missed: info.missed_deadline(),
                pose: out.record.x_m,
                elapsed_periods,
                ..SafetyInput::nominal(info.index)
            },
            &mut tau,
        );
        if let Err(e) = dev.write_torques(&tau) {
            dev.zero_torques();
            ended = Some(End::Lost(e.to_string()));
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
            dev.zero_torques();
            ended = Some(End::Tripped(f.to_string()));
            return TickControl::Stop;
        }
        if out.tripped {
            dev.zero_torques();
            ended = Some(End::Tripped(system.trip().unwrap_or_default()));
            return TickControl::Stop;
        }
        TickControl::Continue
    })
    .map_err(|e| (exit::ERROR, e))?;
    // Zero torques before the port closes (Ctrl-C and the end of --duration alike).
    dev.zero_torques();
    drop(dev);
    drop(tx);

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
    let w = system.world();
    let b = &w.bodies[system.slave()];
    println!(
        "final: t = {:.3} s, {} at ({:.5} m, {:.5} m, {:.4} rad), {} contacts",
        w.time(),
        b.name,
        b.pose.pos.x,
        b.pose.pos.y,
        b.pose.angle,
        w.contacts().contact_count()
    );
    if let Some(l) = logger {
        let report = l.finish().map_err(|e| (exit::ERROR, e))?;
        println!(
            "{report} to {}",
            a.log
                .as_ref()
                .map_or(String::new(), |p| p.display().to_string())
        );
    }
    match ended {
        Some(End::Lost(m)) => Err((
            exit::DEVICE_LOST,
            format!("{m}\n    torques were set to zero and latched"),
        )),
        Some(End::Tripped(m)) => {
            println!("stopped: {m}");
            Ok(exit::SAFETY_STOP)
        }
        None if stop.load(Ordering::Relaxed) => {
            println!("stopped: interrupted (torques zeroed before the port closed)");
            Ok(exit::INTERRUPTED)
        }
        None => Ok(exit::CLEAN),
    }
}
