//! `haptic2d emulate haply`: a stand-in Haply board on a pseudo-terminal. The first line of standard
//! output is `pty: PATH`; a host (`haptic2d run --device haply:PATH`) opens PATH like the board's
//! serial port. The emulated board moves a simulated linkage under the motor torques and a simulated
//! hand until Ctrl-C (or `--duration`).
//!
//! `haptic2d emulate inverse3 [--bind 127.0.0.1:PORT]`: a stand-in for Haply's Inverse Service on
//! loopback (default `127.0.0.1:10001`, the service's own port; port 0 picks a free one). The first
//! line of standard output is `listening: http://ADDR:PORT`; a host runs
//! `haptic2d run --device inverse3:http://ADDR:PORT`. It moves a simulated 3-DOF device (mass and
//! damping per axis) under the commanded force and a simulated hand.

use crate::hand_arg::HandSpec;
use crate::haply_arg::{exit, fail, load_file};
use haptic2d_devices::haply::serial::Pty;
use haptic2d_devices::haply::{
    emulator, serve, BoardKind, EmulatorClock, EmulatorConfig, HaplyKind,
};
use haptic2d_rt::signal::install_ctrlc_stop;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// Options of `haptic2d emulate`.
#[derive(clap::Args, Debug)]
pub struct EmulateArgs {
    /// What to emulate: haply | inverse3.
    pub target: String,
    /// inverse3: the address to listen at (loopback by default; port 0 = any free port).
    #[arg(long, default_value = "127.0.0.1:10001")]
    pub bind: String,
    /// The board's wiring and linkage (a Haply device file, or haply-2diy-gen3 | haply-2diy-gen2 |
    /// haply-twin). Default haply-2diy-gen3.
    #[arg(long, value_name = "FILE.toml")]
    pub device_file: Option<PathBuf>,
    /// Simulated hand: follow (hold the start point) | free | constant:FX,FY,TAU |
    /// sine:FPK,FREQ[,DIRX,DIRY] | script:HOLD,FX,FY,TAU,PUSH[,RFX,RFY,RTAU]. Default follow.
    /// inverse3: follow | free | push:FX,FY,FZ[,HOLD].
    #[arg(long, allow_hyphen_values = true)]
    pub hand: Option<String>,
    /// Where the handle is when the host sets the board up, X,Y (m, the device file's frame).
    /// Default the device file's rest pose (the offsets' pose), where a user holds it when `run`
    /// starts: the stock firmware reports the offsets there, wherever the handle really is.
    /// inverse3: X,Y,Z of the cursor (m, device frame), default 0,0,0.
    #[arg(long, allow_hyphen_values = true)]
    pub start: Option<String>,
    /// haply: the board, m3 (4 ports) or m0 (2 ports: a setup naming ports 3–4 gets short replies).
    #[arg(long, default_value = "m3")]
    pub board: String,
    /// haply: where the handle was when the board was powered, X,Y (m). It does not change what the
    /// board reports (the encoders are set at every setup); default the start point.
    #[arg(long, allow_hyphen_values = true)]
    pub power_up: Option<String>,
    /// Service time of the board (µs), at least 50.
    #[arg(long, default_value_t = 50.0)]
    pub service_us: f64,
    /// Stop after this many seconds (default: until Ctrl-C).
    #[arg(long)]
    pub duration: Option<f64>,
    /// Hand damping (N·s/m) added to the hand model.
    #[arg(long, default_value_t = 2.0)]
    pub hand_damping: f64,
    /// inverse3: report a VerseGrip turning about the device's z axis at this rate (rad/s, from
    /// angle 0 at the start); the loop turns the slave with it. Default: no VerseGrip.
    #[arg(long, allow_hyphen_values = true)]
    pub grip_rate: Option<f64>,
    /// inverse3: a fault of the service, for tests: every state after the first N lacks the
    /// cursor position (the driver must treat it as a lost device).
    #[arg(long, value_name = "N")]
    pub drop_position_after: Option<u64>,
}

/// Runs the emulator.
pub fn run(a: &EmulateArgs) -> ExitCode {
    match run_inner(a) {
        Ok(code) => ExitCode::from(code),
        Err((code, msg)) => fail(code, &msg),
    }
}

fn run_inner(a: &EmulateArgs) -> Result<u8, (u8, String)> {
    let bad = |m: String| (exit::BAD_INPUT, m);
    if a.target == "inverse3" {
        return run_inverse3(a);
    }
    if a.target != "haply" {
        return Err(bad(format!(
            "emulate `{}`: no such emulator\n    fix: haptic2d emulate haply | haptic2d emulate inverse3",
            a.target
        )));
    }
    if !(a.service_us.is_finite() && a.service_us >= 50.0) {
        return Err(bad(format!(
            "--service-us {}: the board's service time is at least 50 µs",
            a.service_us
        )));
    }
    if !(a.hand_damping.is_finite() && a.hand_damping >= 0.0) {
        return Err(bad("--hand-damping must be ≥ 0 N·s/m".into()));
    }
    let file = load_file(a.device_file.as_deref()).map_err(bad)?;
    let board = BoardKind::from_name(&a.board)
        .ok_or_else(|| bad(format!("--board `{}`: expected m0 or m3", a.board)))?;
    let rest = file
        .rest_pose()
        .map_err(|e| bad(format!("{}: {e}", file.source)))?;
    let start = point_arg("--start", a.start.as_deref(), rest).map_err(bad)?;
    let power_up = match &a.power_up {
        Some(_) => Some(point_arg("--power-up", a.power_up.as_deref(), rest).map_err(bad)?),
        None => None,
    };
    let hand = HandSpec::parse(a.hand.as_deref().unwrap_or("follow")).map_err(bad)?;
    let config = EmulatorConfig {
        hand: hand.model(start),
        service_time: Duration::from_secs_f64(a.service_us * 1e-6),
        clock: EmulatorClock::RealTime,
        hand_damping: a.hand_damping,
        board,
        power_up,
    };
    let plant = emulator::plant_for(&file, Some(start), &config).map_err(bad)?;
    let pty = Pty::new().map_err(|e| (exit::ERROR, e))?;
    let stop = install_ctrlc_stop().map_err(|e| (exit::ERROR, e))?;
    println!("pty: {}", pty.path);
    let _ = std::io::stdout().flush();
    let kind = match file.kind {
        HaplyKind::TwoDiy { .. } => "2DIY",
        HaplyKind::Twin(_) => "twin pantograph",
    };
    eprintln!(
        "emulating {} ({kind}, board id {}, {board:?} with the stock firmware: encoders set at every setup, no watchdog) from {}; handle at ({:.4}, {:.4}) m when set up; hand {}; Ctrl-C stops",
        file.name,
        file.id,
        file.source,
        start[0],
        start[1],
        a.hand.as_deref().unwrap_or("follow")
    );
    if let Some(d) = a.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(bad("--duration must be > 0 s".into()));
        }
        let s = stop.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_secs_f64(d));
            s.store(true, Ordering::Relaxed);
        });
    }
    let Pty { master, keep, .. } = pty;
    let report = serve(master, &file, plant, &config, &stop);
    drop(keep);
    eprintln!(
        "emulator stopped ({}): {} frames, {} setups, {} replies, {} bytes discarded; motors still hold {:?} N·m",
        report.reason,
        report.frames,
        report.setups,
        report.replies,
        report.discarded,
        &report.held_torques[..file.joints()]
    );
    Ok(exit::CLEAN)
}

/// `haptic2d emulate inverse3` in a build without the `inverse3` feature: refused, with the command
/// that builds it.
#[cfg(not(feature = "inverse3"))]
fn run_inverse3(_a: &EmulateArgs) -> Result<u8, (u8, String)> {
    Err((
        exit::BAD_INPUT,
        format!("emulate inverse3: {}", crate::inverse3_arg::NOT_BUILT),
    ))
}

/// `X,Y` (m) of option `opt`, or `default` when absent; θ kept from `default`.
fn point_arg(opt: &str, arg: Option<&str>, default: [f64; 3]) -> Result<[f64; 3], String> {
    let Some(s) = arg else {
        return Ok(default);
    };
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("{opt} `{s}`: expected X,Y in metres"))?;
    if v.len() != 2 || !v.iter().all(|x| x.is_finite()) {
        return Err(format!("{opt} `{s}`: expected X,Y in metres"));
    }
    Ok([v[0], v[1], default[2]])
}

/// `haptic2d emulate inverse3`.
#[cfg(feature = "inverse3")]
fn run_inverse3(a: &EmulateArgs) -> Result<u8, (u8, String)> {
    use haptic2d_devices::inverse3::{Emulator3Config, Hand3, Inverse3Emulator};
    let bad = |m: String| (exit::BAD_INPUT, m);
    let bind: std::net::SocketAddr = a.bind.parse().map_err(|_| {
        bad(format!(
            "--bind `{}`: expected ADDR:PORT, e.g. 127.0.0.1:10001 (port 0 = any free port)",
            a.bind
        ))
    })?;
    if !(a.hand_damping.is_finite() && a.hand_damping >= 0.0) {
        return Err(bad("--hand-damping must be ≥ 0 N·s/m".into()));
    }
    let mut start = [0.0; 3];
    if let Some(s) = &a.start {
        let v: Vec<f64> = s
            .split(',')
            .map(|p| p.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad(format!("--start `{s}`: expected X,Y,Z in metres")))?;
        if !(v.len() == 2 || v.len() == 3) || !v.iter().all(|x| x.is_finite()) {
            return Err(bad(format!("--start `{s}`: expected X,Y,Z in metres")));
        }
        start[..v.len()].copy_from_slice(&v);
    }
    let spec = a.hand.as_deref().unwrap_or("follow");
    let hand = Hand3::parse(spec, start, a.hand_damping).map_err(bad)?;
    if let Some(r) = a.grip_rate {
        if !(r.is_finite() && r.abs() <= 100.0) {
            return Err(bad(format!(
                "--grip-rate {r}: expected a finite rate within ±100 rad/s"
            )));
        }
    }
    let cfg = Emulator3Config {
        start,
        hand,
        grip: a.grip_rate.map(|_| [1.0, 0.0, 0.0, 0.0]),
        grip_rate: a.grip_rate.unwrap_or(0.0),
        drop_position_after: a.drop_position_after,
        ..Emulator3Config::default()
    };
    let stop = install_ctrlc_stop().map_err(|e| (exit::ERROR, e))?;
    let mut emu = Inverse3Emulator::start(bind, cfg.clone()).map_err(|e| {
        (
            exit::ERROR,
            format!("cannot listen at {bind}: {e}\n    fix: pick a free port with --bind 127.0.0.1:PORT (0 = any)"),
        )
    })?;
    println!("listening: http://{}", emu.addr());
    let _ = std::io::stdout().flush();
    if !bind.ip().is_loopback() {
        eprintln!("warning: listening beyond loopback at {bind}: anyone on that network can drive the emulated device");
    }
    eprintln!(
        "emulating Haply's Inverse Service at ws://{}/ (device `{}`: mass {:?} kg, damping {:?} N·s/m, force limit {} N); hand {spec}; Ctrl-C stops",
        emu.addr(),
        haptic2d_devices::inverse3::emulator::EMULATED_ID,
        cfg.mass,
        cfg.damping,
        cfg.force_limit
    );
    let end = match a.duration {
        Some(d) if d.is_finite() && d > 0.0 => {
            Some(std::time::Instant::now() + Duration::from_secs_f64(d))
        }
        Some(_) => return Err(bad("--duration must be > 0 s".into())),
        None => None,
    };
    while !stop.load(Ordering::Relaxed) && end.is_none_or(|e| std::time::Instant::now() < e) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let r = emu.stop();
    eprintln!(
        "emulator stopped: {} connections, {} messages ({} malformed), {} states, {} force commands",
        r.connections, r.messages, r.malformed, r.states, r.forces
    );
    Ok(exit::CLEAN)
}
