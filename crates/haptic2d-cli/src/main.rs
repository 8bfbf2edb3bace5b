//! `haptic2d`: the command-line tool of the haptic2d project.

mod cmd_check;
mod cmd_device_check;
mod cmd_devices;
mod cmd_emulate;
mod cmd_log;
mod cmd_reproduce;
mod cmd_run;
mod cmd_scenes;
mod cmd_simulate;
mod cmd_stability;
mod cmd_sweep;
mod controller_file;
mod csv_out;
mod device_arg;
mod exit;
mod foxglove_live;
mod grip_twist;
mod hand_arg;
mod haply_arg;
mod inverse3_arg;
mod pipe;
mod rig_system;
mod run_log;
mod run_rig;
mod run_view;
mod scene_arg;
mod udp_arg;
mod world_mcap;

use clap::{Parser, Subcommand};
use exit::{Failure, Status};
use std::path::PathBuf;
use std::process::ExitCode;

/// Haptic rendering of planar rigid-body motion: a passive planar world, contact and friction models,
/// and a simulated twin-pantograph haptic device.
#[derive(Parser, Debug)]
#[command(
    name = "haptic2d",
    version,
    about = "Haptic rendering of planar rigid-body motion: a passive planar world, contact and friction models, and a simulated twin-pantograph haptic device.",
    long_about = None,
    after_help = exit::EXIT_CODES_HELP
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run the haptic loop: device, controller and world at the control rate (default: box-in-walls,
    /// simulated device, four-channel controller, 1000 Hz); prints a timing summary at exit.
    Run(cmd_run::RunArgs),
    /// Simulate a scene's world alone (no device), headless and as fast as possible, writing a CSV.
    Simulate {
        /// A scene file path, or a built-in scene name (see `haptic2d scenes`).
        scene: String,
        /// Simulated duration (s).
        #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
        duration: f64,
        /// Output file: MCAP when it ends in .mcap (docs/LOGS.md), else CSV (docs/CSV.md). Without
        /// it, only a summary is printed.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Control rate (Hz), overriding the scene's `world.rate`.
        #[arg(long, allow_negative_numbers = true)]
        rate: Option<f64>,
        /// Keep every K-th sample in the CSV.
        #[arg(long, default_value_t = 1)]
        every: u64,
        /// Exit with status 5 when the energy excess exceeds the §13.1 bound (always a warning).
        #[arg(long)]
        strict: bool,
    },
    /// List the built-in scenes.
    Scenes,
    /// A stand-in device on a pseudo-terminal, speaking the real protocol: `emulate haply` (first
    /// stdout line `pty: PATH`; then `run --device haply:PATH`).
    Emulate(cmd_emulate::EmulateArgs),
    /// List the serial ports with their USB ids (Haply boards marked).
    Devices,
    /// Device tools: `device check --device haply:PATH [--pulse]`.
    Device {
        #[command(subcommand)]
        command: cmd_device_check::DeviceCommand,
    },
    /// Validate a scene file and explain every problem found.
    Check {
        /// A scene file path, or a built-in scene name.
        scene: String,
        /// Accept bodies that start overlapping (reported as a warning instead of an error; the
        /// scene key `world.allow_initial_overlap = true` does the same).
        #[arg(long)]
        allow_overlap: bool,
    },
    /// Reproduce the paper's figures (Fig. 4 walls, Figs. 5–6 walls with the device, Fig. 7 peg in
    /// hole, Figs. 8–11 peg with the device) as CSV data, SVG/PNG plots, metrics.json and REPORT.md.
    Reproduce {
        /// Which figure: all, fig4, fig5, fig7 or fig8.
        #[arg(default_value = "all")]
        figure: String,
        /// Output folder.
        #[arg(long, default_value = "reproduction")]
        out: PathBuf,
        /// Exit with an error if any case does not reproduce the paper's claim.
        #[arg(long)]
        strict: bool,
        /// The controller that carries the claims of Figs. 5–6 and 8–11 instead of the default
        /// (architecture and gains from a file; examples in controllers/).
        #[arg(long, value_name = "FILE.toml")]
        controller_file: Option<PathBuf>,
    },
    /// The loop's stability per axis with the hand held and released: right-most poles, sampled-data
    /// growth rate and a verdict, plus a plot of the poles against the hand's impedance.
    Stability(cmd_stability::StabilityArgs),
    /// Logs: `log info FILE` (channels, counts, duration, timing summary), `log convert IN OUT`
    /// (tick logs between CSV and MCAP, by extension).
    #[command(subcommand)]
    Log(cmd_log::LogCmd),
    /// Parameter sweeps; `walls`: stiffness × damping of every wall law, classified by energy gain.
    Sweep {
        /// What to sweep: walls.
        target: String,
        /// Sample rate (Hz).
        #[arg(long, default_value_t = 500.0, allow_negative_numbers = true)]
        rate: f64,
        /// Grid points per axis (2..=64).
        #[arg(long, default_value_t = 12)]
        points: usize,
        /// Output folder.
        #[arg(long, default_value = "reproduction/sweep-walls")]
        out: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Broken pipes (pipe.rs): `run` and `emulate` keep SIGPIPE ignored (their sockets and ports
    // see EPIPE as an error they handle; `run` prints through `outln!` and ends of SIGPIPE after its
    // cleanup); `simulate --out` finishes its file first; printing commands just end quietly.
    match &cli.command {
        Command::Run(_) | Command::Emulate(_) => {}
        Command::Simulate { out: Some(_), .. } => pipe::stop_on_sigpipe(),
        _ => pipe::quiet_on_closed_pipe(),
    }
    let result = match cli.command {
        Command::Emulate(args) => return cmd_emulate::run(&args),
        Command::Devices => return cmd_devices::run(),
        Command::Device { command } => return cmd_device_check::run(&command),
        Command::Run(args) => cmd_run::run(&args),
        Command::Simulate {
            scene,
            duration,
            out,
            rate,
            every,
            strict,
        } => cmd_simulate::run(&cmd_simulate::SimulateArgs {
            scene: &scene,
            duration,
            out: out.as_deref(),
            rate,
            every,
            strict,
        }),
        Command::Scenes => cmd_scenes::run()
            .map(|()| Status::Clean)
            .map_err(Failure::from),
        Command::Stability(args) => cmd_stability::run(&args).map(|()| Status::Clean),
        Command::Check {
            scene,
            allow_overlap,
        } => cmd_check::run(&scene, allow_overlap),
        Command::Reproduce {
            figure,
            out,
            strict,
            controller_file,
        } => cmd_reproduce::run(&figure, &out, strict, controller_file.as_deref())
            .map(|()| Status::Clean),
        Command::Log(cmd) => cmd_log::run(&cmd),
        Command::Sweep {
            target,
            rate,
            points,
            out,
        } => cmd_sweep::run(&target, rate, points, &out).map(|()| Status::Clean),
    };
    // `run`'s output was closed (`| head -1`): everything is finished, end as the pipe says.
    pipe::end_if_broken();
    match result {
        Ok(status) => status.into(),
        Err(f) => {
            eprintln!("error: {}", f.message.trim_end());
            f.status.into()
        }
    }
}
