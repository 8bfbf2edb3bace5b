//! `haptic2d run --device udp:ADDR:PORT [--device-file FILE]`: the haptic loop on a device that
//! speaks the open UDP protocol (docs/DEVICE-PROTOCOL.md), headless. The device listens at
//! ADDR:PORT; the device file (default: the reference pantograph, devices/udp-pantograph.toml)
//! says whether joints or a pose come in and which linkage applies. The system is the 2-DOF
//! pantograph system (the Haply 2DIY's); the loop is the Haply loop's: open before the first
//! deadline, zero torques until the first state and the start-up ramp, the watchdog's
//! missed-deadline limit, a lost device → latch, zero command sent, exit 4 naming the device;
//! Ctrl-C → a zero command, exit 130. At exit it prints the network counters (the round trip is
//! measured by `haptic2d-devices`' `udp_roundtrip` example, docs/PERFORMANCE.md).

use crate::cmd_run::RunArgs;
use crate::haply_arg::{exit, fail};
use crate::scene_arg;
use haptic2d::haptic::planar2::{Planar2Config, Planar2System};
use haptic2d::haptic::{ControllerKind, TickRecord};
use haptic2d_devices::udp::{UdpDevice, UdpDeviceFile};
use haptic2d_rt::signal::install_ctrlc_stop;
use haptic2d_rt::{
    run_loop, telemetry_channel, CsvLogger, DeviceIo, LoggerConfig, LoopConfig, SafetyInput,
    TickControl, TickInterval, Watchdog, WatchdogConfig,
};
use std::net::{SocketAddr, ToSocketAddrs};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// How the loop ended.
enum End {
    Lost(String),
    Tripped(String),
}

/// The device address of `udp:ADDR:PORT` (a name is resolved once, here).
pub fn address_of(device: &str) -> Result<SocketAddr, String> {
    let rest = device.strip_prefix("udp:").unwrap_or(device);
    let hint =
        "expected udp:ADDR:PORT, e.g. udp:127.0.0.1:5005 (the address the device listens at)";
    if rest.is_empty() {
        return Err(format!("--device `{device}`: {hint}"));
    }
    if let Ok(a) = rest.parse::<SocketAddr>() {
        return Ok(a);
    }
    rest.to_socket_addrs()
        .map_err(|e| format!("--device `{device}`: {e}; {hint}"))?
        .next()
        .ok_or_else(|| format!("--device `{device}`: no address; {hint}"))
}

/// Runs the loop on a UDP device.
pub fn run(a: &RunArgs) -> ExitCode {
    match run_inner(a) {
        Ok(code) => ExitCode::from(code),
        Err((code, msg)) => fail(code, &msg),
    }
}

fn run_inner(a: &RunArgs) -> Result<u8, (u8, String)> {
    let bad = |m: String| (exit::BAD_INPUT, m);
    if !(a.rate.is_finite() && a.rate > 0.0 && a.rate <= 20_000.0) {
        return Err(bad(format!(
            "--rate must be a number of Hz in (0, 20000], got {}",
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
        return Err(bad("--hand applies to the simulated device only: on a UDP device the device's hand is the hand (sim_device.py has --push)".into()));
    }
    if a.passivity {
        return Err(bad(
            "--passivity is not available with a UDP device yet".into()
        ));
    }
    let controller =
        ControllerKind::from_name(&a.controller).map_err(|e| bad(format!("--controller: {e}")))?;
    let addr = address_of(&a.device).map_err(bad)?;
    let file = match &a.device_file {
        Some(p) => UdpDeviceFile::from_path(p).map_err(bad)?,
        None => UdpDeviceFile::reference(),
    };
    let scene = scene_arg::load(&a.scene, Some(a.rate)).map_err(bad)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let scene_name = scene.name.clone();
    let mut config = Planar2Config::new(file.linkage, file.torque_limit);
    config.controller = controller;
    let mut system = Planar2System::new(scene.world, config)
        .map_err(|e| bad(format!("scene {} with {}: {e}", scene.source, file.source)))?;
    if !a.headless {
        eprintln!(
            "note: the live display is not available with a UDP device yet; running headless"
        );
    }

    // Open before the first deadline.
    let period = Duration::from_secs_f64(1.0 / a.rate);
    let name = format!("udp:{addr}");
    let mut dev =
        UdpDevice::open(addr, &file, period, &name).map_err(|e| (exit::DEVICE_LOST, e))?;

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
    // A late answer is the network's, counted by the transport; a lost device is the timeout's
    // (exit 4); the missed-deadline limit of the device file stays on.
    let mut watchdog = Watchdog::new(WatchdogConfig {
        min_singularity_margin: 0.0,
        max_missed_run: file.max_missed_deadlines,
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
    println!(
        "running {scene_name}: device {name} ({}, {} in, {} out, torque limit {} N·m), controller {}, {} Hz{}; Ctrl-C stops",
        file.source,
        if file.pose_input { "pose" } else { "joints" },
        if file.wrench_output { "wrench" } else { "torques" },
        file.torque_limit,
        controller.name(),
        a.rate,
        a.duration.map_or(String::new(), |d| format!(" for {d} s"))
    );

    let mut ended: Option<End> = None;
    let mut interval = TickInterval::new();
    let summary = run_loop(&loop_config, &stop, |info| {
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
        let out = system.tick(&[q[0], q[1]]);
        let mut tau = out.record.tau;
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
            ended = Some(End::Tripped(
                system
                    .safety_trip()
                    .map(|t| t.to_string())
                    .unwrap_or_default(),
            ));
            return TickControl::Stop;
        }
        TickControl::Continue
    })
    .map_err(|e| (exit::ERROR, e))?;
    dev.zero_torques();
    let counters = *dev.counters();
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
    println!("udp: {counters}");
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
            println!("stopped: interrupted (a zero command was sent)");
            Ok(exit::INTERRUPTED)
        }
        None => Ok(exit::CLEAN),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn udp_addresses_parse_and_bad_ones_say_the_form() {
        assert_eq!(
            address_of("udp:127.0.0.1:5005").unwrap(),
            "127.0.0.1:5005".parse::<SocketAddr>().unwrap()
        );
        assert!(address_of("udp:[::1]:5005").unwrap().is_ipv6());
        let e = address_of("udp:").unwrap_err();
        assert!(e.contains("udp:ADDR:PORT"), "{e}");
        let e = address_of("udp:127.0.0.1").unwrap_err();
        assert!(e.contains("udp:ADDR:PORT"), "{e}");
    }
}
