//! `haptic2d device check --device haply:PATH --device-file FILE [--pulse]`: reads the angles,
//! prints the pose through the kinematics, and with `--pulse` applies a small, short torque to one
//! motor at a time to confirm its direction, then says which field of the device file to fix.

use crate::haply_arg::{exit, fail, load_file, port_of};
use haptic2d::device::TwinKinematics;
use haptic2d::geom::Vec2;
use haptic2d_devices::haply::serial::open_port;
use haptic2d_devices::haply::{HaplyDevice, HaplyDeviceFile, HaplyKind};
use haptic2d_rt::DeviceIo;
use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Options of `haptic2d device check`.
#[derive(clap::Args, Debug)]
pub struct CheckArgs {
    /// The device: haply:PATH or haply:auto.
    #[arg(long)]
    pub device: String,
    /// The Haply device file (default: haply-2diy-gen3).
    #[arg(long, value_name = "FILE.toml")]
    pub device_file: Option<PathBuf>,
    /// Also pulse each motor (torque below, for 150 ms) to confirm the directions.
    #[arg(long)]
    pub pulse: bool,
    /// Pulse torque (N·m), at most the device file's torque limit.
    #[arg(long, default_value_t = 0.02)]
    pub pulse_torque: f64,
}

/// Subcommands of `haptic2d device`.
#[derive(clap::Subcommand, Debug)]
pub enum DeviceCommand {
    /// Read the angles and the pose; with --pulse confirm the motor directions.
    Check(CheckArgs),
}

/// Runs `device SUBCOMMAND`.
pub fn run(c: &DeviceCommand) -> ExitCode {
    let DeviceCommand::Check(a) = c;
    match check(a) {
        Ok(code) => ExitCode::from(code),
        Err((code, msg)) => fail(code, &msg),
    }
}

const PERIOD: Duration = Duration::from_millis(1);

fn check(a: &CheckArgs) -> Result<u8, (u8, String)> {
    let bad = |m: String| (exit::BAD_INPUT, m);
    let file = load_file(a.device_file.as_deref()).map_err(bad)?;
    if !(a.pulse_torque.is_finite() && a.pulse_torque > 0.0 && a.pulse_torque <= file.torque_limit)
    {
        return Err(bad(format!(
            "--pulse-torque {} N·m: must be > 0 and at most board.torque_limit = {} N·m",
            a.pulse_torque, file.torque_limit
        )));
    }
    let path = port_of(&a.device, &file).map_err(bad)?;
    let name = format!("haply:{path}");
    let port = open_port(&path).map_err(|e| (exit::DEVICE_LOST, e))?;
    let mut dev =
        HaplyDevice::open(port, &file, PERIOD, &name).map_err(|e| (exit::DEVICE_LOST, e))?;
    let lost = |e: haptic2d_rt::DeviceError| (exit::DEVICE_LOST, e.to_string());
    let q = dev.read_encoders().map_err(lost)?;
    println!("{name}: {} ({})", file.name, file.source);
    for (j, m) in file.motors.iter().enumerate() {
        println!("  motor[{j}] port {}: {:9.3}°", m.port, q[j].to_degrees());
    }
    let mut problems = pose_report(&file, &q);
    if a.pulse {
        problems.extend(pulse(&mut dev, &file, a.pulse_torque).map_err(lost)?);
    }
    dev.zero_torques();
    if problems.is_empty() {
        println!("ok: the readings are consistent with {}", file.source);
        Ok(exit::CLEAN)
    } else {
        for p in &problems {
            println!("fix: {p}");
        }
        Ok(exit::BAD_INPUT)
    }
}

/// Prints the pose through the kinematics; returns what looks wrong.
fn pose_report(file: &HaplyDeviceFile, q: &[f64; 4]) -> Vec<String> {
    let mut problems = Vec::new();
    match &file.kind {
        HaplyKind::TwoDiy {
            linkage,
            center,
            half_width,
        } => match linkage.state([q[0], q[1]]) {
            Ok(s) => {
                println!(
                    "  end point ({:.4} m, {:.4} m), singularity margin {:.2}",
                    s.e.x, s.e.y, s.margin
                );
                let c = Vec2::new(center[0], center[1]);
                let d = s.e - c;
                if d.x.abs() > 2.0 * half_width || d.y.abs() > 2.0 * half_width {
                    problems.push(format!(
                        "the end point is far outside the workspace square ({:.3} ± {half_width} m): check motor[*].offset_deg (the angle of each link at power-up) and that the handle was at its rest pose when the board was powered",
                        center[1]
                    ));
                }
            }
            Err(e) => problems.push(format!(
                "the angles do not assemble into the linkage ({e}): check motor[*].offset_deg, the link lengths in [linkage], and the motor/port order of the [[motor]] tables"
            )),
        },
        HaplyKind::Twin(p) => {
            let kin = TwinKinematics::new(p);
            match kin.fk(q, 0.0) {
                Ok(fk) => println!(
                    "  handle ({:.4} m, {:.4} m, {:.3} rad), closure error {:.2e} m",
                    fk.pose[0], fk.pose[1], fk.pose[2], fk.closure_error
                ),
                Err(e) => problems.push(format!(
                    "the twin kinematics fail ({e}): check the offsets of the four [[motor]] tables and device.r_c"
                )),
            }
        }
    }
    problems
}

/// Pulses each motor in turn with `+tau` for 150 ms, then rests 150 ms; a positive torque must turn
/// its link counter-clockwise (the angle grows).
fn pulse<S: Read + Write>(
    dev: &mut HaplyDevice<S>,
    file: &HaplyDeviceFile,
    tau: f64,
) -> Result<Vec<String>, haptic2d_rt::DeviceError> {
    let mut problems = Vec::new();
    for (j, m) in file.motors.iter().enumerate() {
        let q0 = hold(dev, [0.0; 4], Duration::from_millis(150))?;
        let mut t = [0.0; 4];
        t[j] = tau;
        let q1 = hold(dev, t, Duration::from_millis(150))?;
        let dq = q1[j] - q0[j];
        let count = std::f64::consts::TAU / m.counts_per_turn;
        println!(
            "  pulse motor[{j}] (port {}) +{tau} N·m: angle {:+.3}°",
            m.port,
            dq.to_degrees()
        );
        if dq.abs() < 2.0 * count {
            problems.push(format!(
                "motor[{j}] (port {}) did not move under +{tau} N·m: check its cable and the board's motor power; let the handle move freely during the check",
                m.port
            ));
        } else if dq < 0.0 {
            problems.push(format!(
                "motor[{j}] (port {}) turned its link clockwise for a positive torque: flip motor[{j}].direction; if moving the handle by hand also makes this angle run the wrong way, flip motor[{j}].encoder_direction instead",
                m.port
            ));
        }
    }
    hold(dev, [0.0; 4], Duration::from_millis(50))?;
    Ok(problems)
}

/// Runs a 1 kHz exchange loop holding torques `tau` for `d`; returns the last angles.
fn hold<S: Read + Write>(
    dev: &mut HaplyDevice<S>,
    tau: [f64; 4],
    d: Duration,
) -> Result<[f64; 4], haptic2d_rt::DeviceError> {
    let end = Instant::now() + d;
    let mut q = dev.read_encoders()?;
    while Instant::now() < end {
        dev.write_torques(&tau)?;
        std::thread::sleep(PERIOD);
        q = dev.read_encoders()?;
    }
    Ok(q)
}
