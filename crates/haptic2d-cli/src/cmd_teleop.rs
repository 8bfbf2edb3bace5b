//! `haptic2d teleop --master sim --slave sim`: bilateral teleoperation of two simulated
//! twin-pantograph devices across a simulated link (issue 41 item 4, first part; docs/TELEOP.md).
//! A gripping hand pushes the master; the slave follows through a virtual coupling and touches a
//! wall; the coupling's reaction comes back, so the contact is felt at the master. Simulated time
//! (`haptic2d_lab::network::teleop`): deterministic, as fast as the machine goes.

use haptic2d_lab::network::{run_teleop, Architecture, FourChannel, Impairment, Teleop};
use haptic2d_lab::stability::DelayedLoop;

use crate::exit::{Failure, Status};
use crate::outln;

/// `teleop`'s options.
#[derive(clap::Args, Clone, Debug)]
pub struct TeleopArgs {
    /// The master device: `sim` (the simulated twin pantograph, pushed by a simulated grip), or
    /// with `--live` a real one: `haply:PATH`, `udp:ADDR:PORT`, `inverse3[:URL]`.
    #[arg(long, default_value = "sim")]
    pub master: String,
    /// The slave device: `sim` (the simulated twin pantograph, with a wall 5 mm to its left), or
    /// with `--live` a real one: `haply:PATH`, `udp:ADDR:PORT`, `inverse3[:URL]`.
    #[arg(long, default_value = "sim")]
    pub slave: String,
    /// Run in real time, both devices in one 1 kHz loop (docs/TELEOP.md, "Two devices in real
    /// time"); implied when either device is not `sim`.
    #[arg(long)]
    pub live: bool,
    /// The master's device file (a real master; as `run --device-file`).
    #[arg(long, value_name = "FILE.toml")]
    pub master_device_file: Option<std::path::PathBuf>,
    /// The slave's device file (a real slave; as `run --device-file`).
    #[arg(long, value_name = "FILE.toml")]
    pub slave_device_file: Option<std::path::PathBuf>,
    /// Let a UDP device be beyond loopback (as `run --allow-remote-device`).
    #[arg(long)]
    pub allow_remote_device: bool,
    /// Live, simulated master: the grip's target moves from the start pose by (DX, DY) (m) at
    /// SPEED (m/s) from time AT (s); default -0.015,0,0.05,0.6 (15 mm left from 0.6 s).
    #[arg(long, value_name = "DX,DY,SPEED,AT", allow_hyphen_values = true)]
    pub push: Option<String>,
    /// Live: normal scheduling instead of real-time priority for the loop.
    #[arg(long)]
    pub no_rt: bool,
    /// Simulated time (s).
    #[arg(long, default_value_t = 3.0)]
    pub duration: f64,
    /// One-way delay of the link (ms, whole periods of 1 ms); the round trip is twice it.
    #[arg(long, default_value_t = 0.0)]
    pub delay_ms: f64,
    /// Fraction of messages lost in each direction, in [0, 1].
    #[arg(long, default_value_t = 0.0)]
    pub loss: f64,
    /// Seed of the link's losses.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Turn the time-domain passivity controllers off (to see the delayed link create energy).
    #[arg(long)]
    pub no_tdpa: bool,
    /// Instead of a teleoperation run: write the delay figures into DIR (created if missing): the
    /// lab's wall-contact and released-handle runs for round trips 0, 10, 50, 200 ms and loss 0,
    /// 5, 10 % with TDPA, waves and neither, as a table (teleop-delays.md, .csv) and a plot per
    /// round trip (teleop-delay-<ms>ms.svg, .png); the table is printed too (docs/TELEOP.md).
    #[arg(long, value_name = "DIR")]
    pub figures: Option<std::path::PathBuf>,
    /// The coupling and the ports use the devices' 50 Hz filtered velocity instead of the
    /// unfiltered rate of the pose: reproduces the 10 ms chatter (docs/TELEOP.md).
    #[arg(long)]
    pub filtered_velocity: bool,
    /// The teleoperation architecture: `position-force` (the slave follows through the coupling,
    /// its reaction comes back) or `four-channel` (Lawrence's: positions, velocities and the
    /// measured hand and wall forces both ways; docs/TELEOP.md).
    #[arg(long, value_enum, default_value = "position-force")]
    pub architecture: ArchitectureArg,
    /// Coupling stiffness along x and y (N/m): position–force's `K`, four-channel's `K_m = K_s`.
    #[arg(long, default_value_t = 500.0)]
    pub stiffness: f64,
    /// Coupling damping along x and y (N·s/m): position–force's `B`, four-channel's `B_m = B_s`.
    #[arg(long, default_value_t = 5.0)]
    pub damping: f64,
    /// Instead of a run: print the delay margin of the linear model of the loop (x axis, no
    /// TDPA) for the chosen architecture and gains, both architectures for comparison
    /// (docs/TELEOP.md, "The delayed loop's stability").
    #[arg(long)]
    pub stability: bool,
    /// With `--stability`: write the margin against the coupling stiffness, both architectures,
    /// into DIR (teleop-margin.svg, .png; created if missing).
    #[arg(long, value_name = "DIR", requires = "stability")]
    pub stability_plot: Option<std::path::PathBuf>,
}

/// `--architecture`'s values.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArchitectureArg {
    /// Position–force: a virtual coupling at the slave, its reaction sent back.
    PositionForce,
    /// Lawrence's four channels with `C2 = C3 = 1`, `C5 = C6 = 0`.
    FourChannel,
}

/// The run's settings from the options (the link, TDPA, velocities, architecture, gains).
fn config(a: &TeleopArgs, link: Impairment) -> Teleop {
    let base = Teleop::new(link, !a.no_tdpa);
    let mut k = base.k;
    let mut b = base.b;
    (k[0], k[1], b[0], b[1]) = (a.stiffness, a.stiffness, a.damping, a.damping);
    let architecture = match a.architecture {
        ArchitectureArg::PositionForce => Architecture::PositionForce,
        ArchitectureArg::FourChannel => Architecture::FourChannel(FourChannel::lawrence(k, b)),
    };
    Teleop {
        duration: a.duration,
        filtered_velocity: a.filtered_velocity,
        k,
        b,
        architecture,
        ..base
    }
}

/// `--stability`: the delay margins of the linear model, and the plot if asked.
fn stability(a: &TeleopArgs, cfg: &Teleop) -> Result<Status, Failure> {
    let chosen = DelayedLoop::of_teleop(cfg).map_err(Failure::error)?;
    outln!(
        "delayed-loop stability (linear model of the x axis, no TDPA; docs/TELEOP.md): devices {:.4} kg, {:.4} N·s/m each; hand {} N/m, {} N·s/m; wall {} N/m, {} N·s/m; coupling {} N/m, {} N·s/m",
        chosen.m, chosen.b, chosen.hand.0, chosen.hand.1, chosen.wall.0, chosen.wall.1, a.stiffness, a.damping
    );
    for (name, arch) in [
        ("position-force", ArchitectureArg::PositionForce),
        ("four-channel", ArchitectureArg::FourChannel),
    ] {
        let c = config(
            &TeleopArgs {
                architecture: arch,
                ..a.clone()
            },
            cfg.link,
        );
        let d = DelayedLoop::of_teleop(&c)
            .and_then(|l| l.margin())
            .map_err(Failure::error)?;
        let mark = if arch == a.architecture {
            " (chosen)"
        } else {
            ""
        };
        let verdict = if d.round_trip == 0.0 {
            format!(
                "unstable without delay (right-most root {:+.2} ± {:.1}j /s)",
                d.undelayed.0,
                d.undelayed.1.abs()
            )
        } else if d.round_trip.is_infinite() {
            "stable at every round trip".to_string()
        } else {
            format!(
                "stable up to a round trip of {:.2} ms (crossing at {:.1} Hz)",
                d.round_trip * 1e3,
                d.omega / std::f64::consts::TAU
            )
        };
        outln!("{name}{mark}: {verdict}");
    }
    if let Some(dir) = &a.stability_plot {
        let files = haptic2d_lab::stability::delayed_plot::write_margin_plot(cfg, dir)
            .map_err(Failure::error)?;
        for f in files {
            outln!("wrote {}", f.display());
        }
    }
    Ok(Status::Clean)
}

/// Runs `teleop`.
pub fn run(a: &TeleopArgs) -> Result<Status, Failure> {
    if let Some(dir) = &a.figures {
        let (rows, files) =
            haptic2d_lab::network::figures::write_delay_figures(dir).map_err(Failure::error)?;
        outln!("{}", haptic2d_lab::network::figures::markdown(&rows));
        for f in files {
            outln!("wrote {}", f.display());
        }
        return Ok(Status::Clean);
    }
    if !(a.duration.is_finite() && a.duration > 1.0 && a.duration <= 600.0) {
        return Err(Failure::from(format!(
            "--duration must be within (1, 600] s (got {})",
            a.duration
        )));
    }
    if !(a.delay_ms.is_finite() && (0.0..=10_000.0).contains(&a.delay_ms)) {
        return Err(Failure::from(format!(
            "--delay-ms must be within 0..=10000 (got {})",
            a.delay_ms
        )));
    }
    if !(0.0..=1.0).contains(&a.loss) {
        return Err(Failure::from(format!(
            "--loss must be a fraction in [0, 1] (got {})",
            a.loss
        )));
    }
    let link = Impairment::delay_loss(a.delay_ms.round() as u32, a.loss, a.seed);
    if !(a.stiffness.is_finite() && a.stiffness > 0.0 && a.damping.is_finite() && a.damping >= 0.0)
    {
        return Err(Failure::from(format!(
            "--stiffness must be > 0 and --damping ≥ 0 (got {}, {})",
            a.stiffness, a.damping
        )));
    }
    if a.live || a.master != "sim" || a.slave != "sim" {
        return crate::teleop_live::run(a, link);
    }
    if let Some(o) = [(a.push.is_some(), "--push"), (a.no_rt, "--no-rt")]
        .iter()
        .chain(&[
            (a.master_device_file.is_some(), "--master-device-file"),
            (a.slave_device_file.is_some(), "--slave-device-file"),
            (a.allow_remote_device, "--allow-remote-device"),
        ])
        .find(|o| o.0)
    {
        return Err(Failure::from(format!(
            "{}: only with --live (two devices in real time)\n    fix: add --live",
            o.1
        )));
    }
    let cfg = config(a, link);
    if a.stability {
        return stability(a, &cfg);
    }
    let r = run_teleop(&cfg).map_err(Failure::error)?;
    outln!(
        "teleop: master sim, slave sim, {}{:.1} s at 1 kHz, round trip {} ms, loss {:.1} % each way, TDPA {}, velocities {}",
        match a.architecture {
            ArchitectureArg::PositionForce => "",
            ArchitectureArg::FourChannel => "four-channel (C2 = C3 = 1, C5 = C6 = 0), ",
        },
        a.duration,
        2 * link.delay,
        a.loss * 100.0,
        if a.no_tdpa { "off" } else { "on" },
        if a.filtered_velocity { "filtered (50 Hz)" } else { "unfiltered rate" }
    );
    outln!(
        "the grip's target moves {:.0} mm left at {:.0} mm/s from {} s; the slave's wall is {:.0} mm left ({} N/m)",
        -cfg.push[0] * 1e3,
        cfg.push_speed * 1e3,
        cfg.push_at,
        -cfg.wall_x * 1e3,
        cfg.k_wall
    );
    outln!(
        "network: energy in {:.6} J, out {:.6} J, created {:.6} J (≤ 0 is passive); dissipated by TDPA {:.6} J",
        r.network.energy_in,
        r.network.energy_out,
        r.network.created,
        r.dissipated
    );
    outln!(
        "plants: energy created {:.6} J as the two devices really received it (applied force × true displacement per period; the ports book it against their filtered velocities)",
        r.plant_created
    );
    outln!(
        "contact (last second): wall force on the slave {:.3} N, force of the master on the hand {:.3} N, mean |difference| {:.3} N",
        r.wall_force,
        r.master_force,
        r.force_error
    );
    outln!(
        "largest master force {:.3} N; deepest slave penetration {:.2} mm; master–slave separation at the end {:.2} mm",
        r.max_master_force,
        r.max_penetration * 1e3,
        r.separation * 1e3
    );
    match r.fault {
        None => Ok(Status::Clean),
        Some(f) => {
            outln!(
                "stopped: a device fault ({f}) after {:.3} s",
                r.samples as f64 * 1e-3
            );
            Ok(Status::SafetyStop)
        }
    }
}
