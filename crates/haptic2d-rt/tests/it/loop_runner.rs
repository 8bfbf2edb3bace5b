//! The fixed-rate runner: tick bookkeeping and summary consistency.
//!
//! No timing assertions (machines are noisy): these tests check counts,
//! orderings and invariants that hold however loaded the machine is. The
//! summaries are printed; run with `--nocapture` to see them.

use haptic2d_rt::{
    run_loop, spawn_loop, LoopConfig, RtRequest, TickControl, TickInfo, TimingSummary,
};
use haptic2d_test_support::stop::raise_after;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

/// Runs `config` with a trivial tick, checking per-tick bookkeeping, and
/// returns the summary and the tick infos seen.
fn run_recording(config: &LoopConfig) -> (TimingSummary, Vec<TickInfo>) {
    let stop = AtomicBool::new(false);
    let mut infos = Vec::with_capacity(100_000);
    let summary = run_loop(config, &stop, |info| {
        infos.push(info);
        TickControl::Continue
    })
    .expect("valid config");
    (summary, infos)
}

/// Invariants of any summary, whatever the machine load.
fn check_summary(s: &TimingSummary, infos: &[TickInfo]) {
    assert_eq!(s.ticks as usize, infos.len());
    assert_eq!(s.deadlines, s.ticks + s.skipped);
    assert!(s.on_time <= s.ticks && s.overruns <= s.ticks);
    assert!((0.0..=1.0).contains(&s.on_time_fraction));
    for p in [&s.lateness_us, &s.compute_us] {
        assert!(
            p.p50 <= p.p99 && p.p99 <= p.p999 && p.p999 <= p.max,
            "{p:?}"
        );
        assert!(p.mean <= p.max && p.p50 >= 0.0);
    }
    let period_s = 1.0 / s.rate_hz;
    if s.ticks >= 2 {
        assert!(s.achieved_rate_hz > 0.0);
        // Distinct deadlines one period apart at least, wake ≥ deadline.
        assert!(s.elapsed_s >= (s.ticks - 1) as f64 * period_s * (1.0 - 1e-9));
    }
    // Per-tick bookkeeping: consecutive indices, strictly increasing
    // deadlines, and `skipped` equal to the gap in deadline indices.
    let mut skipped_seen = 0;
    for (k, w) in infos.windows(2).enumerate() {
        assert_eq!(w[1].index, k as u64 + 1);
        assert_eq!(w[1].deadline_index - w[0].deadline_index - 1, w[1].skipped);
        skipped_seen += w[1].skipped;
        assert!((w[1].t_s - w[1].deadline_index as f64 * period_s).abs() < 1e-9);
    }
    if let Some(first) = infos.first() {
        assert_eq!(first.index, 0);
        assert_eq!(first.deadline_index, 0);
        assert_eq!(first.skipped, 0);
    }
    // Deadlines skipped after the last tick are counted only in the summary.
    assert!(skipped_seen <= s.skipped);
}

/// Runs the loop at `rate_hz` for `ms` ms with a trivial tick; checks that it ticked and the
/// summary's invariants; returns the summary.
fn short_run(rate_hz: f64, ms: u64) -> TimingSummary {
    let config = LoopConfig {
        rate_hz,
        duration: Some(Duration::from_millis(ms)),
        ..LoopConfig::default()
    };
    let (s, infos) = run_recording(&config);
    println!("{rate_hz} Hz, {ms} ms:\n{s}");
    assert!(s.ticks >= 1);
    check_summary(&s, &infos);
    s
}

#[test]
fn loop_1khz_short_run_reports_a_consistent_summary() {
    let s = short_run(1000.0, 200);
    assert_eq!(s.deadlines, 200);
    assert!((s.period_us - 1000.0).abs() < 1e-9);
    assert!((s.on_time_limit_us - 100.0).abs() < 1e-9);
}

#[test]
fn loop_10khz_short_run_reports_a_consistent_summary() {
    assert_eq!(short_run(10_000.0, 100).deadlines, 1000);
}

#[test]
fn tick_asking_to_stop_ends_the_loop_after_exactly_n_ticks() {
    let stop = AtomicBool::new(false);
    let mut n = 0;
    let s = run_loop(&LoopConfig::default(), &stop, |_| {
        n += 1;
        if n == 25 {
            TickControl::Stop
        } else {
            TickControl::Continue
        }
    })
    .unwrap();
    assert_eq!(n, 25);
    assert_eq!(s.ticks, 25);
}

#[test]
fn stop_flag_set_before_start_runs_no_tick_and_summarises_cleanly() {
    let stop = AtomicBool::new(true);
    let s = run_loop(&LoopConfig::default(), &stop, |_| {
        panic!("no tick expected")
    })
    .unwrap();
    assert_eq!(s.ticks, 0);
    assert_eq!(s.deadlines, 0);
    assert_eq!(s.achieved_rate_hz, 0.0);
    assert_eq!(s.lateness_us.max, 0.0);
    assert!(s.to_string().contains("0 ticks"));
}

#[test]
fn stop_flag_from_another_thread_stops_an_endless_loop() {
    let stop = Arc::new(AtomicBool::new(false));
    let setter = raise_after(&stop, Duration::from_millis(30));
    let s = run_loop(&LoopConfig::default(), &stop, |_| TickControl::Continue).unwrap();
    setter.join().unwrap();
    assert!(s.ticks >= 1);
}

#[test]
fn overrunning_tick_skips_missed_deadlines_instead_of_bursting() {
    // At 1 kHz, tick 3 sleeps 3.5 periods. It then ends at least 3.5 ms after
    // its deadline, so deadlines 4, 5 and 6 have certainly passed: the runner
    // must skip them (count ≥ 3), not run them back to back.
    let stop = AtomicBool::new(false);
    let mut infos = Vec::new();
    let s = run_loop(&LoopConfig::default(), &stop, |info| {
        infos.push(info);
        if info.index == 3 {
            std::thread::sleep(Duration::from_micros(3500));
        }
        if info.index == 6 {
            TickControl::Stop
        } else {
            TickControl::Continue
        }
    })
    .unwrap();
    let after = infos[4];
    assert!(after.skipped >= 3, "skipped {}", after.skipped);
    assert!(after.missed_deadline());
    assert!(after.deadline_index >= infos[3].deadline_index + 4);
    assert!(s.overruns >= 1);
    assert!(s.skipped >= 3);
    // The tick after the overrun starts at a deadline that was still ahead
    // when the long tick ended: no burst of late ticks.
    assert!(after.deadline_index > infos[3].deadline_index + after.skipped);
}

#[test]
fn invalid_config_is_an_error_naming_the_parameter() {
    let stop = AtomicBool::new(false);
    let bad_rate = LoopConfig {
        rate_hz: -5.0,
        ..LoopConfig::default()
    };
    let e = run_loop(&bad_rate, &stop, |_| TickControl::Continue).unwrap_err();
    assert!(e.contains("rate_hz"), "{e}");
    let bad_spin = LoopConfig {
        rate_hz: 10_000.0,
        spin_us: 500.0,
        ..LoopConfig::default()
    };
    let e = run_loop(&bad_spin, &stop, |_| TickControl::Continue).unwrap_err();
    assert!(e.contains("spin_us"), "{e}");
}

#[test]
fn real_time_request_degrades_gracefully_and_is_reported() {
    // Whether or not the kernel grants it, the loop runs and the summary
    // carries the report; a refusal yields one warning line.
    let config = LoopConfig {
        duration: Some(Duration::from_millis(20)),
        rt: true,
        rt_request: RtRequest {
            fifo_priority: Some(10),
            lock_memory: false,
            ..RtRequest::default()
        },
        ..LoopConfig::default()
    };
    let (s, infos) = run_recording(&config);
    let rt = s.rt.clone().expect("rt report present");
    println!("{rt}");
    if let Some(w) = rt.warning() {
        println!("{w}");
        assert!(!w.contains('\n'));
    }
    assert!(s.to_string().contains("real-time:"));
    check_summary(&s, &infos);
}

#[test]
fn spawned_loop_runs_on_its_own_thread_and_returns_the_summary() {
    let stop = Arc::new(AtomicBool::new(false));
    let config = LoopConfig {
        duration: Some(Duration::from_millis(20)),
        ..LoopConfig::default()
    };
    let handle = spawn_loop(config, stop, |_| {
        assert_eq!(std::thread::current().name(), Some("haptic2d-rt"));
        TickControl::Continue
    })
    .unwrap();
    let s = handle.join().unwrap().unwrap();
    assert_eq!(s.deadlines, 20);
}
