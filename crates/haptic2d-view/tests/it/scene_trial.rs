//! Issue 38 item 6: the display's scene-switch gate uses a measured step cost — a timed trial of
//! the new scene, run before the loop starts (never on the haptic thread) — instead of an estimate
//! from the initial state, which was 4–12× too low for a landing pile.

use haptic2d::scene::builtin;
use haptic2d_view::scene_budget::{
    assess, trial, trial_within, TrialEnd, COST_MARGIN, DEFAULT_STEP_FRACTION, MAX_TRIAL_WALL_S,
    TRIAL_S,
};
use std::time::{Duration, Instant};

fn world(name: &str, rate: f64) -> haptic2d::world::World {
    builtin(name, Some(rate)).unwrap().unwrap().world
}

/// Per-step cost (s) of stepping `w` from its current state for `steps` steps, timed like the
/// trial (two copies side by side, the smaller timing of each step), and the p99 of them.
fn running_p99(w: &haptic2d::world::World, steps: usize) -> f64 {
    let (mut a, mut b) = (w.clone(), w.clone());
    let mut c: Vec<f64> = (0..steps)
        .map(|_| {
            let t0 = Instant::now();
            a.step();
            let ta = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            b.step();
            ta.min(t1.elapsed().as_secs_f64())
        })
        .collect();
    c.sort_by(f64::total_cmp);
    c[((0.99 * steps as f64).ceil() as usize).clamp(1, steps) - 1]
}

#[test]
fn the_1000_box_pile_is_refused_at_1khz_and_box_in_walls_accepted() {
    let _cores = crate::CORES.blocking_read();
    let rate = 1000.0;
    let t0 = Instant::now();
    let pile = assess("pile", &world("pile", rate), rate, DEFAULT_STEP_FRACTION);
    let took = t0.elapsed();
    assert!(!pile.runnable, "{pile:?}");
    let why = pile.reason.as_deref().unwrap();
    println!("pile at 1 kHz: {why} (judged in {took:?})");
    assert!(
        why.contains("too heavy") && why.contains("1000 Hz") && why.contains("--rate"),
        "{why}"
    );
    // Refused early: far less than a whole trial's wall-clock limit.
    assert!(
        took < Duration::from_secs_f64(MAX_TRIAL_WALL_S + 0.5),
        "{took:?}"
    );
    let light = assess(
        "box-in-walls",
        &world("box-in-walls", rate),
        rate,
        DEFAULT_STEP_FRACTION,
    );
    assert!(light.runnable, "{light:?}");
    assert!(light.step_us * COST_MARGIN <= light.budget_us, "{light:?}");
}

#[test]
fn a_heavy_trial_stops_as_soon_as_the_percentile_is_over_the_budget() {
    let _cores = crate::CORES.blocking_read();
    // pile at 10 kHz: 3000 steps planned, 30 may exceed the 50 µs budget (with the margin: 33 µs);
    // the pile's steps do.
    let t = trial(&world("pile", 10_000.0), 50e-6, COST_MARGIN);
    assert_eq!(t.end, TrialEnd::OverBudget, "{t:?}");
    assert_eq!(t.planned, (TRIAL_S * 10_000.0).round() as usize);
    // Stopped after the 31st step over the budget: nearly at once, far before the 3000 planned.
    assert!(t.steps < t.planned / 10, "{t:?}");
    assert!(t.p99_s * COST_MARGIN > 50e-6, "{t:?}");
}

/// The trial includes the landing: a pile's boxes land within it, so its measured cost bounds the
/// cost of the steps after it (settled pile) with the margin — where the former estimate from the
/// initial state (boxes in the air, no contacts) did not. pile:100 at 1 kHz: the trial's p99 ×
/// margin against the p99 of the next 0.5 s, timed the same way.
#[test]
fn the_trial_with_its_margin_bounds_the_cost_of_the_steps_that_follow_it() {
    let _cores = crate::CORES.blocking_read();
    let rate = 1000.0;
    let w0 = world("pile:100", rate);
    // The whole trial (no wall-clock cut, whatever the machine's load).
    let t = trial_within(&w0, f64::INFINITY, COST_MARGIN, 600.0);
    assert_eq!(t.end, TrialEnd::Complete, "{t:?}");
    // The world after the trial's steps (deterministic: the same states the trial stepped through).
    let mut w = w0.clone();
    for _ in 0..t.steps {
        w.step();
    }
    assert!(
        w.contacts().contact_count() > 100,
        "the pile has landed: {} contacts",
        w.contacts().contact_count()
    );
    let after = running_p99(&w, 500);
    println!(
        "pile:100 trial p50 {:.0} µs, p99 {:.0} µs, max {:.0} µs; next 0.5 s p99 {:.0} µs",
        t.p50_s * 1e6,
        t.p99_s * 1e6,
        t.max_s * 1e6,
        after * 1e6
    );
    assert!(
        COST_MARGIN * t.p99_s >= after,
        "trial p99 {} µs × {COST_MARGIN} < the running p99 {} µs",
        t.p99_s * 1e6,
        after * 1e6
    );
    // The initial state alone (no contacts yet) is far cheaper than the running cost: the reason
    // the gate times a trial.
    assert_eq!(w0.contacts().contact_count(), 0);
}
