//! Criterion benchmark `tick`: one full haptic tick — simulated-device encoder read, kinematics,
//! velocity filter, hand-wrench observer, four-channel controller, world step (proximity, contacts,
//! laws, integration) and redundancy resolution — for box-in-walls and peg-in-hole at 1 kHz. Budget
//! (DESIGN §6): ≤ 10 µs.
//!
//! The simulated plant is advanced between ticks (so contacts come and go as in a run) but outside the
//! timed region; its own cost (RK4 sub-steps of the lumped dynamics) is the separate `plant_step`
//! benchmark.

use criterion::{criterion_group, criterion_main, Criterion};
use haptic2d::device::{HandModel, SimDevice};
use haptic2d::haptic::{HapticConfig, HapticSystem, SafetyConfig};
use haptic2d::scene::builtin;
use std::hint::black_box;
use std::time::{Duration, Instant};

fn setup(scene: &str, hand: HandModel) -> (HapticSystem, SimDevice, HandModel) {
    let world = builtin(scene, Some(1000.0))
        .expect("built-in")
        .expect("valid")
        .world;
    let config = HapticConfig::default();
    // The steady-state tick, without the start-up ramp: a hand that pushes from the first tick
    // would carry the handle past the workspace while the torques ramp in (a safety stop, by
    // design; the ramp's own path is tested in `tests/it/startup_ramp.rs`).
    let safety = SafetyConfig {
        ramp_time: 0.0,
        ..SafetyConfig::default()
    };
    let sys = HapticSystem::with_safety(world, &config, safety).expect("system");
    let mut plant = SimDevice::new(&config.device, sys.device_start()).expect("plant");
    plant.substeps = 2;
    (sys, plant, hand)
}

fn bench_scene(c: &mut Criterion, name: &str, scene: &str, hand: HandModel) {
    let (mut sys, mut plant, hand) = setup(scene, hand);
    // Warm up into contact (box: pushed into the wall; peg: squeezed in the hole).
    for _ in 0..1500 {
        let q = plant.encoders().expect("encoders");
        let out = sys.tick(&q);
        plant.step(&out.torques, &hand, sys.dt()).expect("plant");
    }
    c.bench_function(&format!("tick/{name}"), |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let t0 = Instant::now();
                let q = plant.encoders().expect("encoders");
                let out = sys.tick(black_box(&q));
                total += t0.elapsed();
                black_box(&out);
                if plant.step(&out.torques, &hand, sys.dt()).is_err() || out.tripped {
                    // Start over if the run wandered off (does not happen with these hands).
                    (sys, plant, _) = setup(scene, hand);
                }
            }
            total
        })
    });
}

fn tick(c: &mut Criterion) {
    // The box is pushed into the left wall and rests there on two corner contacts.
    bench_scene(
        c,
        "box-in-walls",
        "box-in-walls",
        HandModel::Constant {
            wrench: [-2.0, 0.0, 0.0],
        },
    );
    // The peg rests squeezed in the hole on four contacts with friction, held by the hand.
    let start = {
        let (s, _, _) = setup("peg-in-hole", HandModel::Free);
        s.device_start()
    };
    bench_scene(c, "peg-in-hole", "peg-in-hole", HandModel::grip(start));
    // The plant alone, for reference (not part of a real device's tick).
    let (sys, mut plant, hand) = setup("box-in-walls", HandModel::grip([0.0, 0.14, 0.0]));
    c.bench_function("plant_step/2-substeps", |b| {
        b.iter(|| plant.step(black_box(&[0.0; 4]), &hand, sys.dt()))
    });
}

criterion_group!(benches, tick);
criterion_main!(benches);
