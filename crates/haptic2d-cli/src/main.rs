//! `haptic2d`: the command-line tool of the haptic2d project.

mod cmd_check;
mod cmd_device;
mod cmd_device_check;
mod cmd_device_identify;
mod cmd_devices;
mod cmd_emulate;
mod cmd_log;
mod cmd_remote_device;
mod cmd_reproduce;
mod cmd_run;
mod cmd_scenes;
mod cmd_serve_world;
mod cmd_simulate;
mod cmd_stability;
mod cmd_study;
mod cmd_sweep;
mod cmd_teleop;
mod controller_file;
mod csv_out;
mod device_arg;
mod end_io;
mod exit;
mod foxglove_live;
mod grip_twist;
mod hand_arg;
mod haply_arg;
mod loop_end;
mod pipe;
mod push_arg;
mod real_end;
mod rt_thread;
mod run_log;
mod run_rig;
mod run_view;
mod scene_arg;
mod serve_conn;
mod serve_present;
mod slave_plant;
mod study_browser;
mod study_buttons;
mod study_mcap;
mod study_present;
mod study_serve;
mod teleop_end;
mod teleop_live;
mod teleop_report;
mod world_link_arg;
mod world_mcap;
mod worst_step;

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
    max_term_width = 100,
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
    #[command(after_help = examples_help(RUN_EXAMPLES))]
    Run(cmd_run::RunArgs),
    /// Simulate a scene's world alone (no device), headless and as fast as possible, writing a CSV.
    #[command(after_help = examples_help(SIMULATE_EXAMPLES))]
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
    /// A stand-in device speaking the real protocol, at real-time priority: `emulate haply` (a Haply
    /// board on a pseudo-terminal) or `emulate inverse3` (Haply's Inverse Service on loopback).
    #[command(after_help = examples_help(EMULATE_EXAMPLES))]
    Emulate(cmd_emulate::EmulateArgs),
    /// List the serial ports with their USB ids (Haply boards marked).
    Devices,
    /// Device tools: `device check --device haply:PATH [--pulse]`, `device identify`.
    Device {
        #[command(subcommand)]
        command: cmd_device::DeviceCommand,
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
    #[command(after_help = examples_help(REPRODUCE_EXAMPLES))]
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
    #[command(after_help = examples_help(STABILITY_EXAMPLES))]
    Stability(cmd_stability::StabilityArgs),
    /// Logs: `log info FILE` (channels, counts, duration, timing summary), `log convert IN OUT`
    /// (tick logs between CSV and MCAP, by extension).
    #[command(subcommand, after_help = examples_help(LOG_EXAMPLES))]
    Log(cmd_log::LogCmd),
    /// Perceptual studies (docs/STUDIES.md): `study run FILE --observer simulated`, `study analyse
    /// DIR`, `study check FILE`.
    #[command(subcommand, after_help = examples_help(STUDY_EXAMPLES))]
    Study(cmd_study::StudyCmd),
    /// The world side of a loop split at the network: serves SCENE to one `remote-device` over
    /// authenticated UDP, with TDPA on its port (docs/TELEOP.md).
    #[command(after_help = examples_help(cmd_serve_world::EXAMPLES))]
    ServeWorld(cmd_serve_world::ServeWorldArgs),
    /// The device side of a loop split at the network (an alias of `run --device sim --world
    /// udp:HOST:PORT`): the simulated twin pantograph with its local safety (docs/TELEOP.md; `run
    /// --world` takes a real device too).
    #[command(after_help = examples_help(cmd_remote_device::EXAMPLES))]
    RemoteDevice(cmd_remote_device::RemoteDeviceArgs),
    /// Bilateral teleoperation of two devices across a simulated link, with TDPA: the slave's
    /// contact felt at the master; two simulated devices in simulated time, or any two devices
    /// (simulated twin, Haply board, UDP device, Inverse3) in real time with `--live`
    /// (docs/TELEOP.md).
    Teleop(cmd_teleop::TeleopArgs),
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

/// An example of a subcommand's `--help`: what it does, and the command line (words split at
/// spaces, no quoting; `cli_tests::every_example_parses` parses each one).
pub(crate) type Example = (&'static str, &'static str);

const RUN_EXAMPLES: &[Example] = &[
    (
        "Headless for 10 s, every tick logged to MCAP",
        "haptic2d run --headless --duration 10 --log run.mcap",
    ),
    (
        "A Haply 2DIY on a serial port, with its device file",
        "haptic2d run --device haply:/dev/ttyACM0 --device-file devices/haply-2diy-gen3.toml",
    ),
    (
        "Peg in hole with the paper's controller, display on http://127.0.0.1:8080/",
        "haptic2d run peg-in-hole --controller-file controllers/paper-4ch.toml",
    ),
    (
        "A scripted hand push on the simulated device, 5 s, CSV log",
        "haptic2d run --headless --duration 5 --hand script:0.6,-2,0,0,1 --log run.csv",
    ),
    (
        "Live view in Foxglove (ws://127.0.0.1:8765), normal scheduling",
        "haptic2d run --foxglove --no-rt",
    ),
];

const SIMULATE_EXAMPLES: &[Example] = &[
    (
        "100 boxes for 5 s, every sample to CSV",
        "haptic2d simulate pile:100 --duration 5 --out pile.csv",
    ),
    (
        "The peg scene to MCAP (open in Foxglove)",
        "haptic2d simulate peg-in-hole --duration 3 --out peg.mcap",
    ),
    (
        "A scene file at 2 kHz, every 10th sample kept",
        "haptic2d simulate scenes/box-in-walls.toml --rate 2000 --every 10 --out box.csv",
    ),
    (
        "Exit with status 5 on an energy excess",
        "haptic2d simulate box-in-walls --strict",
    ),
];

const EMULATE_EXAMPLES: &[Example] = &[
    (
        "A Haply 2DIY gen3 on a pseudo-terminal (then `run --device haply:PATH`)",
        "haptic2d emulate haply --device-file devices/haply-2diy-gen3.toml",
    ),
    (
        "The twin-pantograph Haply rig for 30 s, at normal priority",
        "haptic2d emulate haply --device-file haply-twin --duration 30 --no-rt",
    ),
    (
        "An Inverse3 service on a free loopback port (a build with --features inverse3)",
        "haptic2d emulate inverse3 --bind 127.0.0.1:0",
    ),
];

const LOG_EXAMPLES: &[Example] = &[
    (
        "Channels, counts, duration and timing of a run's log",
        "haptic2d log info run.mcap",
    ),
    (
        "Rows and columns of a CSV tick log",
        "haptic2d log info run.csv",
    ),
    (
        "An MCAP tick log to CSV",
        "haptic2d log convert run.mcap run.csv",
    ),
    (
        "A CSV tick log to MCAP",
        "haptic2d log convert ticks.csv ticks.mcap",
    ),
];

const STUDY_EXAMPLES: &[Example] = &[
    (
        "Check a study file and explain every problem",
        "haptic2d study check studies/stiffness-walls.toml",
    ),
    (
        "Run a session on the simulated observer (a model, not data); it resumes if cut",
        "haptic2d study run studies/stiffness-walls.toml --observer simulated --out study-data",
    ),
    (
        "The same study for a second pseudonymous participant",
        "haptic2d study run studies/stiffness-walls.toml --observer simulated --participant sim02",
    ),
    (
        "Fit psychometric functions, JNDs and Weber fractions, with plots",
        "haptic2d study analyse study-data/sub-sim01/ses-1",
    ),
];

const REPRODUCE_EXAMPLES: &[Example] = &[
    (
        "Every figure; exit with an error if a claim is not reproduced",
        "haptic2d reproduce all --strict",
    ),
    (
        "Fig. 4 (walls) into a folder of its own",
        "haptic2d reproduce fig4 --out repro-fig4",
    ),
    (
        "Figs. 8–11 with the paper's controller",
        "haptic2d reproduce fig8 --controller-file controllers/paper-4ch.toml",
    ),
];

const STABILITY_EXAMPLES: &[Example] = &[
    (
        "The paper's controller on the default scene",
        "haptic2d stability --controller-file controllers/paper-4ch.toml",
    ),
    (
        "A Haply 2DIY's axes with the coupling controller",
        "haptic2d stability --controller coupling --device-file devices/haply-2diy-gen3.toml",
    ),
    (
        "Figs. 8–11's mapping (scale 2) at 2 kHz, no extra delay",
        "haptic2d stability peg-in-hole --scale 2 --rate 2000 --delay 0 --out stability-peg",
    ),
];

/// The `Examples:` block after a subcommand's help: each example's description as a `#` comment,
/// then its command line.
fn examples_help(examples: &[Example]) -> String {
    let mut s = String::from("Examples:");
    for (what, line) in examples {
        s.push_str(&format!("\n  # {what}\n  {line}"));
    }
    s
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Broken pipes (pipe.rs): `run` and `emulate` keep SIGPIPE ignored (their sockets and ports
    // see EPIPE as an error they handle; `run` prints through `outln!` and ends of SIGPIPE after its
    // cleanup); `simulate --out` finishes its file first; printing commands just end quietly.
    match &cli.command {
        Command::Run(_)
        | Command::Emulate(_)
        | Command::ServeWorld(_)
        | Command::RemoteDevice(_) => {}
        Command::Simulate { out: Some(_), .. } | Command::Log(cmd_log::LogCmd::Convert { .. }) => {
            pipe::stop_on_sigpipe()
        }
        _ => pipe::quiet_on_closed_pipe(),
    }
    let result = match cli.command {
        Command::Emulate(args) => return cmd_emulate::run(&args),
        Command::Devices => return cmd_devices::run(),
        Command::Device { command } => return cmd_device::run(&command),
        Command::Run(args) => cmd_run::run(&args),
        Command::ServeWorld(args) => cmd_serve_world::run(&args),
        Command::RemoteDevice(args) => cmd_remote_device::run(&args),
        Command::Teleop(args) => cmd_teleop::run(&args),
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
        Command::Study(cmd) => cmd_study::run(&cmd),
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

#[cfg(test)]
mod cli_tests {
    use super::*;

    /// Every example in a `--help` is accepted by the parser, as the subcommand it documents.
    #[test]
    fn every_example_parses() {
        let lists: [(&str, &[Example]); 11] = [
            ("serve-world", cmd_serve_world::EXAMPLES),
            ("remote-device", cmd_remote_device::EXAMPLES),
            ("run", RUN_EXAMPLES),
            ("simulate", SIMULATE_EXAMPLES),
            ("emulate", EMULATE_EXAMPLES),
            ("emulate", cmd_emulate::HAPLY_EXAMPLES),
            ("emulate", cmd_emulate::INVERSE3_EXAMPLES),
            ("log", LOG_EXAMPLES),
            ("reproduce", REPRODUCE_EXAMPLES),
            ("stability", STABILITY_EXAMPLES),
            ("study", STUDY_EXAMPLES),
        ];
        for (cmd, examples) in lists {
            assert!(
                (3..=5).contains(&examples.len()),
                "{cmd}: {} examples",
                examples.len()
            );
            for (_, line) in examples {
                let words: Vec<&str> = line.split_whitespace().collect();
                assert_eq!(&words[..2], ["haptic2d", cmd], "{line}");
                if let Err(e) = Cli::try_parse_from(&words) {
                    panic!("{line}: {e}");
                }
            }
        }
    }

    /// A wrong option in an example would be caught (the check above can fail).
    #[test]
    fn a_misspelt_example_is_refused() {
        assert!(Cli::try_parse_from(["haptic2d", "run", "--headles"]).is_err());
        assert!(Cli::try_parse_from(["haptic2d", "log", "info"]).is_err());
        // Each emulator has only its own options.
        assert!(
            Cli::try_parse_from(["haptic2d", "emulate", "haply", "--bind", "127.0.0.1:0"]).is_err()
        );
        assert!(Cli::try_parse_from(["haptic2d", "emulate", "inverse3", "--board", "m0"]).is_err());
    }
}
