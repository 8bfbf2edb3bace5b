//! `haptic2d check`: validates a scene and explains every problem.

use crate::exit::{Failure, Status};
use crate::scene_arg;

/// Validates `arg` and prints a summary of the scene, or every problem found. `allow_overlap`
/// accepts bodies that start overlapping (then reported as warnings).
pub fn run(arg: &str, allow_overlap: bool) -> Result<Status, Failure> {
    let scene = scene_arg::load_allowing(arg, None, allow_overlap)?;
    let w = &scene.world;
    let dynamic = w.bodies.iter().filter(|b| b.is_dynamic()).count();
    println!("{}: ok", scene.source);
    println!(
        "  {} bodies ({} dynamic, {} fixed), {} convex pieces, {} loads",
        w.bodies.len(),
        dynamic,
        w.bodies.len() - dynamic,
        w.colliders.len(),
        w.loads.len()
    );
    println!(
        "  rate {} Hz, proximity every {} samples, normal law \"{}\", friction \"{}\"",
        1.0 / w.params.dt,
        w.params.proximity_every,
        w.normal.name(),
        w.friction.name()
    );
    println!(
        "  device: {}",
        if scene.device.is_some() {
            "the [device] table's parameters (valid; fields left out keep the spec defaults)"
        } else {
            "spec defaults (no [device] table)"
        }
    );
    for warn in &scene.warnings {
        println!("  warning: {warn}");
    }
    // Speeds beyond what the proximity margin and the swept test guarantee (issue 10).
    for warn in w.speed_warnings() {
        println!("  warning: {warn}");
    }
    Ok(Status::Clean)
}
