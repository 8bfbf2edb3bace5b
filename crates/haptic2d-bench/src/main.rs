//! `haptic2d-bench`: haptic2d against rapier2d-f64 on the same scenes, in one process.
//!
//! ```text
//! cargo run --release -p haptic2d-bench -- [--steps 2000] [--warmup 1000] [--scenes pile,sliding]
//! ```
//!
//! Prints a table of median and p99 step times per engine and their ratio (haptic2d / rapier2d), and
//! writes `target/bench/compare.json` and `target/bench/compare.svg` (step time vs N for the pile).
//!
//! **Not apples to apples.** haptic2d is a haptic simulator: penalty (spring–damper) contacts per
//! vertex–edge pair with closest-feature tracking, impulses only at collision, reset-integrator
//! friction, one pass per 1 ms sample and no iteration. rapier2d solves a velocity-level contact
//! problem with Coulomb friction (PGS, soft constraints, 4 iterations by default). They give different
//! trajectories. What is identical is the scene: geometry, masses and inertias, initial state, constant
//! loads (gravity as a body force, the 2 N push), time step (1 ms), number of steps, friction
//! coefficient (μ_s) and restitution; rapier sleeping is disabled because haptic2d never sleeps. See
//! `rapier_world.rs` for the details, and the sanity columns of the table (largest speed and mean
//! height after the run) to check that both engines hold the same scene at rest.

#![warn(missing_docs)]

mod rapier_world;
mod report;
mod scenes;
mod timing;

use clap::Parser;
use std::path::PathBuf;

/// Command-line options.
#[derive(Parser, Debug)]
#[command(
    name = "haptic2d-bench",
    about = "haptic2d vs rapier2d-f64 step times on the same scenes"
)]
struct Args {
    /// Timed steps per engine and scene (1 ms each).
    #[arg(long, default_value_t = 2000)]
    steps: usize,
    /// Untimed steps per engine before timing (the pile settles in them).
    #[arg(long, default_value_t = 1000)]
    warmup: usize,
    /// Steps per interleaved chunk (engines alternate every chunk).
    #[arg(long, default_value_t = 50)]
    chunk: usize,
    /// Comma-separated scene filters (substrings of: pile, box-in-walls, sliding); all when absent.
    #[arg(long, value_delimiter = ',')]
    scenes: Vec<String>,
    /// Comma-separated pile sizes N.
    #[arg(long, value_delimiter = ',', default_values_t = [10usize, 100, 1000])]
    pile: Vec<usize>,
    /// Output folder for compare.json and compare.svg (default: <workspace>/target/bench).
    #[arg(long)]
    out: Option<PathBuf>,
}

fn out_dir(args: &Args) -> PathBuf {
    if let Some(o) = &args.out {
        return o.clone();
    }
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
            manifest
                .ancestors()
                .nth(2)
                .unwrap_or(manifest)
                .join("target")
        });
    target.join("bench")
}

fn run(args: &Args) -> Result<(), String> {
    if args.steps == 0 {
        return Err("--steps must be at least 1".into());
    }
    if args.pile.contains(&0) {
        return Err("--pile sizes must be at least 1".into());
    }
    let cases = scenes::cases(&args.pile, &args.scenes)?;
    if cases.is_empty() {
        return Err(format!(
            "--scenes {:?} matches none of: pile, box-in-walls, sliding",
            args.scenes
        ));
    }
    let mut rows = Vec::new();
    for case in cases {
        let mut h = case.haptic.world;
        let mut r = rapier_world::twin(
            &h,
            scenes::DT,
            case.rapier_friction,
            case.rapier_restitution,
        )
        .map_err(|e| format!("{} n={}: {e}", case.scene, case.n))?;
        eprintln!(
            "{} n={}: {} warm-up + {} timed steps per engine ...",
            case.scene, case.n, args.warmup, args.steps
        );
        let (th, tr) = timing::interleaved(
            args.warmup,
            args.steps,
            args.chunk,
            || h.step(),
            || r.step(),
        );
        let dyn_bodies = || h.bodies.iter().filter(|b| b.is_dynamic());
        let n_dyn = dyn_bodies().count().max(1) as f64;
        let haptic_state = (
            dyn_bodies().map(|b| b.vel.length()).fold(0.0, f64::max),
            dyn_bodies().map(|b| b.pose.pos.y).sum::<f64>() / n_dyn,
        );
        rows.push(report::Row {
            scene: case.scene.to_string(),
            n: case.n,
            haptic_median_us: th.median(),
            haptic_p99_us: th.p99(),
            rapier_median_us: tr.median(),
            rapier_p99_us: tr.p99(),
            haptic_state,
            rapier_state: (r.max_speed(), r.mean_height()),
        });
    }
    print!("{}", report::table(&rows));
    let dir = out_dir(args);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let json = dir.join("compare.json");
    std::fs::write(&json, report::json(&rows)).map_err(|e| format!("{}: {e}", json.display()))?;
    let svg = dir.join("compare.svg");
    report::svg(&rows, &svg)?;
    println!("wrote {} and {}", json.display(), svg.display());
    Ok(())
}

fn main() {
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}
