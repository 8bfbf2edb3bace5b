use super::*;
use crate::run_rig::test_rig::{sim_rig, tick_info};
use crate::run_rig::Rig;

/// One tick as `ServeLoop::tick` does it on the simulated rig (presenter before the step, the
/// system tick and the torques written, the measures after it); returns the report and the probe's
/// contact force magnitude after the step (N), read independently of the presenter.
fn tick(
    rig: &mut Rig,
    p: &mut ServePresenter,
    k: u64,
    cmd: Option<ToLoop>,
) -> (Option<FromLoop>, f64) {
    let slave = rig.system.slave();
    let info = tick_info(k);
    let r = p.before_step(cmd, rig.system.world_mut(), slave, info.t_s, 1e-3, false);
    let q = rig.read().unwrap();
    let out = rig.tick_system(&q, &info, false);
    rig.io.write_torques(&out.torques).unwrap();
    p.after_step(rig.system.world(), slave, 1e-3, false);
    let w = rig.system.world().contact_wrench(slave);
    (r, w.force.x.hypot(w.force.y))
}

fn minsky() -> Laws {
    (
        NormalModel::from_name("minsky", true).unwrap(),
        FrictionModel::default(),
    )
}

/// While the hand presses the probe into the wall the requested stimulus is not installed (the
/// wall keeps the law being felt); it is installed at the first tick without contact, where the
/// contact force is zero before and after the switch; after the interval the neutral stimulus
/// comes back, again only in free space.
#[test]
fn stimuli_are_switched_only_in_free_space_and_the_neutral_one_returns_after_the_interval() {
    let mut rig = sim_rig();
    let neutral = (rig.system.world().normal, rig.system.world().friction);
    assert_ne!(neutral.0, minsky().0);
    let mut p = ServePresenter::new(neutral);
    let home = rig.hand_target_world();
    rig.set_hand_target([-0.01, 0.0, 0.0]);
    let mut k = 0;
    for _ in 0..3000 {
        tick(&mut rig, &mut p, k, None);
        k += 1;
    }
    let slave = rig.system.slave();
    assert!(
        !in_free_space(rig.system.world(), slave),
        "the box presses the wall"
    );
    let req = Request {
        id: 7,
        laws: minsky(),
        duration_s: Some(0.2),
    };
    assert_eq!(
        tick(&mut rig, &mut p, k, Some(ToLoop::Present(req))).0,
        None
    );
    for _ in 0..500 {
        k += 1;
        assert_eq!(tick(&mut rig, &mut p, k, None).0, None);
        assert_eq!(rig.system.world().normal, neutral.0, "no switch in contact");
    }
    rig.set_hand_target(home);
    let mut last_force = f64::NAN;
    let started = loop {
        k += 1;
        let free_before = in_free_space(rig.system.world(), slave);
        let (r, f) = tick(&mut rig, &mut p, k, None);
        if let Some(FromLoop::Started { id, t_s }) = r {
            assert_eq!(id, 7);
            assert!(free_before, "installed only in free space");
            assert_eq!(
                (last_force, f),
                (0.0, 0.0),
                "no contact force around the switch"
            );
            assert_eq!(rig.system.world().normal, minsky().0);
            break t_s;
        }
        assert_eq!(r, None);
        last_force = f;
        assert!(k < 20_000, "the box never left the wall");
    };
    // The interval lasts 0.2 s of loop time: 200 ticks.
    let done = loop {
        k += 1;
        if let (Some(r), _) = tick(&mut rig, &mut p, k, None) {
            break r;
        }
    };
    let FromLoop::Done { id: 7, measured } = done else {
        panic!("expected the end of presentation 7, got {done:?}");
    };
    assert_eq!(measured.start_s, started);
    assert!(
        (measured.end_s - started - 0.2).abs() < 1.5e-3,
        "{measured:?}"
    );
    assert_eq!(measured.ticks, 200);
    // Still in free space: the neutral stimulus is back at the next tick.
    k += 1;
    tick(&mut rig, &mut p, k, None);
    assert_eq!(rig.system.world().normal, neutral.0);
    assert_eq!(p.presenting(), None);
}

/// A probe that never leaves contact fails the request after FREE_SPACE_WAIT_S of loop time with
/// that reason, and the stimulus is never installed; the client's end gives a waiting request up.
#[test]
fn a_probe_held_in_contact_fails_the_request_and_end_gives_a_waiting_one_up() {
    let mut rig = sim_rig();
    let neutral = (rig.system.world().normal, rig.system.world().friction);
    let mut p = ServePresenter::new(neutral);
    rig.set_hand_target([-0.01, 0.0, 0.0]);
    let mut k = 0;
    for _ in 0..3000 {
        tick(&mut rig, &mut p, k, None);
        k += 1;
    }
    let req = |id| {
        Some(ToLoop::Present(Request {
            id,
            laws: minsky(),
            duration_s: None,
        }))
    };
    tick(&mut rig, &mut p, k, req(1));
    let mut waited = 1;
    let failed = loop {
        k += 1;
        waited += 1;
        if let (Some(r), _) = tick(&mut rig, &mut p, k, None) {
            break r;
        }
        assert!(waited < 12_000, "the request never failed");
    };
    let FromLoop::NotFree { id: 1, waited_s } = failed else {
        panic!("expected presentation 1 to fail, got {failed:?}");
    };
    assert!(waited_s > FREE_SPACE_WAIT_S && waited_s < FREE_SPACE_WAIT_S + 2e-3);
    assert_eq!(rig.system.world().normal, neutral.0);
    tick(&mut rig, &mut p, k + 1, req(2));
    let (r, _) = tick(&mut rig, &mut p, k + 2, Some(ToLoop::End(2)));
    assert!(matches!(r, Some(FromLoop::NotFree { id: 2, .. })), "{r:?}");
}

/// The measures are those of the world in the same run: the peak and the mean contact force over
/// the ticks with contact, the time in contact and the deepest penetration (the probe's most
/// negative signed distance) recomputed here tick by tick from the world after each step.
#[test]
fn the_measures_are_the_probe_contact_force_and_depth_of_the_interval() {
    let mut rig = sim_rig();
    let neutral = (rig.system.world().normal, rig.system.world().friction);
    let mut p = ServePresenter::new(neutral);
    let slave = rig.system.slave();
    let mut k = 0;
    let req = Request {
        id: 3,
        laws: neutral,
        duration_s: None,
    };
    assert!(matches!(
        tick(&mut rig, &mut p, k, Some(ToLoop::Present(req))).0,
        Some(FromLoop::Started { id: 3, .. })
    ));
    rig.set_hand_target([-0.01, 0.0, 0.0]);
    let (mut peak, mut sum, mut n, mut deepest) = (0.0f64, 0.0, 0u64, 0.0f64);
    for _ in 0..2000 {
        k += 1;
        let (_, f) = tick(&mut rig, &mut p, k, None);
        peak = peak.max(f);
        if f > 0.0 {
            sum += f;
            n += 1;
        }
        for c in rig.system.world().contact_records() {
            if c.body_a == slave || c.body_b == slave {
                deepest = deepest.max(-c.d[0]);
            }
        }
    }
    k += 1;
    let (r, _) = tick(&mut rig, &mut p, k, Some(ToLoop::End(3)));
    let Some(FromLoop::Done { id: 3, measured: m }) = r else {
        panic!("expected the end of presentation 3, got {r:?}");
    };
    // The first tick (the one that installed the stimulus) is measured too: free space, zero force.
    assert_eq!(m.ticks, 2001);
    assert!(
        n > 500 && peak > 0.1 && deepest > 0.0,
        "the box pressed the wall"
    );
    assert_eq!(m.contact_ticks, n);
    assert_eq!(m.peak_force_n, peak);
    assert!((m.mean_force_n() - sum / n as f64).abs() < 1e-12);
    assert!((m.contact_s - n as f64 * 1e-3).abs() < 1e-9);
    assert_eq!(m.deepest_m, deepest);
}
