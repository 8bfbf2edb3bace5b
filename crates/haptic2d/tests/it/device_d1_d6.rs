//! Checkable behaviour of the twin-pantograph device model, spec §10.8 (D1–D6), and of the 2-DOF
//! five-bar behind the `CartesianDevice` boundary (issue 37).

#![allow(clippy::needless_range_loop)] // index loops mirror the matrix formulas

use haptic2d::device::dynamics::LumpedDynamics;
use haptic2d::device::jacobian::{
    condition_number, jacobian, jacobian_at, jacobian_dot_at, singularity_margin,
};
use haptic2d::device::linalg::{dot4, jt_mul_v, norm4, V3, V4};
use haptic2d::device::redundancy::{min_norm_torques, null_vector, saturate, weighted_torques};
use haptic2d::device::{
    DeviceFault, DeviceParams, HandModel, ObserverKind, SimDevice, TwinKinematics, TwinPantograph,
};
use haptic2d::geom::Vec2;

const T: f64 = 0.002;

/// The default workspace sampled as 9×9 positions × 24 angles (§10.2's prototype check).
fn workspace_poses() -> Vec<V3> {
    let p = DeviceParams::default();
    let mut v = Vec::new();
    for ix in 0..9 {
        for iy in 0..9 {
            for it in 0..24 {
                v.push([
                    p.workspace_center_x + p.workspace_half_width * (ix as f64 / 4.0 - 1.0),
                    p.workspace_center_y + p.workspace_half_width * (iy as f64 / 4.0 - 1.0),
                    std::f64::consts::TAU * it as f64 / 24.0 - std::f64::consts::PI + 0.01,
                ]);
            }
        }
    }
    v
}

/// A few deterministic pseudo-random numbers in [−1, 1) (no RNG dependency needed).
fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

#[test]
fn d1_fk_ik_round_trip() {
    let params = DeviceParams::default();
    params.validate().expect("defaults are valid");
    let kin = TwinKinematics::new(&params);
    // Five-bar: P to 1e-12 m over the workspace (and the crank-pin region around it).
    let mut worst_p: f64 = 0.0;
    for pose in workspace_poses() {
        for (j, p) in kin.endpoints(&pose).iter().enumerate() {
            let bar = kin.pantographs[j];
            let q = bar.ik(*p).expect("reachable");
            let p2 = bar.fk(q).expect("assembles");
            worst_p = worst_p.max((p2 - *p).length());
        }
    }
    assert!(worst_p < 1e-12, "five-bar FK∘IK error {worst_p:e} m");

    // Device FK∘IK: pose to 1e-12.
    let mut worst_pose: f64 = 0.0;
    for pose in workspace_poses() {
        let q = kin.ik(&pose).expect("reachable");
        let fk = kin.fk(&q, pose[2] + 0.3).expect("consistent");
        for i in 0..3 {
            worst_pose = worst_pose.max((fk.pose[i] - pose[i]).abs());
        }
        assert!(fk.closure_error.abs() < 1e-12);
    }
    assert!(worst_pose < 1e-12, "device FK∘IK error {worst_pose:e}");

    // θ continuous over ±10 full turns (unwrapped through the encoders).
    let x0 = [0.01, 0.15];
    let mut theta_prev = 0.0;
    let n = 2000;
    let turns = 10.0 * std::f64::consts::TAU;
    let mut worst_theta: f64 = 0.0;
    for sweep in [1.0, -1.0, 1.0] {
        for k in 0..=n {
            let theta = if sweep > 0.0 {
                -turns + 2.0 * turns * k as f64 / n as f64
            } else {
                turns - 2.0 * turns * k as f64 / n as f64
            };
            if k == 0 && theta_prev == 0.0 {
                theta_prev = theta;
            }
            let q = kin.ik(&[x0[0], x0[1], theta]).expect("reachable");
            let fk = kin.fk(&q, theta_prev).expect("consistent");
            worst_theta = worst_theta.max((fk.pose[2] - theta).abs());
            theta_prev = fk.pose[2];
        }
    }
    assert!(worst_theta < 1e-12, "unwrapped θ error {worst_theta:e} rad");

    // Errors, not panics.
    assert!(matches!(
        kin.ik(&[0.0, 0.5, 0.0]),
        Err(DeviceFault::Unreachable { .. })
    ));
    assert!(kin.pantographs[0].ik(Vec2::new(-0.03, 0.0)).is_err());
    let mut q = kin.ik(&[0.0, 0.14, 0.3]).expect("reachable");
    q[2] += 0.03; // slipped encoders on pantograph 2 (both elbows turned outward)
    q[3] -= 0.03;
    let r = kin.fk(&q, 0.3);
    assert!(
        matches!(r, Err(DeviceFault::ClosureViolation { .. })),
        "{r:?}"
    );
}

#[test]
fn d2_jacobian_matches_finite_differences() {
    let params = DeviceParams::default();
    let kin = TwinKinematics::new(&params);
    let h = 1e-6;
    let mut worst_rel: f64 = 0.0;
    let mut worst_cond: f64 = 0.0;
    let mut best_cond = f64::INFINITY;
    let mut min_margin = f64::INFINITY;
    let mut worst_jdot: f64 = 0.0;
    for pose in workspace_poses() {
        let j = jacobian(&kin, &pose).expect("regular");
        let mut err2 = 0.0;
        let mut norm2 = 0.0;
        for c in 0..3 {
            let mut xp = pose;
            let mut xm = pose;
            xp[c] += h;
            xm[c] -= h;
            let qp = kin.ik(&xp).expect("reachable");
            let qm = kin.ik(&xm).expect("reachable");
            for r in 0..4 {
                let fd = (qp[r] - qm[r]) / (2.0 * h);
                err2 += (fd - j[r][c]).powi(2);
                norm2 += j[r][c].powi(2);
            }
        }
        worst_rel = worst_rel.max((err2 / norm2).sqrt());
        let cond = condition_number(&j, params.r_c);
        worst_cond = worst_cond.max(cond);
        best_cond = best_cond.min(cond);
        min_margin = min_margin.min(singularity_margin(&kin, &pose).expect("reachable"));

        // Analytic J̇ against a central difference of J along the twist.
        let xd = [0.05, -0.03, 2.0];
        let cfg = kin.configuration(&pose).expect("reachable");
        let jd = jacobian_dot_at(&kin, &cfg, &j, &xd);
        let hp: V3 = std::array::from_fn(|i| pose[i] + 1e-6 * xd[i]);
        let hm: V3 = std::array::from_fn(|i| pose[i] - 1e-6 * xd[i]);
        let jp = jacobian(&kin, &hp).expect("regular");
        let jm = jacobian(&kin, &hm).expect("regular");
        let mut e2 = 0.0;
        let mut n2 = 0.0;
        for r in 0..4 {
            for c in 0..3 {
                let fd = (jp[r][c] - jm[r][c]) / 2e-6;
                e2 += (fd - jd[r][c]).powi(2);
                n2 += jd[r][c].powi(2);
            }
        }
        worst_jdot = worst_jdot.max((e2 / n2).sqrt());
    }
    println!(
        "D2: worst relative Jacobian error {worst_rel:.2e}; scaled condition number over 9x9x24 in [{best_cond:.3}, {worst_cond:.3}]; min singularity margin {min_margin:.3}; worst J-dot rel error {worst_jdot:.2e}"
    );
    assert!(
        worst_rel < 1e-5,
        "Jacobian vs FD relative error {worst_rel:e}"
    );
    assert!(
        worst_jdot < 1e-5,
        "J-dot vs FD relative error {worst_jdot:e}"
    );
    assert!(worst_cond <= 4.6, "condition number {worst_cond} > 4.6");
    assert!(min_margin >= params.min_singularity_margin);
}

#[test]
fn d3_redundancy_minimum_norm_and_null_space() {
    let params = DeviceParams::default();
    let kin = TwinKinematics::new(&params);
    let mut seed = 7u64;
    for (n, pose) in workspace_poses().iter().enumerate().step_by(7) {
        let j = jacobian(&kin, pose).expect("regular");
        let w = [
            2.0 * lcg(&mut seed),
            2.0 * lcg(&mut seed),
            0.05 * lcg(&mut seed),
        ];
        let tau = min_norm_torques(&j, &w).expect("regular");
        let back = jt_mul_v(&j, &tau);
        for i in 0..3 {
            assert!((back[i] - w[i]).abs() < 1e-10, "J^T tau != W at pose {n}");
        }
        let nu = null_vector(&j).expect("regular");
        let jt_nu = jt_mul_v(&j, &nu);
        assert!(jt_nu.iter().all(|v| v.abs() < 1e-12), "J^T nu = {jt_nu:?}");
        assert!((norm4(&nu) - 1.0).abs() < 1e-14);
        // Sign convention: the largest-magnitude component is positive.
        let imax = (0..4)
            .max_by(|&a, &b| nu[a].abs().total_cmp(&nu[b].abs()))
            .unwrap_or(0);
        assert!(nu[imax] > 0.0);
        // Minimum norm: orthogonal to ν, so adding ±εν increases |τ|.
        assert!(dot4(&tau, &nu).abs() < 1e-12);
        for eps in [1e-3, -1e-3] {
            let t2: V4 = std::array::from_fn(|i| tau[i] + eps * nu[i]);
            assert!(norm4(&t2) > norm4(&tau));
        }
        // Weighted option (τ_max-weighted) also produces W_d exactly.
        let tw = weighted_torques(&j, &w, &[0.25, 0.25, 0.36, 0.16]).expect("regular");
        let back_w = jt_mul_v(&j, &tw);
        for i in 0..3 {
            assert!((back_w[i] - w[i]).abs() < 1e-10);
        }
        // Saturation keeps the wrench direction.
        let big = w.map(|v| 200.0 * v);
        let tb = min_norm_torques(&j, &big).expect("regular");
        let s = saturate(&tb, 0.0, &nu, params.tau_max);
        assert!(s.wrench_scale < 1.0);
        assert!(s.tau.iter().all(|v| v.abs() <= params.tau_max + 1e-15));
        let wb = jt_mul_v(&j, &s.tau);
        for i in 0..3 {
            assert!((wb[i] - s.wrench_scale * big[i]).abs() < 1e-9);
        }
    }
}

#[test]
fn d4_preload_leaves_handle_wrench_unchanged() {
    let params = DeviceParams::default();
    let kin = TwinKinematics::new(&params);
    let rho = 0.04; // ≤ 0.1·τ_max
    for pose in workspace_poses().iter().step_by(11) {
        let j = jacobian(&kin, pose).expect("regular");
        let nu = null_vector(&j).expect("regular");
        let w = [1.5, -0.7, 0.03];
        let tau_w = min_norm_torques(&j, &w).expect("regular");
        let s = saturate(&tau_w, rho, &nu, params.tau_max);
        assert_eq!(s.wrench_scale, 1.0);
        let back = jt_mul_v(&j, &s.tau);
        for i in 0..3 {
            assert!((back[i] - w[i]).abs() < 1e-10);
        }
        // Same ρ always squeezes the same way: τ − τ_w = ρ·ν with ν's fixed sign.
        for i in 0..4 {
            assert!((s.tau[i] - tau_w[i] - rho * nu[i]).abs() < 1e-15);
        }
        // Saturated with preload: wrench direction kept, limit respected, preload kept.
        let big = w.map(|v| 100.0 * v);
        let tb = min_norm_torques(&j, &big).expect("regular");
        let sb = saturate(&tb, rho, &nu, params.tau_max);
        assert!(sb.tau.iter().all(|v| v.abs() <= params.tau_max + 1e-15));
        let wb = jt_mul_v(&j, &sb.tau);
        for i in 0..3 {
            assert!((wb[i] - sb.wrench_scale * big[i]).abs() < 1e-9);
        }
    }
    // Through the façade: preload does not change the wrench either.
    let mut dev = TwinPantograph::new(params, T, ObserverKind::Momentum).expect("valid");
    let q = kin.ik(&[0.01, 0.13, 0.7]).expect("reachable");
    let pose = dev.pose_from_encoders(&q).expect("consistent");
    let j = dev.jacobian(&pose).expect("regular");
    let w = [0.8, 1.2, -0.02];
    let a = dev.torques_for_wrench(&w, 0.0).expect("ok");
    let b = dev.torques_for_wrench(&w, 0.05).expect("ok");
    let (wa, wb) = (jt_mul_v(&j, &a.tau), jt_mul_v(&j, &b.tau));
    for i in 0..3 {
        assert!((wa[i] - wb[i]).abs() < 1e-10);
    }
}

/// Runs the simulated plant under a handle-space PD hold (through the façade: encoders → pose →
/// velocity → observer; PD wrench → torques), with hand-wrench steps. Returns per-tick
/// `(t, true W_h, estimate)`.
fn run_observer_scenario(
    kind: ObserverKind,
    quantize: bool,
    steps: &[(f64, V3)],
    duration: f64,
) -> Vec<(f64, V3, V3)> {
    // "Model exact": the plant's Coulomb friction sign at rest is unobservable from filtered
    // encoder velocities, so D5 runs with viscous joint friction only (known exactly to the observer).
    let params = DeviceParams {
        f_c: 0.0,
        ..DeviceParams::default()
    };
    let x0 = [0.0, 0.14, 0.2];
    let mut plant = SimDevice::new(&params, x0).expect("valid");
    plant.quantize = quantize;
    let mut dev = TwinPantograph::new(params, T, kind).expect("valid");
    dev.reset(x0[2]);
    let kp = [300.0, 300.0, 0.5];
    let kd = [10.0, 10.0, 0.01];
    let mut tau_prev = [0.0; 4];
    let mut log = Vec::new();
    let n = (duration / T).round() as usize;
    let mut wh = [0.0; 3];
    for k in 0..n {
        let t = k as f64 * T;
        for (ts, w) in steps {
            if (t - ts).abs() < 0.5 * T {
                wh = *w;
            }
        }
        let q = plant.encoders().expect("reachable");
        let est = dev.estimate(&q, &tau_prev).expect("consistent");
        // Motion: the hold target circles for the first 0.3 s, then stays.
        let phase = (t.min(0.3) / 0.3) * std::f64::consts::TAU;
        let target = [
            x0[0] + 0.01 * phase.sin(),
            x0[1] + 0.01 * (1.0 - phase.cos()),
            x0[2] + 0.3 * phase.sin(),
        ];
        let w_cmd: V3 =
            std::array::from_fn(|i| kp[i] * (target[i] - est.pose[i]) - kd[i] * est.velocity[i]);
        let cmd = dev.torques_for_wrench(&w_cmd, 0.0).expect("regular");
        assert!(!cmd.near_singular && !cmd.saturated);
        log.push((t, wh, est.hand_wrench));
        plant
            .step(&cmd.tau, &HandModel::Constant { wrench: wh }, T)
            .expect("plant stays in the workspace");
        tau_prev = cmd.tau;
    }
    log
}

#[test]
fn d5_momentum_observer_tracks_hand_wrench_steps() {
    let steps = [
        (0.5, [2.0, 0.0, 0.0]),
        (1.0, [2.0, 2.0, 0.0]),
        (1.5, [2.0, 2.0, 0.05]),
    ];
    let k_o = DeviceParams::default().observer_gain;
    let log = run_observer_scenario(ObserverKind::Momentum, false, &steps, 2.5);
    for (dof, (ts, w)) in steps.iter().enumerate() {
        let step_size = w[dof];
        let before = log
            .iter()
            .rfind(|(t, _, _)| *t < ts - 0.5 * T)
            .map(|e| e.2[dof])
            .unwrap_or(0.0);
        let rise = log
            .iter()
            .find(|(t, _, est)| *t >= *ts && (est[dof] - before) >= 0.95 * step_size)
            .map(|(t, _, _)| t - ts)
            .unwrap_or(f64::INFINITY);
        println!(
            "D5: DOF {dof} step {step_size}: 95% rise time {:.4} s (limit 3/K_O = {:.4} s), pre-step estimate {before:.2e}",
            rise,
            3.0 / k_o[dof]
        );
        assert!(rise <= 3.0 / k_o[dof] + 1e-9, "DOF {dof} rise {rise} s");
    }
    let (_, w_true, est) = log.last().copied().expect("ran");
    let err: V3 = std::array::from_fn(|i| (est[i] - w_true[i]).abs());
    println!("D5: steady-state error at t = 2.5 s: {err:?}");
    assert!(err.iter().all(|e| *e < 1e-6), "steady-state error {err:?}");
    // Tracking error while the hand is still (W_h = 0) but the device moves (first 0.3 s).
    let moving_err = log
        .iter()
        .filter(|(t, _, _)| *t < 0.5)
        .map(|(_, _, e)| e[0].abs().max(e[1].abs()))
        .fold(0.0, f64::max);
    println!("D5: max |estimate| (x, y) with W_h = 0 during motion: {moving_err:.3e} N");
}

#[test]
fn d5_observers_agree_at_rest_and_with_quantised_encoders() {
    let steps = [(0.2, [1.0, -1.5, 0.03])];
    for kind in [
        ObserverKind::Static,
        ObserverKind::InverseDynamics,
        ObserverKind::Momentum,
    ] {
        for quantize in [false, true] {
            let log = run_observer_scenario(kind, quantize, &steps, 1.5);
            if !quantize {
                // Exact model at rest: all three observers converge to the true wrench.
                let (_, w_true, est) = log.last().copied().expect("ran");
                let err: V3 = std::array::from_fn(|i| (est[i] - w_true[i]).abs());
                println!("D5 ({kind:?}, exact encoders): final error {err:?}");
                let tol = if kind == ObserverKind::Momentum {
                    [1e-6, 1e-6, 1e-8]
                } else {
                    [1e-5, 1e-5, 1e-7]
                };
                for i in 0..3 {
                    assert!(err[i] < tol[i], "{kind:?}: {err:?}");
                }
            } else {
                // Quantised encoders (40000 counts/rev at the joint): the PD hold hunts between counts,
                // so report the RMS error over the last 0.5 s (noise level of each observer).
                let tail: Vec<_> = log.iter().filter(|(t, _, _)| *t >= 1.0).collect();
                let rms: V3 = std::array::from_fn(|i| {
                    (tail
                        .iter()
                        .map(|(_, w, e)| (e[i] - w[i]).powi(2))
                        .sum::<f64>()
                        / tail.len() as f64)
                        .sqrt()
                });
                println!(
                    "D5 ({kind:?}, quantised encoders): RMS error over the last 0.5 s {rms:?}"
                );
                assert!(
                    rms[0] < 0.25 && rms[1] < 0.25 && rms[2] < 5e-3,
                    "{kind:?}: {rms:?}"
                );
            }
        }
    }
}

#[test]
fn d6_kinetic_energy_is_conserved_without_inputs() {
    let params = DeviceParams {
        f_c: 0.0,
        f_v: 0.0,
        ..DeviceParams::default()
    };
    let mut plant = SimDevice::new(&params, [0.005, 0.14, 0.4]).expect("valid");
    plant.set_state([0.005, 0.14, 0.4], [0.012, -0.008, 6.0]);
    let e0 = plant.kinetic_energy().expect("reachable");
    let mut worst: f64 = 0.0;
    for _ in 0..500 {
        plant
            .step(&[0.0; 4], &HandModel::Free, T)
            .expect("stays reachable");
        let e = plant.kinetic_energy().expect("reachable");
        worst = worst.max(((e - e0) / e0).abs());
    }
    let x = plant.pose();
    println!("D6: E0 = {e0:.4e} J, max relative drift over 1 s = {worst:.2e}, final pose {x:?}");
    assert!(x[2] > 1.0, "the handle rotated");
    assert!(worst < 1e-6, "relative KE drift {worst:e}");

    // The lumped mass matrix is symmetric positive definite over the workspace.
    let model = LumpedDynamics::new(&params);
    let kin = model.kin;
    for pose in workspace_poses().iter().step_by(13) {
        let cfg = kin.configuration(pose).expect("reachable");
        let j = jacobian_at(&kin, &cfg).expect("regular");
        let m = model.mass_matrix(&j, pose[2]);
        for r in 0..3 {
            for c in 0..3 {
                assert!((m[r][c] - m[c][r]).abs() < 1e-15);
            }
        }
        let ev = haptic2d::device::linalg::sym3_eigenvalues(&m);
        assert!(ev[0] > 0.0);
    }
}

#[test]
fn d_sensing_defaults() {
    let p = DeviceParams::default();
    let f = haptic2d::device::filter::VelocityFilter::new(p.velocity_cutoff_hz, T);
    assert!((f.alpha - 0.466).abs() < 1e-3, "alpha_v = {}", f.alpha);
    let enc = haptic2d::device::encoder::Encoder::new(p.encoder_counts, p.n_g);
    assert!((enc.resolution - std::f64::consts::TAU / 40000.0).abs() < 1e-18);
    assert!((enc.quantize(0.123456) - 0.123456).abs() <= 0.5 * enc.resolution);
    // Validation names the field.
    let bad = DeviceParams {
        l2: -1.0,
        ..DeviceParams::default()
    };
    assert!(bad.validate().unwrap_err().contains("l2"));
    let far = DeviceParams {
        workspace_half_width: 0.08,
        ..DeviceParams::default()
    };
    assert!(far.validate().unwrap_err().contains("workspace_half_width"));
    assert!(p
        .validate_for_period(0.02)
        .unwrap_err()
        .contains("observer_gain"));
    // TOML overrides of a subset.
    let q: DeviceParams =
        toml::from_str("l1 = 0.11\nobserver_gain = [40.0, 40.0, 30.0]").expect("parses");
    assert_eq!(q.l1, 0.11);
    assert_eq!(q.l2, 0.13);
    assert!(toml::from_str::<DeviceParams>("l3 = 1.0").is_err());
}

// ---- The 2-DOF five-bar at the Cartesian boundary (issue 37) ----

use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::device::{CartesianDevice, Pantograph2Device};

/// The gen 3 2DIY linkage (m) and a device on it: τ_max 0.123 N·m, margin limit 0.1, 50 Hz filter.
fn five_bar() -> (Pantograph2, Pantograph2Device) {
    let l = Pantograph2::new(0.038, 0.07, 0.09).unwrap();
    (l, Pantograph2Device::new(l, [0.123; 2], 0.1, 50.0, T))
}

/// `J = ∂E/∂q` by central differences of the forward kinematics alone (not the closed form).
fn fd_jacobian(l: &Pantograph2, q: [f64; 2]) -> [[f64; 2]; 2] {
    let h = 1e-6;
    let mut j = [[0.0; 2]; 2];
    for c in 0..2 {
        let (mut qp, mut qm) = (q, q);
        qp[c] += h;
        qm[c] -= h;
        let (ep, em) = (l.fk(qp).unwrap(), l.fk(qm).unwrap());
        j[0][c] = (ep.x - em.x) / (2.0 * h);
        j[1][c] = (ep.y - em.y) / (2.0 * h);
    }
    j
}

#[test]
fn the_five_bar_device_maps_a_handle_force_to_jt_f() {
    let (l, mut dev) = five_bar();
    assert_eq!(
        dev.wrench_to_torques(&[1.0, 0.0, 0.0], 0.0),
        Err(DeviceFault::NoPose)
    );
    let q = l.ik(Vec2::new(0.019, 0.10)).unwrap();
    dev.sense(&q, &[0.0; 4], T).unwrap();
    let j = fd_jacobian(&l, q);
    // A force small enough not to saturate; the moment has no motor on a five-bar.
    let f = [0.3, -0.2, 5.0];
    let cmd = dev.wrench_to_torques(&f, 0.0).unwrap();
    for i in 0..2 {
        let expected = j[0][i] * f[0] + j[1][i] * f[1];
        assert!(
            (cmd.tau[i] - expected).abs() < 1e-7,
            "tau[{i}] = {} against {expected}",
            cmd.tau[i]
        );
    }
    assert_eq!([cmd.tau[2], cmd.tau[3]], [0.0, 0.0]);
    assert!(!cmd.saturated && cmd.wrench_scale == 1.0 && !cmd.near_singular);
    assert_eq!(dev.tau_max(), [0.123, 0.123, 0.0, 0.0]);
}

#[test]
fn the_five_bar_device_saturates_keeping_the_torque_direction() {
    let (l, mut dev) = five_bar();
    let q = l.ik(Vec2::new(0.019, 0.10)).unwrap();
    dev.sense(&q, &[0.0; 4], T).unwrap();
    let small = dev.wrench_to_torques(&[0.3, -0.2, 0.0], 0.0).unwrap();
    let big = dev.wrench_to_torques(&[300.0, -200.0, 0.0], 0.0).unwrap();
    let peak = big.tau[0].abs().max(big.tau[1].abs());
    assert!((peak - 0.123).abs() < 1e-12, "{peak}");
    assert!(big.saturated && big.wrench_scale < 1.0);
    // Same direction: the ratio τ_1/τ_2 of the unsaturated command.
    assert!(
        (big.tau[0] / big.tau[1] - small.tau[0] / small.tau[1]).abs() < 1e-9,
        "{:?} against {:?}",
        big.tau,
        small.tau
    );
}

/// §10.7's filter on the handle point, in the device frame: the first reading reads zero velocity;
/// a 1 mm step in x over one period then reads `α·(0.001/T)` with `α = 1 − exp(−2π·50·T)`.
#[test]
fn the_five_bar_device_reads_the_handle_point_and_its_filtered_velocity() {
    let (l, mut dev) = five_bar();
    let (e0, e1) = (Vec2::new(0.019, 0.10), Vec2::new(0.020, 0.10));
    let first = dev.sense(&l.ik(e0).unwrap(), &[0.0; 4], T).unwrap();
    assert!((first.pose[0] - e0.x).abs() < 1e-12 && (first.pose[1] - e0.y).abs() < 1e-12);
    assert_eq!(first.pose[2], 0.0);
    assert_eq!(first.velocity, [0.0; 3]);
    assert_eq!(first.hand_wrench, [0.0; 3]);
    let second = dev.sense(&l.ik(e1).unwrap(), &[0.0; 4], T).unwrap();
    let alpha = 1.0 - (-std::f64::consts::TAU * 50.0 * T).exp();
    assert!(
        (second.velocity[0] - alpha * 0.001 / T).abs() < 1e-9,
        "{:?}",
        second.velocity
    );
    assert!(second.velocity[1].abs() < 1e-9 && second.velocity[2] == 0.0);
    assert!(dev.margin() > 0.1 && dev.margin() <= 1.0);
}
