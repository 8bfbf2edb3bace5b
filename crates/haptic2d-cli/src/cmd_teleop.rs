//! `haptic2d teleop --master sim --slave sim`: bilateral teleoperation of two simulated
//! twin-pantograph devices across a simulated link (issue 41 item 4, first part; docs/TELEOP.md).
//! A gripping hand pushes the master; the slave follows through a virtual coupling and touches a
//! wall; the coupling's reaction comes back, so the contact is felt at the master. Simulated time
//! (`haptic2d_lab::network::teleop`): deterministic, as fast as the machine goes.

use haptic2d_lab::network::{run_teleop, Impairment, Teleop};

use crate::exit::{Failure, Status};
use crate::outln;

/// `teleop`'s options.
#[derive(clap::Args, Debug)]
pub struct TeleopArgs {
    /// The master device: `sim` (the simulated twin pantograph, pushed by a simulated grip).
    #[arg(long, default_value = "sim")]
    pub master: String,
    /// The slave device: `sim` (the simulated twin pantograph, with a wall 5 mm to its left).
    #[arg(long, default_value = "sim")]
    pub slave: String,
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
    for (which, v) in [("--master", &a.master), ("--slave", &a.slave)] {
        if v != "sim" {
            return Err(Failure::from(format!(
                "{which} {v}: only `sim` (the simulated twin pantograph) is built so far\n    fix: {which} sim"
            )));
        }
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
    let cfg = Teleop {
        duration: a.duration,
        filtered_velocity: a.filtered_velocity,
        ..Teleop::new(link, !a.no_tdpa)
    };
    let r = run_teleop(&cfg).map_err(Failure::error)?;
    outln!(
        "teleop: master sim, slave sim, {:.1} s at 1 kHz, round trip {} ms, loss {:.1} % each way, TDPA {}, velocities {}",
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
