//! Fig. 4 through the full world pipeline (§13.1): F4-1, F4-2, F4-3, the G3 state trace, and P4 for
//! the paper method.

use crate::common_fig4;

use common_fig4::run;
use haptic2d::contact::{ContactState, EventKind};
use haptic2d::integrate::IntegrationMode;
use haptic2d::metrics::BounceMetrics;
use std::collections::BTreeMap;

/// Ticks at which records were created, with how many were created in that tick.
fn creations(events: &[haptic2d::contact::ContactEvent]) -> BTreeMap<u64, usize> {
    let mut m = BTreeMap::new();
    for e in events {
        if matches!(
            e.kind,
            EventKind::Created(ContactState::Colliding) | EventKind::CreatedSimultaneous
        ) {
            *m.entry(e.tick).or_insert(0) += 1;
        }
    }
    m
}

#[test]
fn f4_1_flat_impacts_are_simultaneous_and_spin_free() {
    for mode in [IntegrationMode::ExactZoh, IntegrationMode::SemiImplicit] {
        let r = run("box-in-walls", mode, 4.0, None);
        let c = creations(&r.events);
        assert!(!c.is_empty(), "{mode:?}: no impact happened");
        for (tick, n) in &c {
            assert_eq!(
                *n, 2,
                "{mode:?}: impact at tick {tick} involved {n} corner(s), expected both"
            );
        }
        assert!(
            r.max_abs_omega < 1e-9,
            "{mode:?}: |ω| reached {}",
            r.max_abs_omega
        );
    }
}

#[test]
fn f4_flat_reproduces_the_1d_paper_method() {
    // §5.10 reference (1-D exact-ZOH harness): 4 separations, ratios 0.48, 0.46, 0.42, settles ≈ 0.67 s.
    let r = run("box-in-walls", IntegrationMode::ExactZoh, 10.0, None);
    let m = BounceMetrics::from_samples(&r.samples);
    assert_eq!(m.separations(), 4, "separations: {:?}", m.separation_times);
    for (got, want) in m.contact_ratios.iter().zip([0.48, 0.46, 0.42]) {
        assert!((got - want).abs() <= 0.02, "ratios {:?}", m.contact_ratios);
    }
    let settle = m.settle_time.expect("the paper method settles");
    assert!(settle < 1.5, "settle time {settle}");
    // Final penetration F/K: 2 N on 2 × 1000 N/m.
    assert!(
        (m.final_penetration - 1e-3).abs() < 5e-5,
        "final penetration {}",
        m.final_penetration
    );
}

#[test]
fn f4_2_tilted_first_impact_spins_then_rests_flush() {
    for mode in [IntegrationMode::ExactZoh, IntegrationMode::SemiImplicit] {
        let r = run("box-in-walls-tilt", mode, 10.0, None);
        let c = creations(&r.events);
        let (first_tick, n) = c.iter().next().expect("an impact");
        assert_eq!(
            *n, 1,
            "{mode:?}: the first tilted impact involves one corner"
        );
        // |ω| just after the first impact (state after that tick's step).
        let after = r.samples[*first_tick as usize + 1].omega;
        assert!(
            after > 5.0,
            "{mode:?}: |ω| after the first impact = {after}"
        );
        let box_i = r.world.body_index("box").unwrap();
        let theta = r.world.bodies[box_i].pose.angle;
        assert!(
            (2.0 * theta).sin().abs() < 0.02,
            "{mode:?}: not flush, θ = {theta}"
        );
        let records: Vec<_> = r.world.contact_records().collect();
        assert_eq!(
            records.len(),
            2,
            "{mode:?}: {} contacts at rest",
            records.len()
        );
        assert!(records
            .iter()
            .all(|e| e.state == Some(ContactState::Continuous)));
        let total: f64 = records.iter().map(|e| e.f_n).sum();
        assert!(
            (total - 2.0).abs() <= 0.02,
            "{mode:?}: total normal force {total}"
        );
    }
}

#[test]
fn f4_3_paper_method_loses_energy_at_every_bounce() {
    for mode in [IntegrationMode::ExactZoh, IntegrationMode::SemiImplicit] {
        let r = run("box-in-walls", mode, 10.0, None);
        let m = BounceMetrics::from_samples(&r.samples);
        assert!(m.separations() >= 2, "{mode:?}");
        for w in m.exit_speeds.windows(2) {
            assert!(w[1] < w[0], "{mode:?}: exit speeds {:?}", m.exit_speeds);
        }
        for ratio in &m.contact_ratios {
            assert!(
                *ratio <= 0.5 + 0.02,
                "{mode:?}: ratios {:?}",
                m.contact_ratios
            );
        }
    }
}

#[test]
fn g3_state_trace_of_the_paper_run() {
    let r = run("box-in-walls", IntegrationMode::ExactZoh, 10.0, None);
    let first = r.events.iter().map(|e| e.tick).min().expect("events");
    let at_first: Vec<_> = r.events.iter().filter(|e| e.tick == first).collect();
    let created = at_first
        .iter()
        .filter(|e| {
            matches!(
                e.kind,
                EventKind::Created(ContactState::Colliding) | EventKind::CreatedSimultaneous
            )
        })
        .count();
    let resolved = at_first
        .iter()
        .filter(|e| e.kind == EventKind::Resolved)
        .count();
    assert_eq!(
        (created, resolved),
        (2, 2),
        "Colliding → Continuous for both corners: {at_first:?}"
    );
    assert!(
        r.events.iter().any(|e| e.kind == EventKind::Released),
        "deletion at separation"
    );
    // A final Continuous record persists until the end: the last events are creations, never released.
    let last_release = r
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Released)
        .map(|e| e.tick)
        .max()
        .unwrap();
    let live: Vec<_> = r.world.contact_records().collect();
    assert_eq!(live.len(), 2);
    for rec in live {
        assert_eq!(rec.state, Some(ContactState::Continuous));
        assert!(
            rec.since > last_release,
            "the final records were created after the last release"
        );
    }
}

#[test]
fn p4_guard_never_triggers_on_the_paper_run() {
    let r = run(
        "box-in-walls",
        IntegrationMode::SemiImplicit,
        10.0,
        Some(1e-9),
    );
    assert_eq!(r.world.guard_triggers(), 0);
}

#[test]
fn box_in_walls_energy_stays_within_the_discretisation_bound() {
    // §13.1 F4-3 note: per-sample stored energy can move by ≈ 6e-4 J through ZOH/SEH discretisation, so
    // the bound on (kinetic + stored) − (initial + applied work) is 1e-3 J, not zero.
    let r = run("box-in-walls", IntegrationMode::SemiImplicit, 10.0, None);
    assert!(r.max_excess < 1e-3, "max excess {} J", r.max_excess);
}
