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
//!
//! Both are subcommands with their own options (issue 39 item 7). Both run at real-time priority
//! (`SCHED_FIFO` [`DEVICE_FIFO_PRIORITY`], below the loop's) unless `--no-rt`: a real device has a
//! CPU of its own, and its stand-in at normal priority answers late on a loaded machine (issue 39
//! item 4). When the kernel refuses, the emulator says so and how to get it, and runs anyway.

use crate::hand_arg::HandSpec;
use crate::haply_arg::{exit, exit_code, load_file};
use haptic2d_devices::haply::serial::Pty;
use haptic2d_devices::haply::{
    emulator, serve, BoardKind, EmulatorClock, EmulatorConfig, HaplyKind,
};
use haptic2d_rt::rt::{setup_realtime, RtRequest, DEVICE_FIFO_PRIORITY};
use haptic2d_rt::signal::install_ctrlc_stop;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// `haptic2d emulate haply|inverse3`.
#[derive(clap::Args, Debug)]
#[command(
    subcommand_required = true,
    arg_required_else_help = true,
    subcommand_value_name = "haply|inverse3"
)]
pub struct EmulateArgs {
    /// Which emulator.
    #[command(subcommand)]
    pub target: EmulateTarget,
}

/// The emulators.
#[derive(clap::Subcommand, Debug)]
pub enum EmulateTarget {
    /// A Haply board (2DIY or twin) with its stock firmware on a pseudo-terminal; the first stdout
    /// line is `pty: PATH` (then `haptic2d run --device haply:PATH`).
    #[command(after_help = crate::examples_help(HAPLY_EXAMPLES))]
    Haply(HaplyArgs),
    /// Haply's Inverse Service with one Inverse3 on loopback; the first stdout line is
    /// `listening: http://ADDR:PORT` (then `haptic2d run --device inverse3:http://ADDR:PORT`).
    #[command(after_help = crate::examples_help(INVERSE3_EXAMPLES))]
    Inverse3(Inverse3Args),
}

/// Examples of `emulate haply --help` (parsed by `cli_tests::every_example_parses`).
pub const HAPLY_EXAMPLES: &[crate::Example] = &[
    (
        "A Haply 2DIY gen3 (then, in another terminal, `haptic2d run --device haply:PATH`)",
        "haptic2d emulate haply",
    ),
    (
        "A 2-port M0 board, a hand pushing 1 N along x, for 30 s",
        "haptic2d emulate haply --board m0 --hand constant:1,0,0 --duration 30",
    ),
    (
        "The twin-pantograph Haply rig (four motors on an M3 board)",
        "haptic2d emulate haply --device-file haply-twin",
    ),
];

/// Examples of `emulate inverse3 --help`.
pub const INVERSE3_EXAMPLES: &[crate::Example] = &[
    (
        "On a free loopback port (then `haptic2d run --device inverse3:http://127.0.0.1:PORT`)",
        "haptic2d emulate inverse3 --bind 127.0.0.1:0",
    ),
    (
        "A hand that holds the cursor 1 s, then pushes 0.8 N along −x",
        "haptic2d emulate inverse3 --bind 127.0.0.1:0 --hand push:-0.8,0,0,1",
    ),
    (
        "A VerseGrip turning at 1 rad/s, for 10 s",
        "haptic2d emulate inverse3 --grip-rate 1 --duration 10",
    ),
];

/// Options both emulators have.
#[derive(clap::Args, Debug)]
pub struct CommonArgs {
    /// Stop after this many seconds (default: until Ctrl-C).
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// Hand damping (N·s/m) added to the hand model.
    #[arg(long, default_value_t = 2.0, value_name = "B")]
    pub hand_damping: f64,
    /// SCHED_FIFO priority of the emulator (1–99; the loop of `run` has 80).
    #[arg(long, default_value_t = DEVICE_FIFO_PRIORITY, value_name = "P")]
    pub rt_priority: i32,
    /// Normal scheduling: on a loaded machine the emulator then answers late.
    #[arg(long)]
    pub no_rt: bool,
}

/// Options of `haptic2d emulate haply`.
#[derive(clap::Args, Debug)]
pub struct HaplyArgs {
    /// Wiring and linkage: a Haply device file, or haply-2diy-gen3 (default), haply-2diy-gen2,
    /// haply-twin.
    #[arg(long, value_name = "FILE.toml")]
    pub device_file: Option<PathBuf>,
    /// Simulated hand: follow (hold the start point; default) | free | constant:FX,FY,TAU |
    /// sine:FPK,FREQ[,DIRX,DIRY] | script:HOLD,FX,FY,TAU,PUSH[,RFX,RFY,RTAU].
    #[arg(long, allow_hyphen_values = true, value_name = "SPEC")]
    pub hand: Option<String>,
    /// Handle position when the host sets the board up (m); default the rest pose.
    #[arg(long, allow_hyphen_values = true, value_name = "X,Y")]
    pub start: Option<String>,
    /// The board: m3 (4 ports) or m0 (2 ports).
    #[arg(long, default_value = "m3")]
    pub board: String,
    /// Handle position at power-up (m); changes nothing the board reports. Default the start.
    #[arg(long, allow_hyphen_values = true, value_name = "X,Y")]
    pub power_up: Option<String>,
    /// Service time of the board (µs), at least 50.
    #[arg(long, default_value_t = 50.0, value_name = "US")]
    pub service_us: f64,
    #[command(flatten)]
    pub common: CommonArgs,
}

/// Options of `haptic2d emulate inverse3`.
#[derive(clap::Args, Debug)]
pub struct Inverse3Args {
    /// Address to listen at (loopback by default; port 0 = any free port).
    #[arg(long, default_value = "127.0.0.1:10001", value_name = "ADDR:PORT")]
    pub bind: String,
    /// Simulated hand: follow (default) | free | push:FX,FY,FZ[,HOLD].
    #[arg(long, allow_hyphen_values = true, value_name = "SPEC")]
    pub hand: Option<String>,
    /// Cursor position at the start (m, device frame); default 0,0,0.
    #[arg(long, allow_hyphen_values = true, value_name = "X,Y,Z")]
    pub start: Option<String>,
    /// Report a VerseGrip turning about z at this rate (rad/s); default no VerseGrip.
    #[arg(long, allow_hyphen_values = true, value_name = "RAD_S")]
    pub grip_rate: Option<f64>,
    /// For tests: every state after the first N lacks the cursor position.
    #[arg(long, value_name = "N")]
    pub drop_position_after: Option<u64>,
    #[command(flatten)]
    pub common: CommonArgs,
}

/// Real-time priority for the emulator's process (the threads it starts afterwards inherit it),
/// unless `--no-rt`; the note (applied, or refused and how to get it) goes to standard error.
fn realtime(program: &str, c: &CommonArgs) -> Result<(), (u8, String)> {
    if c.no_rt {
        eprintln!(
            "{}",
            haptic2d_rt::RtReport::skipped().device_note(program, 0)
        );
        return Ok(());
    }
    if !(1..=99).contains(&c.rt_priority) {
        return Err((
            exit::BAD_INPUT,
            format!(
                "--rt-priority {}: expected 1–99 (default {DEVICE_FIFO_PRIORITY}, below the loop's 80)",
                c.rt_priority
            ),
        ));
    }
    let report = setup_realtime(&RtRequest::device(c.rt_priority));
    eprintln!("{}", report.device_note(program, c.rt_priority));
    Ok(())
}

/// Runs the emulator.
pub fn run(a: &EmulateArgs) -> ExitCode {
    let r = match &a.target {
        EmulateTarget::Haply(h) => run_haply(h),
        EmulateTarget::Inverse3(i) => run_inverse3(i),
    };
    exit_code(r)
}

/// `haptic2d emulate haply`.
fn run_haply(a: &HaplyArgs) -> Result<u8, (u8, String)> {
    let bad = |m: String| (exit::BAD_INPUT, m);
    if !(a.service_us.is_finite() && a.service_us >= 50.0) {
        return Err(bad(format!(
            "--service-us {}: the board's service time is at least 50 µs",
            a.service_us
        )));
    }
    if !(a.common.hand_damping.is_finite() && a.common.hand_damping >= 0.0) {
        return Err(bad("--hand-damping must be ≥ 0 N·s/m".into()));
    }
    if let Some(d) = a.common.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(bad("--duration must be > 0 s".into()));
        }
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
        hand_damping: a.common.hand_damping,
        board,
        power_up,
    };
    let plant = emulator::plant_for(&file, Some(start), &config).map_err(bad)?;
    let pty = Pty::new().map_err(|e| (exit::ERROR, e))?;
    let stop = install_ctrlc_stop().map_err(|e| (exit::ERROR, e))?;
    realtime("haptic2d emulate haply", &a.common)?;
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
    if let Some(d) = a.common.duration {
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
fn run_inverse3(_a: &Inverse3Args) -> Result<u8, (u8, String)> {
    Err((
        exit::BAD_INPUT,
        format!(
            "emulate inverse3: {}",
            haptic2d_devices::registry::inverse3::NOT_BUILT
        ),
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
fn run_inverse3(a: &Inverse3Args) -> Result<u8, (u8, String)> {
    use haptic2d_devices::inverse3::{Emulator3Config, Hand3, Inverse3Emulator};
    let bad = |m: String| (exit::BAD_INPUT, m);
    let bind: std::net::SocketAddr = a.bind.parse().map_err(|_| {
        bad(format!(
            "--bind `{}`: expected ADDR:PORT, e.g. 127.0.0.1:10001 (port 0 = any free port)",
            a.bind
        ))
    })?;
    if !(a.common.hand_damping.is_finite() && a.common.hand_damping >= 0.0) {
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
    let hand = Hand3::parse(spec, start, a.common.hand_damping).map_err(bad)?;
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
    let end = match a.common.duration {
        Some(d) if d.is_finite() && d > 0.0 => {
            Some(std::time::Instant::now() + Duration::from_secs_f64(d))
        }
        Some(_) => return Err(bad("--duration must be > 0 s".into())),
        None => None,
    };
    let stop = install_ctrlc_stop().map_err(|e| (exit::ERROR, e))?;
    // Before the emulator's threads start: they inherit the priority.
    realtime("haptic2d emulate inverse3", &a.common)?;
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
