//! `haptic2d device check --device haply:PATH --device-file FILE [--pulse]`: with the handle held
//! still at the rest pose, opens the board as `run` does (identify, setup, the rest-pose check:
//! docs/DEVICES.md §7), prints the angles and the pose through the kinematics, and with `--pulse`
//! applies a small, short torque to one motor at a time to confirm the motor and encoder
//! directions, then says which field of the device file to fix.
//!
//! A positive torque must turn its link counter-clockwise, i.e. make its reported angle grow. That
//! alone cannot tell a correct joint from one whose motor **and** encoder are both reversed (the
//! link turns clockwise and the encoder counts backwards: the angle still grows). The other joint
//! of the five-bar can: pulsing joint `j` from rest also moves joint `k`, through the end point's
//! mass, the hand's stiffness or damping at the handle — all of the form `Jᵀ·(c·1)·J` — so that
//! `Δq_k / Δq_j` has the sign of `−(JᵀJ)_kj` (the joint-space terms, rotor inertia and joint
//! friction, are diagonal and do not change it). A reversed encoder on either joint reverses that
//! sign. The two pulses give three signs (`Δq_0`, `Δq_1`, and the coupling's); the check names the
//! fewest flips of the four direction fields that explain them, or the candidates when two explain
//! them equally (a joint with both reversed looks like the other joint with both reversed). Flipping
//! all four is a mirror image no pulse can see.

use crate::haply_arg::{exit, load_file, port_of, Outcome, BENCH_PERIOD};
use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::device::TwinKinematics;
use haptic2d_devices::haply::serial::open_port;
use haptic2d_devices::haply::{HaplyDevice, HaplyDeviceFile, HaplyKind};
use haptic2d_rt::DeviceIo;
use std::io::{Read, Write};
use std::path::PathBuf;
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
    /// Also pulse each motor (torque below, for 150 ms) to confirm the motor and encoder
    /// directions (let the handle move freely or hold it lightly).
    #[arg(long)]
    pub pulse: bool,
    /// Pulse torque (N·m), at most the device file's torque limit.
    #[arg(long, default_value_t = 0.02)]
    pub pulse_torque: f64,
}

/// Runs `device check`: its exit code, or the code and message of what stopped it.
pub fn check(a: &CheckArgs) -> Outcome {
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
    println!("{name}: hold the handle still at its rest pose: the board is being set up");
    let mut dev =
        HaplyDevice::open(port, &file, BENCH_PERIOD, &name).map_err(|e| (exit::DEVICE_LOST, e))?;
    println!("{name}: {}", dev.firmware_summary());
    if let Some(w) = dev.start_warning() {
        eprintln!("warning: {w}");
    }
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
        HaplyKind::TwoDiy { linkage, .. } => match linkage.state([q[0], q[1]]) {
            Ok(s) => println!(
                "  rest pose: end point ({:.4} m, {:.4} m), singularity margin {:.2}",
                s.e.x, s.e.y, s.margin
            ),
            Err(e) => problems.push(format!(
                "the angles do not assemble into the linkage ({e}): check motor[*].offset_deg, the link lengths in [linkage], and the motor/port order of the [[motor]] tables"
            )),
        },
        HaplyKind::Twin(p) => {
            let kin = TwinKinematics::new(p);
            match kin.fk(q, 0.0) {
                Ok(fk) => println!(
                    "  homing pose: handle ({:.4} m, {:.4} m, {:.3} rad), closure error {:.2e} m",
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

/// One pulse's outcome: the joint angle changes (rad) from before to the end of the pulse.
pub(crate) struct Pulse {
    /// Joint angle changes (rad).
    pub(crate) dq: [f64; 4],
}

/// Pulses each motor in turn with `+tau` for 150 ms, then rests 150 ms, and diagnoses the
/// directions (see the module documentation).
fn pulse<S: Read + Write>(
    dev: &mut HaplyDevice<S>,
    file: &HaplyDeviceFile,
    tau: f64,
) -> Result<Vec<String>, haptic2d_rt::DeviceError> {
    let mut problems = Vec::new();
    let mut pulses = Vec::new();
    let mut q_rest = [0.0; 4];
    // Twin: (motor, closure-error change (m), limit (m)) of the pulses that broke the closure.
    let mut drifts: Vec<(usize, f64, f64)> = Vec::new();
    for (j, m) in file.motors.iter().enumerate() {
        let q0 = hold(dev, [0.0; 4], Duration::from_millis(150))?;
        if j == 0 {
            q_rest = q0;
        }
        let mut t = [0.0; 4];
        t[j] = tau;
        let q1 = hold(dev, t, Duration::from_millis(150))?;
        let dq: [f64; 4] = std::array::from_fn(|i| q1[i] - q0[i]);
        println!(
            "  pulse motor[{j}] (port {}) +{tau} N·m: angle {:+.3}°",
            m.port,
            dq[j].to_degrees()
        );
        let count = std::f64::consts::TAU / m.counts_per_turn;
        if dq[j].abs() < 2.0 * count {
            problems.push(format!(
                "motor[{j}] (port {}) did not move under +{tau} N·m: check its cable and the board's motor power; let the handle move freely during the check",
                m.port
            ));
        }
        if let HaplyKind::Twin(p) = &file.kind {
            // The readings of a rigid handle keep |P_2 − P_1| = r_c while it moves; a reversed
            // joint makes them drift apart. Threshold: 3 counts of a proximal link at its elbow.
            let mut kin = TwinKinematics::new(p);
            kin.closure_tol = f64::INFINITY;
            let closure = |q: &[f64; 4]| kin.fk(q, 0.0).map(|f| f.closure_error);
            let limit = 3.0 * count * p.l1;
            match (closure(&q0), closure(&q1)) {
                (Ok(c0), Ok(c1)) => {
                    if (c1 - c0).abs() > limit {
                        drifts.push((j, c1 - c0, limit));
                    }
                }
                (_, Err(e)) | (Err(e), _) => problems.push(format!(
                    "after pulsing motor[{j}] (port {}) the twin kinematics fail ({e}): a motor or encoder direction is reversed; check motor[{j}].direction and encoder_direction first",
                    m.port
                )),
            }
        }
        pulses.push(Pulse { dq });
    }
    hold(dev, [0.0; 4], Duration::from_millis(50))?;
    if let Some(&(worst, _, limit)) = drifts.iter().max_by(|a, b| a.1.abs().total_cmp(&b.1.abs())) {
        let list: Vec<String> = drifts
            .iter()
            .map(|(j, d, _)| format!("motor[{j}] {:+.2} mm", d * 1e3))
            .collect();
        problems.push(format!(
            "the readings no longer describe one rigid handle while the motors push (closure error change per pulse, above 3 counts = {:.2} mm: {}): a direction is reversed — a joint whose motor and encoder are both reversed still shows a growing angle; the largest change is under motor[{worst}]'s pulse: check it first (flip both motor[{worst}].direction and motor[{worst}].encoder_direction if its angle grew, else its encoder_direction) and run the check again",
            limit * 1e3,
            list.join(", ")
        ));
    }
    if !problems.is_empty() {
        return Ok(problems);
    }
    match &file.kind {
        HaplyKind::TwoDiy { linkage, .. } => {
            let counts = [
                file.motors[0].counts_per_turn,
                file.motors[1].counts_per_turn,
            ];
            problems.extend(diagnose_2dof(linkage, &q_rest, &pulses, counts));
        }
        HaplyKind::Twin(_) => {
            for (j, p) in pulses.iter().enumerate() {
                if p.dq[j] < 0.0 {
                    problems.push(format!(
                        "motor[{j}] (port {}) turned its link clockwise for a positive torque: flip motor[{j}].direction; if moving the handle by hand also makes this angle run the wrong way, flip motor[{j}].encoder_direction instead",
                        file.motors[j].port
                    ));
                }
            }
        }
    }
    Ok(problems)
}

/// The direction diagnosis of a five-bar from its two pulses (module documentation).
pub(crate) fn diagnose_2dof(
    linkage: &Pantograph2,
    q_rest: &[f64; 4],
    pulses: &[Pulse],
    counts: [f64; 2],
) -> Vec<String> {
    let Ok(s) = linkage.state([q_rest[0], q_rest[1]]) else {
        return vec!["the rest pose does not assemble: see above".into()];
    };
    let j = s.j;
    // (JᵀJ)_01: the coupling's expected sign is −sign of it.
    let c = j[0][0] * j[0][1] + j[1][0] * j[1][1];
    let sign = |v: f64| if v >= 0.0 { 1 } else { -1 };
    let d = [sign(pulses[0].dq[0]), sign(pulses[1].dq[1])];
    // The coupling from each pulse: the other joint's motion against the pulsed one's.
    let mut coupling = Vec::new();
    for (jj, p) in pulses.iter().enumerate().take(2) {
        let k = 1 - jj;
        let min_k = 2.0 * std::f64::consts::TAU / counts[k];
        if p.dq[k].abs() >= min_k && c.abs() > 1e-6 {
            coupling.push(sign(p.dq[k] * p.dq[jj]) * -sign(c));
        }
    }
    let mut out = Vec::new();
    let p = match coupling.as_slice() {
        [] => {
            out.push("the other joint did not follow either pulse, so a motor and encoder reversed together cannot be told from a correct joint: let the handle move freely (or hold it lightly) and run the check again".to_string());
            // Fall back on the plain sign of each joint.
            1
        }
        [a] => *a,
        [a, b] if a == b => *a,
        _ => {
            out.push("the two pulses disagree on the coupling between the joints: run the check again with the handle free or lightly held".into());
            return out;
        }
    };
    // Fewest flips (motor m_j, encoder e_j, ±1) that explain D_j = e_j·m_j and P = e_0·e_1.
    let mut best: Vec<[i32; 4]> = Vec::new();
    let mut best_n = usize::MAX;
    for bits in 0..16u32 {
        let f: [i32; 4] = std::array::from_fn(|i| if bits >> i & 1 == 1 { -1 } else { 1 });
        let (m0, e0, m1, e1) = (f[0], f[1], f[2], f[3]);
        if e0 * m0 != d[0] || e1 * m1 != d[1] || e0 * e1 != p {
            continue;
        }
        let n = bits.count_ones() as usize;
        if n < best_n {
            best_n = n;
            best.clear();
        }
        if n == best_n {
            best.push(f);
        }
    }
    if best_n == 0 {
        return out;
    }
    let describe = |f: &[i32; 4]| {
        let mut parts = Vec::new();
        for jj in 0..2 {
            match (f[2 * jj] < 0, f[2 * jj + 1] < 0) {
                (true, true) => parts.push(format!(
                    "motor[{jj}]'s motor AND encoder are both reversed (its link turns clockwise for a positive torque and its encoder counts backwards, so its angle still grows): flip both motor[{jj}].direction and motor[{jj}].encoder_direction"
                )),
                (true, false) => parts.push(format!(
                    "motor[{jj}] turns its link clockwise for a positive torque: flip motor[{jj}].direction"
                )),
                (false, true) => parts.push(format!(
                    "motor[{jj}]'s encoder counts backwards: flip motor[{jj}].encoder_direction"
                )),
                (false, false) => {}
            }
        }
        parts.join("; ")
    };
    if best.len() == 1 {
        out.push(describe(&best[0]));
    } else {
        let options: Vec<String> = best.iter().map(describe).collect();
        out.push(format!(
            "the pulses show a reversed direction but cannot tell which of these it is: {} — apply the first, run the check again, and if it still fails undo it and apply the next",
            options.join(" — or — ")
        ));
    }
    out
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
        std::thread::sleep(BENCH_PERIOD);
        q = dev.read_encoders()?;
    }
    Ok(q)
}
