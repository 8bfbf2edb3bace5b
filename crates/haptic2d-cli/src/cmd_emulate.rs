//! `haptic2d emulate haply`: a stand-in Haply board on a pseudo-terminal. The first line of standard
//! output is `pty: PATH`; a host (`haptic2d run --device haply:PATH`) opens PATH like the board's
//! serial port. The emulated board moves a simulated linkage under the motor torques and a simulated
//! hand until Ctrl-C (or `--duration`).

use crate::hand_arg::HandSpec;
use crate::haply_arg::{exit, fail, load_file};
use haptic2d_devices::haply::serial::Pty;
use haptic2d_devices::haply::{emulator, serve, EmulatorClock, EmulatorConfig, HaplyKind};
use haptic2d_rt::signal::install_ctrlc_stop;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// Options of `haptic2d emulate`.
#[derive(clap::Args, Debug)]
pub struct EmulateArgs {
    /// What to emulate: haply.
    pub target: String,
    /// The board's wiring and linkage (a Haply device file, or haply-2diy-gen3 | haply-2diy-gen2 |
    /// haply-twin). Default haply-2diy-gen3.
    #[arg(long, value_name = "FILE.toml")]
    pub device_file: Option<PathBuf>,
    /// Simulated hand: follow (hold the start point) | free | constant:FX,FY,TAU |
    /// sine:FPK,FREQ[,DIRX,DIRY] | script:HOLD,FX,FY,TAU,PUSH[,RFX,RFY,RTAU]. Default follow.
    #[arg(long, allow_hyphen_values = true)]
    pub hand: Option<String>,
    /// Start point of the handle X,Y (m, the device file's frame). Default the workspace centre.
    #[arg(long, allow_hyphen_values = true)]
    pub start: Option<String>,
    /// Service time of the board (µs), at least 50.
    #[arg(long, default_value_t = 50.0)]
    pub service_us: f64,
    /// Stop after this many seconds (default: until Ctrl-C).
    #[arg(long)]
    pub duration: Option<f64>,
    /// Hand damping (N·s/m) added to the hand model.
    #[arg(long, default_value_t = 2.0)]
    pub hand_damping: f64,
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
    if a.target != "haply" {
        return Err(bad(format!(
            "emulate `{}`: no such emulator\n    fix: haptic2d emulate haply",
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
    let mut start = file.workspace_center();
    if let Some(s) = &a.start {
        let v: Vec<f64> = s
            .split(',')
            .map(|p| p.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad(format!("--start `{s}`: expected X,Y in metres")))?;
        if v.len() != 2 || !v.iter().all(|x| x.is_finite()) {
            return Err(bad(format!("--start `{s}`: expected X,Y in metres")));
        }
        start[0] = v[0];
        start[1] = v[1];
    }
    let hand = HandSpec::parse(a.hand.as_deref().unwrap_or("follow")).map_err(bad)?;
    let config = EmulatorConfig {
        hand: hand.model(start),
        service_time: Duration::from_secs_f64(a.service_us * 1e-6),
        clock: EmulatorClock::RealTime,
        hand_damping: a.hand_damping,
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
        "emulating {} ({kind}, board id {}) from {}; hand {}; Ctrl-C stops",
        file.name,
        file.id,
        file.source,
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
        "emulator stopped ({}): {} frames, {} replies, {} bytes discarded",
        report.reason, report.frames, report.replies, report.discarded
    );
    Ok(exit::CLEAN)
}
