//! The safety watchdog (DESIGN §7): a fault zeroes the torques in the same
//! tick, latches, and explains itself.

use haptic2d_rt::{FaultKind, SafetyInput, Watchdog, WatchdogConfig};

fn dog() -> Watchdog {
    Watchdog::new(WatchdogConfig::default()).unwrap()
}

const TAU: [f64; 4] = [0.1, -0.2, 0.3, -0.05];

#[test]
fn nominal_ticks_pass_torques_through_unchanged() {
    let mut w = dog();
    for k in 0..100 {
        let mut tau = TAU;
        assert!(w.guard(&SafetyInput::nominal(k), &mut tau).is_ok());
        assert_eq!(tau, TAU);
    }
    assert!(!w.is_latched());
}

#[test]
fn non_finite_torque_zeroes_torques_in_the_same_tick_and_latches() {
    let mut w = dog();
    let mut tau = TAU;
    assert!(w.guard(&SafetyInput::nominal(0), &mut tau).is_ok());
    // Tick 1: τ[2] is NaN.
    let mut tau = [0.1, 0.2, f64::NAN, 0.3];
    let f = w.guard(&SafetyInput::nominal(1), &mut tau).unwrap_err();
    assert_eq!(tau, [0.0; 4], "torques must be zero in the faulting tick");
    assert_eq!(f.tick, 1);
    assert!(matches!(f.kind, FaultKind::NonFiniteTorque { index: 2, value } if value.is_nan()));
    let reason = f.reason();
    assert!(
        reason.contains("non-finite torque") && reason.contains("τ[2]"),
        "{reason}"
    );
    // Latched: later healthy ticks are still zeroed, with the original fault.
    for k in 2..10 {
        let mut tau = TAU;
        let again = w.guard(&SafetyInput::nominal(k), &mut tau).unwrap_err();
        assert_eq!(tau, [0.0; 4]);
        // (Compared by text: the fault holds a NaN, which is never == itself.)
        assert_eq!(again.reason(), reason);
    }
    assert_eq!(w.fault().map(|f| f.reason()), Some(reason));
}

#[test]
fn infinite_torque_is_caught_too() {
    let mut w = dog();
    let mut tau = [f64::NEG_INFINITY, 0.0, 0.0, 0.0];
    let f = w.guard(&SafetyInput::nominal(7), &mut tau).unwrap_err();
    assert_eq!(tau, [0.0; 4]);
    assert!(matches!(
        f.kind,
        FaultKind::NonFiniteTorque { index: 0, .. }
    ));
}

#[test]
fn closure_fault_zeroes_torques_in_the_same_tick_and_latches() {
    let mut w = dog();
    let mut tau = TAU;
    let input = SafetyInput {
        closure_fault: true,
        ..SafetyInput::nominal(42)
    };
    let f = w.guard(&input, &mut tau).unwrap_err();
    assert_eq!(tau, [0.0; 4]);
    assert_eq!(f.kind, FaultKind::ClosureFault);
    assert_eq!(f.tick, 42);
    assert!(f.reason().contains("closure"), "{}", f.reason());
    let mut tau = TAU;
    assert!(w.guard(&SafetyInput::nominal(43), &mut tau).is_err());
    assert_eq!(tau, [0.0; 4]);
}

#[test]
fn non_finite_pose_and_extra_values_trip() {
    let mut w = dog();
    let mut tau = TAU;
    let input = SafetyInput {
        pose: [0.0, f64::NAN, 0.0],
        ..SafetyInput::nominal(0)
    };
    let f = w.guard(&input, &mut tau).unwrap_err();
    assert!(matches!(f.kind, FaultKind::NonFinitePose { index: 1, .. }));
    assert!(f.reason().contains("pose y"), "{}", f.reason());

    let mut w = dog();
    let extra = [1.0, 2.0, f64::INFINITY];
    let input = SafetyInput {
        extra: &extra,
        ..SafetyInput::nominal(0)
    };
    let f = w.guard(&input, &mut tau).unwrap_err();
    assert!(matches!(f.kind, FaultKind::NonFiniteValue { index: 2, .. }));
}

#[test]
fn singularity_margin_below_limit_trips() {
    // MODELS §10.4: clamp to zero when the margin < 0.1.
    let mut w = dog();
    let mut tau = TAU;
    let ok = SafetyInput {
        singularity_margin: 0.1,
        ..SafetyInput::nominal(0)
    };
    assert!(w.guard(&ok, &mut tau).is_ok());
    let bad = SafetyInput {
        singularity_margin: 0.099,
        ..SafetyInput::nominal(1)
    };
    let f = w.guard(&bad, &mut tau).unwrap_err();
    assert_eq!(tau, [0.0; 4]);
    assert!(matches!(f.kind, FaultKind::Singularity { .. }));
    assert!(f.reason().contains("singularity margin"));
}

#[test]
fn device_lost_trips() {
    let mut w = dog();
    let mut tau = TAU;
    let f = w
        .guard(
            &SafetyInput {
                device_lost: true,
                ..SafetyInput::nominal(3)
            },
            &mut tau,
        )
        .unwrap_err();
    assert_eq!(tau, [0.0; 4]);
    assert_eq!(f.kind, FaultKind::DeviceLost);
}

#[test]
fn missed_deadline_run_of_n_trips_but_interrupted_runs_do_not() {
    let mut w = Watchdog::new(WatchdogConfig {
        max_missed_run: Some(3),
        ..WatchdogConfig::default()
    })
    .unwrap();
    let missed = |k| SafetyInput {
        deadline_missed: true,
        ..SafetyInput::nominal(k)
    };
    let mut tau = TAU;
    // miss, miss, ok, miss, miss: never 3 in a row.
    for (k, m) in [true, true, false, true, true].into_iter().enumerate() {
        let input = if m {
            missed(k as u64)
        } else {
            SafetyInput::nominal(k as u64)
        };
        assert!(w.guard(&input, &mut tau).is_ok());
    }
    // Third consecutive miss: trips in that tick.
    let f = w.guard(&missed(5), &mut tau).unwrap_err();
    assert_eq!(tau, [0.0; 4]);
    assert_eq!(f.kind, FaultKind::MissedDeadlines { run: 3, limit: 3 });
    assert_eq!(f.tick, 5);
}

#[test]
fn reset_rearms_the_watchdog() {
    let mut w = dog();
    let mut tau = [f64::NAN; 4];
    assert!(w.guard(&SafetyInput::nominal(0), &mut tau).is_err());
    w.reset();
    let mut tau = TAU;
    assert!(w.guard(&SafetyInput::nominal(1), &mut tau).is_ok());
    assert_eq!(tau, TAU);
}

#[test]
fn invalid_config_names_the_parameter() {
    let e = Watchdog::new(WatchdogConfig {
        min_singularity_margin: f64::NAN,
        ..WatchdogConfig::default()
    })
    .unwrap_err();
    assert!(e.contains("min_singularity_margin"));
    let e = Watchdog::new(WatchdogConfig {
        max_missed_run: Some(0),
        ..WatchdogConfig::default()
    })
    .unwrap_err();
    assert!(e.contains("max_missed_run"));
}

/// Issue 11: a stall of any length used to count as one missed deadline (10 in a row needed). Now a
/// single tick more than `max_stall_periods` periods after the previous one trips, in that tick.
#[test]
fn one_stalled_tick_longer_than_the_limit_trips_at_once() {
    let mut w = dog();
    let mut tau = TAU;
    for k in 0..5 {
        assert!(w.guard(&SafetyInput::nominal(k), &mut tau).is_ok());
    }
    // 4.9 periods late is jitter; 50 periods (50 ms at 1 kHz) is a stall.
    let late = SafetyInput {
        elapsed_periods: 4.9,
        deadline_missed: true,
        ..SafetyInput::nominal(5)
    };
    assert!(w.guard(&late, &mut tau).is_ok());
    let stall = SafetyInput {
        elapsed_periods: 50.0,
        deadline_missed: true,
        ..SafetyInput::nominal(6)
    };
    let f = w.guard(&stall, &mut tau).unwrap_err();
    assert_eq!(tau, [0.0; 4]);
    assert_eq!(
        f.kind,
        FaultKind::Stall {
            periods: 50.0,
            limit: 5.0
        }
    );
    assert!(f.reason().contains("stalled"), "{}", f.reason());
    // A broken interval (NaN) is a stall too; disabled, nothing trips.
    let mut w = dog();
    let nan = SafetyInput {
        elapsed_periods: f64::NAN,
        ..SafetyInput::nominal(0)
    };
    assert!(w.guard(&nan, &mut TAU.clone()).is_err());
    let mut off = Watchdog::new(WatchdogConfig {
        max_stall_periods: None,
        ..WatchdogConfig::default()
    })
    .unwrap();
    assert!(off.guard(&stall, &mut TAU.clone()).is_ok());
    // The limit is checked.
    let bad = WatchdogConfig {
        max_stall_periods: Some(0.5),
        ..WatchdogConfig::default()
    };
    assert!(bad.validate().unwrap_err().contains("max_stall_periods"));
}

#[test]
fn tick_interval_measures_wake_to_wake() {
    use haptic2d_rt::{TickInfo, TickInterval};
    let period_ns = 1_000_000;
    let info = |k: u64, lateness_ns: u64| TickInfo {
        index: k,
        deadline_index: k,
        t_s: k as f64 * 1e-3,
        period_s: 1e-3,
        period_ns,
        lateness_ns,
        skipped: 0,
        deadline_ns: 5_000_000 + k * period_ns,
    };
    let mut m = TickInterval::new();
    assert_eq!(
        m.update(&info(0, 20_000)),
        period_ns,
        "first tick: one period"
    );
    assert_eq!(m.update(&info(1, 20_000)), period_ns);
    // Deadlines 2..49 skipped, tick 50 woke 0.3 ms late.
    assert_eq!(m.update(&info(50, 300_000)), 49 * period_ns + 280_000);
    m.reset();
    assert_eq!(m.update(&info(51, 0)), period_ns);
}
