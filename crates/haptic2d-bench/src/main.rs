//! `haptic2d-bench`: haptic2d against rapier2d-f64 and Box2D v3 (`boxdd`, 4 and 1 substeps) on the
//! same scenes, in one process.
//!
//! ```text
//! cargo run --release -p haptic2d-bench -- [--quick] [--steps 2000] [--warmup 1000] [--scenes pile,sliding] [--pile 10,100]
//! cargo run --release -p haptic2d-bench --features box2d-avx2 -- ...   # Box2D's AVX2 build
//! cargo run --release -p haptic2d-bench -- --step-times ...              # + steps.csv, steps_*.svg
//! ```
//!
//! Prints a table of median and p99 step times per engine and their ratios (haptic2d / engine), the
//! settle state of every engine after the run (largest speed, bodies above 1 cm/s, mean height,
//! largest overlap), and
//! writes `target/bench/compare.json` and `target/bench/compare.svg` (step time vs N for the pile).
//!
//! **Not apples to apples.** haptic2d is a haptic simulator: penalty (spring–damper) contacts per
//! vertex–edge pair with closest-feature tracking, impulses only at collision, reset-integrator
//! friction, one pass per 1 ms sample and no iteration. rapier2d solves a velocity-level contact
//! problem with Coulomb friction (PGS, soft constraints, 4 iterations by default). They give different
//! trajectories. What is identical is the scene: geometry, masses and inertias, initial state, constant
//! loads (gravity as a body force, the 2 N push), time step (1 ms), number of steps, friction
//! coefficient (μ_s) and restitution; rapier sleeping is disabled because haptic2d never sleeps. See
//! `rapier_world.rs` for the details, and the settle table (largest speed, moving bodies, mean height and
//! overlap after the run) to check that the engines hold the same scene at rest. Box2D: `box2d_world.rs`.

#![warn(missing_docs)]

mod box2d_world;
mod phases;
mod rapier_world;
mod reference;
mod report;
mod rest_time;
mod scenes;
mod settle;
mod state;
mod timing;

use clap::Parser;
use haptic2d::world::World;
use std::path::PathBuf;

/// The instruction set the Rust engines (haptic2d, rapier2d) were compiled for: `x86-64-v3` when
/// built with `RUSTFLAGS="-C target-cpu=x86-64-v3"` (or for a newer CPU), else `baseline` (no
/// AVX2 and FMA; docs/PERFORMANCE.md, "The x86-64-v3 build"). Box2D's C build is chosen by the
/// `box2d-avx2` feature instead.
const RUST_BUILD: &str = if cfg!(all(target_feature = "avx2", target_feature = "fma")) {
    "x86-64-v3"
} else {
    "baseline"
};

/// Command-line options.
#[derive(Parser, Debug)]
#[command(
    name = "haptic2d-bench",
    about = "haptic2d vs rapier2d-f64 and Box2D v3 step times on the same scenes"
)]
struct Args {
    /// Timed steps per engine and scene (1 ms each).
    #[arg(long, default_value_t = 2000)]
    steps: usize,
    /// Untimed steps per engine before timing. With the default (1 s), pile:100 is at rest
    /// before timing starts (every engine from 0.16 s at most), but pile:1000 is still settling:
    /// haptic2d's comes to rest at 2.15 s, Box2D's (4 substeps) at 3.03 s, rapier2d's at 3.31 s
    /// (`--rest-time`).
    #[arg(long, default_value_t = 1000)]
    warmup: usize,
    /// Steps per interleaved chunk (engines alternate every chunk).
    #[arg(long, default_value_t = 50)]
    chunk: usize,
    /// Comma-separated scene filters (substrings of: pile, box-in-walls, sliding, pyramid); all when absent.
    #[arg(long, value_delimiter = ',')]
    scenes: Vec<String>,
    /// Comma-separated pile sizes N.
    #[arg(long, value_delimiter = ',', default_values_t = [10usize, 100, 1000, 5000])]
    pile: Vec<usize>,
    /// Quick run: piles 10 and 100 only, 500 warm-up and 1000 timed steps (overrides those options).
    #[arg(long)]
    quick: bool,
    /// Run haptic2d's global proximity stage whole every N_g-th sample (the old schedule, with its
    /// deadline spike) instead of spread over the samples (the default, `WorldParams::proximity_spread`).
    #[arg(long)]
    no_spread: bool,
    /// Clock that times each step: wall (default) or this thread's CPU time (fairer under load).
    #[arg(long, value_enum, default_value_t = timing::Clock::Wall)]
    clock: timing::Clock,
    /// Instead of timing: run haptic2d alone on the selected cases for this many simulated seconds
    /// and print the settle state every `--every` seconds (no files written).
    #[arg(long)]
    settle: Option<f64>,
    /// Instead of timing: run every engine (untimed) on the selected cases for this many
    /// simulated seconds and print when each came to rest (every body below 1 cm/s from then on,
    /// checked every 10 ms; no files written).
    #[arg(long)]
    rest_time: Option<f64>,
    /// Print interval of `--settle` (simulated s).
    #[arg(long, default_value_t = 0.5)]
    every: f64,
    /// With `--settle`: steps after this simulated time (s) run through `settle::profiled_step`,
    /// for `valgrind --tool=callgrind --toggle-collect='*profiled_step*'`.
    #[arg(long, default_value_t = f64::INFINITY)]
    profile_after: f64,
    /// With `--settle`: the steps after `--profile-after` of every other global period (10 samples)
    /// run each right after a pause, through
    /// `settle::cold_step`, and the summary prints the cold steps' median against the warm ones'
    /// (what a chunk start of the interleaved bench costs). `evict`: write 8 MiB, evicting the
    /// world from the L1 and L2 caches; `evict=MIB`: write MIB MiB (above the 32 MiB L3: to
    /// memory); `idle=MS`: compute for MS ms without touching memory. A trailing `,code` (e.g.
    /// `idle=100,code`) then steps a copy of the world once, untimed: the step's code is warm and
    /// only the world's data is cold. Built with `--features stage-timing`, the summary also
    /// shows each stage's wall time, warm and cold.
    #[arg(long)]
    cold: Option<settle::Cold>,
    /// Law parameter overrides for haptic2d, comma-separated `normal.KEY=V` / `friction.KEY=V`
    /// (e.g. `--set normal.bc=200`); reported in the output.
    #[arg(long, value_delimiter = ',')]
    set: Vec<String>,
    /// Output folder for compare.json and compare.svg (default: <workspace>/target/bench).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Also write every timed step's time of every engine to `steps.csv` in the output folder
    /// (columns scene, n, engine, step, sample, us; `sample` is the engine's sample index since
    /// the start, warm-up included) and plot them, one `steps_<scene>_<n>.svg` per case.
    #[arg(long)]
    step_times: bool,
    /// Also split every engine's timed steps into a landing phase (steps before LANDING_END) and a
    /// settled phase (from SETTLED_FROM): median, p99 and p99/median per phase, haptic2d's ratio
    /// to each peer per phase, and its landing p99 against its settled median (issue 42's
    /// targets). Time from the start with `--warmup 0`, e.g. `--warmup 0 --steps 3000 --phases 1000,2000`.
    #[arg(long, value_name = "LANDING_END,SETTLED_FROM")]
    phases: Option<phases::Phases>,
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
    let quick;
    let args = if args.quick {
        quick = Args {
            steps: 1000,
            warmup: 500,
            pile: vec![10, 100],
            scenes: args.scenes.clone(),
            out: args.out.clone(),
            set: args.set.clone(),
            ..*args
        };
        &quick
    } else {
        args
    };
    if args.steps == 0 {
        return Err("--steps must be at least 1".into());
    }
    if args.pile.contains(&0) {
        return Err("--pile sizes must be at least 1".into());
    }
    if let Some(p) = args.phases {
        p.check(args.steps)?;
    }
    let cases = scenes::cases(&args.pile, &args.scenes)?;
    if cases.is_empty() {
        return Err(format!(
            "--scenes {:?} matches none of: pile, box-in-walls, sliding, pyramid",
            args.scenes
        ));
    }
    if let Some(secs) = args.settle {
        if !(secs.is_finite() && secs > 0.0 && args.every.is_finite() && args.every > 0.0) {
            return Err("--settle and --every must be positive durations in s".into());
        }
        for case in cases {
            let (label, mut h) = haptic_world(args, case.scene, case.n, case.haptic.world)?;
            settle::run(
                &label,
                &mut h,
                scenes::DT,
                secs,
                args.every,
                args.profile_after,
                args.cold,
            );
        }
        return Ok(());
    }
    if let Some(secs) = args.rest_time {
        if !(secs.is_finite() && secs > 0.0) {
            return Err("--rest-time must be a positive duration in s".into());
        }
        for case in cases {
            let (label, mut h) = haptic_world(args, case.scene, case.n, case.haptic.world)?;
            let (mut r, mut b4, mut b1) =
                peers(&h, &label, case.rapier_friction, case.rapier_restitution)?;
            let dynamic: Vec<bool> = h.bodies.iter().map(|b| b.is_dynamic()).collect();
            let dt = scenes::DT;
            let res = {
                let hc = std::cell::RefCell::new(&mut h);
                rest_time::run(
                    &dynamic,
                    dt,
                    secs,
                    &mut || drop(hc.borrow_mut().step()),
                    &mut || {
                        hc.borrow()
                            .bodies
                            .iter()
                            .map(|b| (b.pose.pos, b.pose.angle, b.vel))
                            .collect()
                    },
                )
            };
            println!("{}", rest_time::line(&label, "haptic2d", secs, &res));
            let rc = std::cell::RefCell::new(&mut r);
            let res = rest_time::run(
                &dynamic,
                dt,
                secs,
                &mut || rc.borrow_mut().step(),
                &mut || rc.borrow().poses(),
            );
            println!("{}", rest_time::line(&label, "rapier2d", secs, &res));
            for (name, b) in [("box2d 4 sub", &mut b4), ("box2d 1 sub", &mut b1)] {
                let bc = std::cell::RefCell::new(b);
                let res = rest_time::run(
                    &dynamic,
                    dt,
                    secs,
                    &mut || bc.borrow_mut().step(),
                    &mut || bc.borrow_mut().poses(),
                );
                println!("{}", rest_time::line(&label, name, secs, &res));
            }
        }
        return Ok(());
    }
    let mut rows = Vec::new();
    let mut step_csv = String::from("scene,n,engine,step,sample,us\n");
    for case in cases {
        let (label, mut h) = haptic_world(args, case.scene, case.n, case.haptic.world)?;
        if !args.set.is_empty() {
            eprintln!("{label}: haptic2d with {}", args.set.join(", "));
        }
        let (mut r, mut b4, mut b1) =
            peers(&h, &label, case.rapier_friction, case.rapier_restitution)?;
        eprintln!(
            "{label}: {} warm-up + {} timed steps per engine (4 engines, haptic2d build {}, box2d build {}, {:?} clock) ...",
            args.warmup,
            args.steps,
            RUST_BUILD,
            box2d_world::BUILD,
            args.clock
        );
        // The machine's own spread on a deterministic workload, interleaved like a fifth engine
        // and sized during the warm-up to take haptic2d's median step (`reference.rs`).
        let reference = std::cell::RefCell::new(reference::Reference::new(64 << 10));
        let mut stage_log = Vec::with_capacity(if haptic2d::stage_time::ENABLED {
            args.warmup + args.steps
        } else {
            0
        });
        let mut samples = {
            // haptic2d's stage times, step by step, for the phase table (a `stage-timing` build).
            let log = &mut stage_log;
            let mut fh = || {
                drop(h.step());
                if haptic2d::stage_time::ENABLED {
                    log.push(*h.stage_times());
                }
            };
            let (mut fr, mut f4, mut f1) = (|| r.step(), || b4.step(), || b1.step());
            let mut fref = || reference.borrow_mut().step();
            timing::interleaved(
                args.clock,
                args.warmup,
                args.steps,
                args.chunk,
                &mut [&mut fh, &mut fr, &mut f4, &mut f1, &mut fref],
                &mut |haptic, own| reference.borrow_mut().rescale(haptic, own),
            )
        };
        let reference_samples = samples.pop().unwrap_or(timing::Samples(Vec::new()));
        let reference_bytes = reference.borrow().bytes();
        drop(reference);
        // Step `i` of the timed run is haptic2d's sample `warmup + i`: its median per phase of
        // the global stage's period shows a deadline spike (or its absence) directly.
        let n_g = h.params.proximity_every.max(1) as usize;
        let phase_medians: Vec<String> = (0..n_g)
            .map(|ph| {
                let v: Vec<f64> = samples[0]
                    .0
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| (args.warmup + i) % n_g == ph)
                    .map(|(_, &t)| t)
                    .collect();
                format!("{:.1}", timing::Samples(v).median())
            })
            .collect();
        eprintln!(
            "{label}: haptic2d median µs by sample mod {n_g} (global stage {}): {}",
            if h.params.proximity_spread {
                "spread"
            } else {
                "whole at 0"
            },
            phase_medians.join(" ")
        );
        let haptic_poses: Vec<_> = h
            .bodies
            .iter()
            .map(|b| (b.pose.pos, b.pose.angle, b.vel))
            .collect();
        let box2d = if box2d_world::BUILD == "avx2" {
            "box2d_avx2"
        } else {
            "box2d"
        };
        let keys = [
            "haptic2d".to_string(),
            "rapier2d".to_string(),
            box2d.to_string(),
            format!("{box2d}_1sub"),
        ];
        if args.step_times {
            let mut all_keys = keys.to_vec();
            all_keys.push(report::REFERENCE.to_string());
            let all: Vec<&timing::Samples> = samples.iter().chain([&reference_samples]).collect();
            for (key, t) in all_keys.iter().zip(&all) {
                report::step_rows(&mut step_csv, case.scene, case.n, key, args.warmup, t);
            }
            let dir = out_dir(args);
            std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            let svg = dir.join(format!("steps_{}_{}.svg", case.scene, case.n));
            report::steps_svg(&label, &all_keys, &all, &svg)?;
        }
        if let Some(p) = args.phases {
            let named: Vec<(&str, &timing::Samples)> = keys
                .iter()
                .map(String::as_str)
                .zip(samples.iter())
                .collect();
            print!("{}", phases::table(&label, p, &named));
            if haptic2d::stage_time::ENABLED {
                let timed = &stage_log[args.warmup.min(stage_log.len())..];
                print!("{}", phases::stage_table(&label, p, &samples[0], timed));
            }
        }
        let states = [
            state::of(&h, &haptic_poses),
            state::of(&h, &r.poses()),
            state::of(&h, &b4.poses()),
            state::of(&h, &b1.poses()),
        ];
        let engines = keys
            .into_iter()
            .zip(samples.iter().zip(states))
            .map(|(key, (t, state))| report::EngineResult {
                key,
                median_us: t.median(),
                p99_us: t.p99(),
                p99_warm_us: t.without_chunk_starts(args.chunk).p99(),
                chunk_start_us: t.chunk_starts(args.chunk).median(),
                state,
            })
            .collect();
        rows.push(report::Row {
            scene: case.scene.to_string(),
            n: case.n,
            engines,
            reference: report::ReferenceResult {
                bytes: reference_bytes,
                median_us: reference_samples.median(),
                p99_us: reference_samples.p99(),
                p99_warm_us: reference_samples.without_chunk_starts(args.chunk).p99(),
                chunk_start_us: reference_samples.chunk_starts(args.chunk).median(),
            },
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
    if args.step_times {
        let csv = dir.join("steps.csv");
        std::fs::write(&csv, step_csv).map_err(|e| format!("{}: {e}", csv.display()))?;
        println!(
            "wrote {} and steps_<scene>_<n>.svg beside it",
            csv.display()
        );
    }
    Ok(())
}

/// The label of a case ("pile n=100") and its haptic2d world `h` with `--no-spread` and `--set`
/// applied.
fn haptic_world(
    args: &Args,
    scene: &str,
    n: usize,
    mut h: World,
) -> Result<(String, World), String> {
    let label = format!("{scene} n={n}");
    h.params.proximity_spread = !args.no_spread;
    settle::apply(&mut h, &args.set).map_err(|e| format!("{label}: {e}"))?;
    Ok((label, h))
}

/// The peers' twins of `h` at the benchmark's period, with friction `mu` and restitution `e`:
/// Rapier, Box2D with 4 substeps (its default) and Box2D with 1.
fn peers(
    h: &World,
    label: &str,
    mu: f64,
    e: f64,
) -> Result<
    (
        rapier_world::RapierTwin,
        box2d_world::Box2dTwin,
        box2d_world::Box2dTwin,
    ),
    String,
> {
    let err = |x: String| format!("{label}: {x}");
    Ok((
        rapier_world::twin(h, scenes::DT, mu, e).map_err(err)?,
        box2d_world::twin(h, scenes::DT, 4, mu, e).map_err(err)?,
        box2d_world::twin(h, scenes::DT, 1, mu, e).map_err(err)?,
    ))
}

fn main() {
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}
