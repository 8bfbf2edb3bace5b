//! `haptic2d simulate`: the world alone, headless, as fast as possible.

use crate::csv_out::WorldCsv;
use crate::scene_arg;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::time::{Duration, Instant};

/// Runs `scene` for `duration` s, writing every `every`-th sample to `out`.
pub fn run(
    scene: &str,
    duration: f64,
    out: Option<&Path>,
    rate: Option<f64>,
    every: u64,
) -> Result<(), String> {
    if !(duration.is_finite() && duration > 0.0) {
        return Err(format!(
            "--duration must be a positive number of seconds, got {duration}"
        ));
    }
    if every == 0 {
        return Err("--every must be at least 1".into());
    }
    let scene = scene_arg::load(scene, rate)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let mut world = scene.world;
    let dt = world.params.dt;
    let ticks = (duration / dt).round() as u64;
    let mut csv = match out {
        Some(p) => {
            let f = File::create(p).map_err(|e| format!("cannot create {}: {e}", p.display()))?;
            let mut w = WorldCsv::new(BufWriter::with_capacity(1 << 20, f), &world)
                .map_err(|e| format!("cannot write {}: {e}", p.display()))?;
            w.row(&world).map_err(|e| e.to_string())?;
            Some(w)
        }
        None => None,
    };

    // The bar appears only once the run has taken more than a second.
    let bar = ProgressBar::with_draw_target(Some(ticks), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{spinner} simulating [{bar:40}] {percent}% ({eta} left)")
            .map_err(|e| e.to_string())?
            .progress_chars("=> "),
    );
    let start = Instant::now();
    let mut shown = false;
    let mut max_excess = f64::NEG_INFINITY;
    let mut max_contacts = 0;
    let mut max_depth = 0.0f64;
    for k in 1..=ticks {
        world.step();
        let e = world.ledger();
        max_excess = max_excess.max(e.excess());
        if k % 256 == 0 {
            if let Some(b) = world.bodies.iter().find(|b| {
                !(b.pose.pos.is_finite()
                    && b.pose.angle.is_finite()
                    && b.vel.is_finite()
                    && b.omega.is_finite())
            }) {
                return Err(format!(
                    "the simulation diverged at t = {:.4} s: body \"{}\" has a non-finite state\n    fix: lower the contact stiffness or raise the rate (see the minimum-mass rule, docs/SCENES.md)",
                    world.time(),
                    b.name
                ));
            }
            max_contacts = max_contacts.max(world.contacts().contact_count());
            max_depth = world
                .contact_records()
                .map(|c| -c.d[0])
                .fold(max_depth, f64::max);
            if !shown && start.elapsed() > Duration::from_secs(1) {
                bar.set_draw_target(ProgressDrawTarget::stderr());
                shown = true;
            }
            bar.set_position(k);
        }
        if let Some(c) = csv.as_mut() {
            if k % every == 0 {
                c.row(&world)
                    .map_err(|e| format!("cannot write CSV: {e}"))?;
            }
        }
    }
    bar.finish_and_clear();
    if let Some(c) = csv {
        c.finish().map_err(|e| format!("cannot write CSV: {e}"))?;
    }
    let wall = start.elapsed().as_secs_f64();
    let e = world.ledger();
    println!(
        "{}: {ticks} samples ({duration} s at {} Hz) in {wall:.3} s wall ({:.2} µs/sample, {:.1}× real time)",
        scene.name,
        1.0 / dt,
        wall * 1e6 / ticks as f64,
        duration / wall
    );
    println!(
        "energy: initial {:.6} J, final kinetic {:.6} J + stored {:.6} J, applied work {:.6} J, removed by impacts {:.6} J",
        e.initial, e.kinetic, e.stored, e.applied_work, e.impact_loss
    );
    println!(
        "max (kinetic + stored) − (initial + applied work) over the run: {max_excess:.3e} J; contacts now {}, at most {max_contacts}",
        world.contacts().contact_count(),
    );
    let depth_now = world.contact_records().map(|c| -c.d[0]).fold(0.0, f64::max);
    println!(
        "deepest contact penetration: {:.3} mm at the end, {:.3} mm over the run (sampled every 256 samples)",
        depth_now * 1e3,
        max_depth * 1e3
    );
    if let Some(p) = out {
        println!("wrote {}", p.display());
    }
    Ok(())
}
