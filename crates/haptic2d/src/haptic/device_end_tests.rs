//! Tests of [`DeviceEnd`]: the same safety for every device kind without a world.

use super::*;
use crate::geom::Vec2;

const T: f64 = 1e-3;

fn square() -> WorkspaceSquare {
    WorkspaceSquare::around([0.0, 0.0], 0.05)
}

fn point_end() -> DeviceEnd {
    DeviceEnd::point(5.0, square(), 0.2, SafetyConfig::default(), T).unwrap()
}

fn linkage() -> Pantograph2 {
    Pantograph2::new(0.038, 0.07, 0.09).unwrap()
}

fn five_bar_end() -> (DeviceEnd, V4) {
    let l = linkage();
    let ws = WorkspaceSquare::five_bar(&l);
    let q = l.ik(Vec2::new(ws.centre[0], ws.centre[1])).unwrap();
    let end = DeviceEnd::five_bar(l, [0.2, 0.2], 0.1, ws, 0.05, SafetyConfig::default(), T);
    (end.unwrap(), [q[0], q[1], 0.0, 0.0])
}

fn twin_end() -> (DeviceEnd, V4) {
    let p = DeviceParams::default();
    let centre = [p.workspace_center_x, p.workspace_center_y, 0.0];
    let q = crate::device::SimDevice::new(&p, centre)
        .unwrap()
        .encoders()
        .unwrap();
    (DeviceEnd::twin(p, SafetyConfig::default(), T).unwrap(), q)
}

/// Runs `n` ticks asking `f` at the fixed reading `q`; returns the applied wrenches.
fn run(end: &mut DeviceEnd, q: &V4, f: V3, n: u64) -> Vec<EndOutput> {
    (0..n)
        .map(|k| {
            let at = (k, k as f64 * T);
            let est = end.sense(at, q, T, 0.0);
            end.actuate(at, est.as_ref(), &f)
        })
        .collect()
}

#[test]
fn every_kind_starts_at_zero_torque_and_ramps_in_over_the_ramp_time() {
    let (five, qf) = five_bar_end();
    let (twin, qt) = twin_end();
    let ramp_ticks = (SafetyConfig::default().ramp_time / T).round() as usize;
    for (name, mut end, q, f) in [
        ("point", point_end(), [0.0; 4], [1.0, 0.5, 0.0]),
        ("five-bar", five, qf, [0.3, -0.2, 0.0]),
        ("twin", twin, qt, [0.3, -0.2, 0.001]),
    ] {
        let out = run(&mut end, &q, f, ramp_ticks as u64 + 10);
        assert_eq!(out[0].tau, [0.0; 4], "{name}: first tick");
        assert_eq!(out[0].applied, [0.0; 3], "{name}: first tick");
        // Halfway through the ramp, half the wrench; after it, all of it (no saturation here).
        let half = out[ramp_ticks / 2].applied[0] / f[0];
        assert!((half - 0.5).abs() < 0.01, "{name}: halfway {half}");
        let full = out[ramp_ticks + 5].applied;
        for i in 0..3 {
            if end.axes()[i] {
                assert!(
                    (full[i] - f[i]).abs() < 1e-9 * f[i].abs().max(1.0),
                    "{name}: {full:?}"
                );
            }
        }
        assert!(out.iter().all(|o| !o.gated), "{name}");
    }
}

#[test]
fn a_latched_end_writes_zero_torques_whatever_is_asked() {
    let (twin, qt) = twin_end();
    for (mut end, q) in [(point_end(), [0.0; 4]), (twin, qt)] {
        run(&mut end, &q, [1.0, 0.0, 0.0], 600);
        let what = "link force";
        end.trip(
            (600, 0.6),
            SafetyReason::NonFiniteSignal {
                what,
                value: f64::NAN,
            },
        );
        let out = run(&mut end, &q, [1.0, 0.0, 0.0], 3);
        assert!(out
            .iter()
            .all(|o| o.gated && o.tau == [0.0; 4] && o.applied == [0.0; 3]));
    }
}

#[test]
fn a_stalled_loop_latches_zero_torques_in_that_tick() {
    let mut end = point_end();
    run(&mut end, &[0.0; 4], [1.0, 0.0, 0.0], 600);
    let limit = SafetyConfig::default().stall_limit(T);
    let at = (600, 0.6);
    let est = end.sense(at, &[0.0; 4], 2.0 * limit, 0.0);
    let out = end.actuate(at, est.as_ref(), &[1.0, 0.0, 0.0]);
    assert!(out.gated && out.tau == [0.0; 4]);
    assert!(matches!(
        end.trip_info().unwrap().reason,
        SafetyReason::Stall { .. }
    ));
}

#[test]
fn a_point_handle_beyond_its_square_trips_and_a_force_limit_keeps_the_direction() {
    let mut end = point_end();
    // 8 N at 3:4 on a 5 N device: 3:4 kept, magnitude 5 N.
    let out = run(&mut end, &[0.0; 4], [4.8, 6.4, 0.0], 700);
    let a = out.last().unwrap().applied;
    assert!((a[0].hypot(a[1]) - 5.0).abs() < 1e-9 && (a[0] / a[1] - 0.75).abs() < 1e-12);
    let far = square().half_width + square().trip_distance + 0.01;
    let out = run(&mut end, &[far, 0.0, 0.0, 0.0], [0.0; 3], 1);
    assert!(out[0].gated && out[0].tau == [0.0; 4]);
    assert!(matches!(
        end.trip_info().unwrap().reason,
        SafetyReason::Workspace { .. }
    ));
}

#[test]
fn a_five_bar_below_its_singularity_margin_trips_at_the_reading() {
    let (mut end, _) = five_bar_end();
    // Scan the motor angles for a reading whose distal links are nearly parallel (margin
    // |u1 × u2| / l2² below the 0.1 limit, not yet singular).
    let l = linkage();
    let step = std::f64::consts::PI / 200.0;
    let near = (0..40000)
        .map(|i| [(i / 200) as f64 * step, (i % 200) as f64 * step])
        .find(|q| {
            l.state(*q)
                .is_ok_and(|s| s.margin < 0.05 && s.margin > 1e-3)
        })
        .expect("a near-singular reading");
    let est = end.sense((0, 0.0), &[near[0], near[1], 0.0, 0.0], T, 0.0);
    let out = end.actuate((0, 0.0), est.as_ref(), &[0.1, 0.0, 0.0]);
    assert!(out.gated && out.tau == [0.0; 4]);
    let reason = end.trip_info().unwrap().reason;
    assert!(
        matches!(reason, SafetyReason::Singularity { .. }),
        "{reason}"
    );
}

#[test]
fn the_origin_is_the_first_valid_reading_and_the_twin_gives_its_mass() {
    let (mut end, q) = twin_end();
    assert!(end.origin().is_none());
    run(&mut end, &q, [0.0; 3], 2);
    let p = DeviceParams::default();
    let o = end.origin().unwrap();
    assert!(
        (o[0] - p.workspace_center_x).abs() < 1e-3 && (o[1] - p.workspace_center_y).abs() < 1e-3
    );
    let m = end.mass_diagonal();
    assert!(m.iter().all(|v| v.is_finite() && *v > 0.0), "{m:?}");
    assert_eq!(point_end().mass_diagonal(), [0.2, 0.2, 0.0]);
}
