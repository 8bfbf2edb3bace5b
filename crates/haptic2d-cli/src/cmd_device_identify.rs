//! `haptic2d device identify --device haply:PATH --device-file FILE [--write]`: measures a 2DIY's
//! joint-space inertia (kg·m²) and viscous damping (N·m·s/rad) at its rest pose from small torque
//! pulses, hand released, and writes them to the device file's `[identified]` table, which the
//! stability gate (`run`, `stability`) then uses instead of the built-in estimates.
//!
//! Steps: the board is opened as `run` opens it (the handle held still at the rest pose, the
//! rest-pose check: a handle that moves during the set-up is refused, exit 2); the user lets go;
//! the handle must stay still at zero torque (else exit 2); one sine doublet per joint (starts at
//! zero, ramps in, at most `--torque`, every torque clamped by the driver, the end point watched
//! against a 15 mm bound); the fit of `haptic2d_devices::haply::identify` (method and units there);
//! the direction diagnosis of `device check --pulse` on the fitted response (a reversed motor, or a
//! motor and encoder reversed together: exit 2 with the field to flip, nothing written); a third
//! pulse along the heavy direction; the final fit, printed, and with `--write` stored in the file.

use crate::cmd_device_check::{diagnose_2dof, Pulse};
use crate::haply_arg::{exit, load_file, port_of, Outcome, BENCH_PERIOD};
use haptic2d_devices::haply::identified::{replace_table, utc_iso8601, Identified};
use haptic2d_devices::haply::identify::{
    estimate, heavy_direction, joint_directions, lumped, record_pulses, Identification,
    IdentifyError, PulsePlan, Timebase,
};
use haptic2d_devices::haply::serial::open_port;
use haptic2d_devices::haply::{HaplyDevice, HaplyDeviceFile, HaplyKind};
use haptic2d_rt::DeviceIo;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Largest doublet amplitude accepted (N·m): identification needs small pulses.
const MAX_PULSE_TORQUE: f64 = 0.02;
/// A fit whose residual is above this fraction of its right-hand side is not written.
const MAX_RESIDUAL: f64 = 0.15;
/// … nor one whose inertia coupling is this far from reciprocal.
const MAX_ASYMMETRY: f64 = 0.25;

/// Options of `haptic2d device identify`.
#[derive(clap::Args, Debug)]
pub struct IdentifyArgs {
    /// The device: haply:PATH or haply:auto (a 2DIY).
    #[arg(long)]
    pub device: String,
    /// The Haply device file (default: haply-2diy-gen3; --write needs a file path).
    #[arg(long, value_name = "FILE.toml")]
    pub device_file: Option<PathBuf>,
    /// Amplitude of each joint pulse (N·m), at most 0.02 and the file's torque limit.
    #[arg(long, default_value_t = 0.0015)]
    pub torque: f64,
    /// Seconds between the set-up and the pulses, for letting go of the handle.
    #[arg(long, default_value_t = 2.0)]
    pub release_delay: f64,
    /// Write the [identified] table into the device file (otherwise print it).
    #[arg(long)]
    pub write: bool,
}

/// Runs `device identify`: its exit code, or the code and message of what stopped it.
pub fn identify(a: &IdentifyArgs) -> Outcome {
    let bad = |m: String| (exit::BAD_INPUT, m);
    let file = load_file(a.device_file.as_deref()).map_err(bad)?;
    let HaplyKind::TwoDiy { linkage, .. } = &file.kind else {
        return Err(bad(format!(
            "{}: device identify measures a 2DIY (kind = \"2diy\"); the twin's closed chain is not identified yet",
            file.source
        )));
    };
    let cap = file.torque_limit.min(MAX_PULSE_TORQUE);
    if !(a.torque.is_finite() && a.torque > 0.0 && a.torque <= cap) {
        return Err(bad(format!(
            "--torque {} N·m: must be > 0 and at most {cap} N·m (small pulses; board.torque_limit = {} N·m)",
            a.torque, file.torque_limit
        )));
    }
    if !(a.release_delay.is_finite() && (0.0..=60.0).contains(&a.release_delay)) {
        return Err(bad("--release-delay must be 0–60 s".into()));
    }
    let target = match (&a.device_file, a.write) {
        (Some(p), true) if p.is_file() => Some(p.clone()),
        (_, true) => {
            return Err(bad(
                "--write needs --device-file with the path of your device file (a built-in file cannot be written): copy devices/haply-2diy-gen3.toml and give its path".into(),
            ))
        }
        _ => None,
    };
    let path = port_of(&a.device, &file).map_err(bad)?;
    let name = format!("haply:{path}");
    let port = open_port(&path).map_err(|e| (exit::DEVICE_LOST, e))?;
    println!("{name}: hold the handle still at its rest pose: the board is being set up");
    let mut dev = HaplyDevice::open(port, &file, BENCH_PERIOD, &name).map_err(|e| {
        // The rest-pose check (the handle moved during the set-up) is the user's to fix.
        if e.contains("right after the set-up") {
            (exit::BAD_INPUT, e)
        } else {
            (exit::DEVICE_LOST, e)
        }
    })?;
    println!("{name}: {}", dev.firmware_summary());
    if let Some(w) = dev.start_warning() {
        eprintln!("warning: {w}");
    }
    let lost = |e: haptic2d_rt::DeviceError| (exit::DEVICE_LOST, e.to_string());
    if a.release_delay > 0.0 {
        println!(
            "{name}: let go of the handle without moving it: the pulses start in {:.1} s",
            a.release_delay
        );
        let end = Instant::now() + Duration::from_secs_f64(a.release_delay);
        while Instant::now() < end {
            dev.write_torques(&[0.0; 4]).map_err(lost)?;
            std::thread::sleep(BENCH_PERIOD);
            dev.read_encoders().map_err(lost)?;
        }
    }
    let plan = PulsePlan {
        amplitude: a.torque,
        timebase: Timebase::Wall,
        period: BENCH_PERIOD.as_secs_f64(),
        ..PulsePlan::default()
    };
    let rest4 = file.rest_joint_angles();
    let rest = [rest4[0], rest4[1]];
    let counts = [
        file.motors[0].counts_per_turn,
        file.motors[1].counts_per_turn,
    ];
    let recorded = |e: IdentifyError| match e {
        IdentifyError::NotStill(m) => (exit::BAD_INPUT, m),
        IdentifyError::Excursion(m) | IdentifyError::Fit(m) => (exit::ERROR, m),
        IdentifyError::Device(e) => (exit::DEVICE_LOST, e.to_string()),
    };
    println!(
        "  pulses: one sine doublet per joint, ±{:.1} mN·m over 2 × {:.0} ms, end point kept within {:.0} mm of the rest pose",
        plan.amplitude * 1e3,
        plan.half_period * 1e3,
        plan.max_excursion * 1e3
    );
    let dirs = joint_directions(&plan);
    let mut pulses =
        record_pulses(&mut dev, linkage, rest, counts, &dirs, true, &plan).map_err(recorded)?;
    let first = estimate(&pulses).map_err(|e| (exit::ERROR, format!("the fit failed: {e}")))?;
    // Directions: the signs of the fitted response, diagnosed as `device check --pulse` does.
    let problems = match first.response_displacement(plan.amplitude, plan.half_period) {
        Some(d) => diagnose_2dof(
            linkage,
            &rest4,
            &[
                Pulse {
                    dq: [d[0][0], d[0][1], 0.0, 0.0],
                },
                Pulse {
                    dq: [d[1][0], d[1][1], 0.0, 0.0],
                },
            ],
            counts,
        ),
        None => vec!["the pulses did not move the joints independently: let the handle move freely and run the identification again".into()],
    };
    if !problems.is_empty() {
        dev.zero_torques();
        for p in &problems {
            println!("fix: {p}");
        }
        println!("nothing identified: fix the directions in {} (or run `haptic2d device check --pulse`), then run the identification again", file.source);
        return Ok(exit::BAD_INPUT);
    }
    let heavy = heavy_direction(&first, &plan, cap, &jacobian(linkage, rest)?).ok_or((
        exit::ERROR,
        "the first estimate's inertia is not positive definite: let the handle move freely and run the identification again".to_string(),
    ))?;
    println!(
        "  third pulse along the heavy direction: ({:+.2}, {:+.2}) mN·m",
        heavy[0] * 1e3,
        heavy[1] * 1e3
    );
    pulses.extend(
        record_pulses(&mut dev, linkage, rest, counts, &[heavy], false, &plan).map_err(recorded)?,
    );
    dev.zero_torques();
    drop(dev);
    let id = estimate(&pulses).map_err(|e| (exit::ERROR, format!("the fit failed: {e}")))?;
    let identified = report(&id, linkage, rest)?;
    if id.relative_residual > MAX_RESIDUAL || id.asymmetry() > MAX_ASYMMETRY {
        return Err((
            exit::ERROR,
            format!(
                "the fit is poor (residual {:.1} % > {:.0} % or reciprocity error {:.1} % > {:.0} %): a hand on the handle, friction or an obstacle; nothing written — let go of the handle and run the identification again",
                id.relative_residual * 100.0,
                MAX_RESIDUAL * 100.0,
                id.asymmetry() * 100.0,
                MAX_ASYMMETRY * 100.0
            ),
        ));
    }
    let table = identified.to_toml();
    match target {
        Some(p) => {
            let text = std::fs::read_to_string(&p)
                .map_err(|e| (exit::ERROR, format!("reading {}: {e}", p.display())))?;
            let new = replace_table(&text, &table);
            // The file must still load, with the values just measured.
            let check = HaplyDeviceFile::from_toml(&new, &file.source)
                .map_err(|e| (exit::ERROR, format!("the updated file does not load: {e}")))?;
            if check.identified.is_none() {
                return Err((
                    exit::ERROR,
                    "the updated file lost its [identified] table".into(),
                ));
            }
            let tmp = p.with_extension("toml.identify-tmp");
            std::fs::write(&tmp, new)
                .and_then(|_| std::fs::rename(&tmp, &p))
                .map_err(|e| (exit::ERROR, format!("writing {}: {e}", p.display())))?;
            println!(
                "wrote [identified] to {}: `run` and `stability` use it for the stability gate",
                p.display()
            );
        }
        None => {
            println!("add this to your device file (or run again with --write):\n");
            print!("{table}");
        }
    }
    Ok(exit::CLEAN)
}

fn jacobian(
    linkage: &haptic2d::device::pantograph2::Pantograph2,
    rest: [f64; 2],
) -> Result<[[f64; 2]; 2], (u8, String)> {
    linkage
        .state(rest)
        .map(|s| s.j)
        .map_err(|e| (exit::BAD_INPUT, format!("the rest pose is singular: {e}")))
}

/// Prints the identified numbers and returns the table's contents.
fn report(
    id: &Identification,
    linkage: &haptic2d::device::pantograph2::Pantograph2,
    rest: [f64; 2],
) -> Result<Identified, (u8, String)> {
    let (m, b) = id.symmetric();
    let (i_j, m_e) = lumped(&m, &jacobian(linkage, rest)?);
    println!(
        "identified at the rest pose ({} samples, fit residual {:.1} %, reciprocity error {:.1} %):",
        id.samples,
        id.relative_residual * 100.0,
        id.asymmetry() * 100.0
    );
    for j in 0..2 {
        println!(
            "  joint {j}: inertia {:.3e} kg·m², damping {:.3e} N·m·s/rad",
            m[j][j], b[j][j]
        );
    }
    println!("  coupling: inertia M_01 {:.3e} kg·m²", m[0][1]);
    let out = Identified {
        date: utc_iso8601(
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
        ),
        command: command_line(),
        inertia: [m[0][0], m[1][1]],
        inertia_coupling: m[0][1],
        damping: [b[0][0].max(0.0), b[1][1].max(0.0)],
        joint_inertia: i_j,
        end_mass: m_e,
    };
    println!(
        "  lumped model for the stability gate: I_j {:.3e} kg·m², m_e {:.4} kg, b {:.3e} N·m·s/rad",
        out.joint_inertia,
        out.end_mass,
        out.joint_damping()
    );
    Ok(out)
}

/// This process's command line, shell-quoted where needed.
fn command_line() -> String {
    let mut args = std::env::args();
    let mut out = vec!["haptic2d".to_string()];
    args.next();
    for a in args {
        if a.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./:=,+@".contains(c))
        {
            out.push(a);
        } else {
            out.push(format!("'{}'", a.replace('\'', "'\\''")));
        }
    }
    out.join(" ")
}
