//! Steps a built-in scene for a number of seconds and nothing else, for instruction counts of the
//! step's stages under callgrind without the CLI's output (issue 42; docs/PERFORMANCE.md).
//!
//! `cargo build --release -p haptic2d --example step_profile`, then
//! `valgrind --tool=callgrind target/release/examples/step_profile pile:100 3`.

use haptic2d::scene::builtin;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(name), Some(duration)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: step_profile SCENE DURATION_S (a built-in scene, e.g. pile:100 3)");
        std::process::exit(2);
    };
    let duration: f64 = duration.parse().expect("DURATION_S: a number of seconds");
    let scene = match builtin(name, None) {
        Some(Ok(scene)) => scene,
        Some(Err(e)) => panic!("{name}: {e}"),
        None => panic!("no built-in scene {name}"),
    };
    let mut world = scene.world;
    world.prime();
    let ticks = (duration / world.params.dt).round() as u64;
    for _ in 0..ticks {
        if let Some(d) = world.step() {
            panic!("diverged: {d:?}");
        }
    }
    println!("{name}: {ticks} samples stepped");
}
