//! `haptic2d simulate`: the world alone, headless, as fast as possible.
//!
//! Every sample is checked for divergence by the step itself ([`World::step`](haptic2d::world::World::step):
//! a non-finite state or one beyond the
//! documented magnitudes) *before* its row is written, so a CSV never holds a NaN or runaway row.
//! SIGINT/SIGTERM stop the run after the current sample: the rows so far are flushed, the summary
//! printed, and the exit status is 130.

use crate::exit::{Failure, Status};
use crate::scene_arg;
use crate::world_mcap::{OverlapSummary, WorldOut};
use haptic2d::scene::MAX_SAMPLES;
use haptic2d::world::World;
use haptic2d_rt::signal::install_stop_signals;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::Path;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// The energy-excess bound (J) of the passivity check (§13.1 and issue 10's acceptance): a run whose
/// `(kinetic + stored) − (initial + applied work)` ever exceeds it generated energy. Reported as a
/// warning; an error (exit 5) under `--strict`.
pub const ENERGY_EXCESS_BOUND_J: f64 = 1e-3;

/// Options of `haptic2d simulate`.
pub struct SimulateArgs<'a> {
    /// Scene file or built-in name.
    pub scene: &'a str,
    /// Simulated duration (s).
    pub duration: f64,
    /// Output file: MCAP when it ends in .mcap (docs/LOGS.md), else CSV (docs/CSV.md).
    pub out: Option<&'a Path>,
    /// Rate override (Hz).
    pub rate: Option<f64>,
    /// Keep every K-th sample.
    pub every: u64,
    /// Exit 5 on an energy excess above [`ENERGY_EXCESS_BOUND_J`].
    pub strict: bool,
}

/// Runs the scene for `duration` s, writing every `every`-th sample to `out`.
pub fn run(a: &SimulateArgs) -> Result<Status, Failure> {
    let duration = a.duration;
    if !(duration.is_finite() && duration > 0.0) {
        return Err(format!(
            "--duration must be a positive number of seconds, got {duration}\n    fix: e.g. --duration 10"
        )
        .into());
    }
    if a.every == 0 {
        return Err("--every must be at least 1".into());
    }
    let scene = scene_arg::load(a.scene, a.rate)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let mut world = scene.world;
    // The t = 0 state (contacts, stored energy of bodies that start in contact) before the first row.
    world.prime();
    let dt = world.params.dt;
    let samples = (duration / dt).round();
    if samples > MAX_SAMPLES {
        return Err(format!(
            "--duration {duration} s at {} Hz is {samples:e} samples, above the documented cap of {MAX_SAMPLES:e}\n    fix: shorten --duration or lower the rate",
            1.0 / dt
        )
        .into());
    }
    let ticks = samples as u64;
    let stop = install_stop_signals()?;
    // The true largest overlap of two bodies (issue 35) from t = 0; the CSV's column reads it.
    let mut overlap = OverlapSummary::default();
    overlap.sample(&world);
    let mut csv = match a.out {
        Some(p) => {
            let mut w = WorldOut::create(p, &world, a.scene, &scene.name)
                .map_err(|e| Failure::error(format!("cannot write {}: {e}", p.display())))?;
            // The t = 0 row: primed above, so it reports the contacts and stored energy at t = 0.
            w.row(&world, &overlap)
                .map_err(|e| Failure::error(format!("cannot write CSV: {e}")))?;
            Some(w)
        }
        None => None,
    };

    // The bar appears only once the run has taken more than a second.
    let bar = ProgressBar::with_draw_target(Some(ticks), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{spinner} simulating [{bar:40}] {percent}% ({eta} left)")
            .map_err(|e| Failure::error(e.to_string()))?
            .progress_chars("=> "),
    );
    let start = Instant::now();
    let mut shown = false;
    let mut max_excess = f64::NEG_INFINITY;
    let mut max_contacts = 0;
    let mut max_depth = 0.0f64;
    let mut done = 0u64;
    let mut status = Status::Clean;
    for k in 1..=ticks {
        // SIGPIPE under `--out` stops like SIGTERM (the file is finished below, then the process
        // ends of SIGPIPE: pipe.rs).
        if stop.load(Ordering::Relaxed) || crate::pipe::sigpipe_seen() {
            status = Status::Interrupted;
            break;
        }
        if let Some(d) = world.step() {
            // The rows so far are kept (flushed below); this one is not written.
            if let Some(c) = csv.take() {
                c.finish(&overlap)
                    .map_err(|e| Failure::error(format!("cannot write CSV: {e}")))?;
                crate::pipe::restore_after_output();
            }
            bar.finish_and_clear();
            eprintln!(
                "error: the simulation diverged at t = {:.4} s (sample {k}): {d}\n    fix: lower the contact stiffness or raise the rate (see the minimum-mass rule and the bounds, docs/SCENES.md)",
                world.time()
            );
            return Ok(Status::Diverged);
        }
        done = k;
        let e = world.ledger();
        max_excess = max_excess.max(e.excess());
        max_contacts = max_contacts.max(world.contacts().contact_count());
        max_depth = world
            .contact_records()
            .map(|c| -c.d[0])
            .fold(max_depth, f64::max);
        overlap.sample(&world);
        if k % 256 == 0 {
            if !shown && start.elapsed() > Duration::from_secs(1) {
                bar.set_draw_target(ProgressDrawTarget::stderr());
                shown = true;
            }
            bar.set_position(k);
        }
        if let Some(c) = csv.as_mut() {
            if k % a.every == 0 {
                c.row(&world, &overlap)
                    .map_err(|e| Failure::error(format!("cannot write CSV: {e}")))?;
            }
        }
    }
    bar.finish_and_clear();
    if let Some(c) = csv {
        c.finish(&overlap)
            .map_err(|e| Failure::error(format!("cannot write CSV: {e}")))?;
        // The file is whole: a SIGPIPE that stopped the run ends the process now (status 141).
        crate::pipe::restore_after_output();
    }
    let wall = start.elapsed().as_secs_f64();
    let e = world.ledger();
    let simulated = done as f64 * dt;
    if status == Status::Interrupted {
        println!("interrupted by a signal (SIGINT or SIGTERM) after {done} of {ticks} samples");
    }
    println!(
        "{}: {done} samples ({simulated} s at {} Hz) in {wall:.3} s wall ({:.2} µs/sample, {:.1}× real time)",
        scene.name,
        1.0 / dt,
        wall * 1e6 / done.max(1) as f64,
        simulated / wall
    );
    println!(
        "energy: initial {:.6} J, final kinetic {:.6} J + stored {:.6} J, applied work {:.6} J, removed by impacts {:.6} J",
        e.initial, e.kinetic, e.stored, e.applied_work, e.impact_loss
    );
    println!(
        "max (kinetic + stored) − (initial + applied work) over the run: {max_excess:.3e} J; contacts now {}, at most {max_contacts}",
        world.contacts().contact_count(),
    );
    print_contacts(&world, max_depth, &overlap);
    if let Some(p) = a.out {
        println!("wrote {}", p.display());
    }
    if max_excess > ENERGY_EXCESS_BOUND_J {
        eprintln!(
            "warning: the world generated energy: excess {max_excess:.3e} J above the bound {ENERGY_EXCESS_BOUND_J:e} J (§13.1){}",
            if a.strict { "" } else { " (--strict makes this exit 5)" }
        );
        if a.strict && status == Status::Clean {
            status = Status::EnergyExcess;
        }
    }
    Ok(status)
}

/// The summary's contact lines: the deepest contact penetration (now and over the run, `max_depth`
/// in m), the true largest overlap of two bodies, and the large-impact-island counters when any
/// large island occurred.
fn print_contacts(world: &World, max_depth: f64, overlap: &OverlapSummary) {
    let depth_now = world.contact_records().map(|c| -c.d[0]).fold(0.0, f64::max);
    println!(
        "deepest contact penetration: {:.3} mm at the end, {:.3} mm over the run",
        depth_now * 1e3,
        max_depth * 1e3
    );
    let pair = if overlap.max_m > 0.0 {
        format!(
            " (\"{}\" and \"{}\" at t = {:.3} s)",
            overlap.bodies.0, overlap.bodies.1, overlap.at_s
        )
    } else {
        String::new()
    };
    println!(
        "largest overlap of two bodies (separating-axis depth): {:.3} mm at the end, {:.3} mm over the run{pair}",
        overlap.end_m * 1e3,
        overlap.max_m * 1e3
    );
    let budget = world.contacts().impact_budget();
    if budget.islands > 0 {
        // Large impact islands (MODELS §7.7): how often the sweep budget and its passive fallback
        // acted, so a user sees when restitution in a pile was cut.
        println!(
            "large impact islands: {} solved ({} row updates); {} solver phases stopped by the sweep budget ([contact] impact_sweeps), {} of them given fewer sweeps by the sample's row budget ([contact] impact_budget); {} with restitution scaled down to stay passive",
            budget.islands, budget.row_updates, budget.phases_cut, budget.phases_capped, budget.restitution_scaled
        );
    }
    if let Some(line) = chain_budget_line(world) {
        println!("{line}");
    }
}

/// The chain damper's work budget (MODELS §6.7) when it stopped the sweeps of any sample: in how
/// many samples, the budget, and the row updates run; `None` when it never cut.
pub(crate) fn chain_budget_line(world: &World) -> Option<String> {
    let d = world.chain_damper();
    let budget = world.params.chain_row_updates();
    (d.budget_cuts > 0).then(|| {
        format!(
            "chain damper: sweeps stopped by the work budget ([world] chain_budget, {} row updates a sample) in {} samples; {} row updates in all, at most {} in one sample",
            budget.map_or("unbounded".to_string(), |b| b.to_string()),
            d.budget_cuts,
            d.row_updates,
            d.max_row_updates
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic2d::contact::WorkBudget;

    /// The world of built-in scene `name`.
    fn builtin(name: &str) -> World {
        haptic2d::scene::builtin(name, None)
            .expect("a known scene")
            .expect("a valid scene")
            .world
    }

    /// The summary's chain-budget line names the samples the budget cut and the row updates the
    /// damper counted (a landing pile:100 under a budget of one row update: every sample that
    /// wanted a second sweep is cut); a run the budget never cut (the default budget on the
    /// paper's box-in-walls, which has no chains) prints none.
    #[test]
    fn the_chain_budget_line_counts_the_samples_the_budget_cut() {
        let mut w = builtin("pile:100");
        w.params.chain_budget = WorkBudget::RowUpdates(1);
        let mut cut = 0;
        for _ in 0..300 {
            w.step();
            cut += w.chain_damper().last_cut as u64;
        }
        assert!(cut > 0, "the budget never cut");
        let line = chain_budget_line(&w).expect("a line when the budget cut");
        assert!(line.contains("1 row updates a sample"), "{line}");
        assert!(line.contains(&format!(" in {cut} samples;")), "{line}");
        let total = w.chain_damper().row_updates;
        assert!(
            line.contains(&format!("; {total} row updates in all")),
            "{line}"
        );
        let mut quiet = builtin("box-in-walls");
        for _ in 0..300 {
            quiet.step();
        }
        assert_eq!(chain_budget_line(&quiet), None);
    }
}
