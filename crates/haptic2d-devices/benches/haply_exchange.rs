//! The Haply driver's own work per exchange, USB excluded: encode the write, decode the reply,
//! degrees → radians, kinematics (end point, Jacobian) and `τ = Jᵀ f` with the torque clamp.
//! Issue 12 target: ≤ 5 µs median.

use criterion::{criterion_group, criterion_main, Criterion};
use haptic2d::device::pantograph2::{jt_mul, Pantograph2};
use haptic2d::device::ObserverKind;
use haptic2d::device::{DeviceParams, TwinPantograph};
use haptic2d::geom::Vec2;
use haptic2d_devices::haply::codec::{decode_reply, encode_reply, encode_write, WRITE_MAX_LEN};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let linkage = Pantograph2::new(0.038, 0.07, 0.09).unwrap();
    let q = linkage.ik(Vec2::new(0.019, 0.10)).unwrap();
    let mut reply = [0u8; 65];
    let n = encode_reply(
        1,
        &[],
        &[q[1].to_degrees() as f32, q[0].to_degrees() as f32],
        &mut reply,
    )
    .unwrap();
    c.bench_function("haply_2diy_exchange_work", |b| {
        b.iter(|| {
            let r = decode_reply(1, 0, 2, black_box(&reply[..n])).unwrap();
            let q = [
                (r.angles_deg[1] as f64).to_radians(),
                (r.angles_deg[0] as f64).to_radians(),
            ];
            let s = linkage.state(q).unwrap();
            let tau = jt_mul(&s.j, black_box([0.5, -0.2]));
            let t = [
                tau[1].clamp(-0.123, 0.123) as f32,
                tau[0].clamp(-0.123, 0.123) as f32,
            ];
            let mut out = [0u8; WRITE_MAX_LEN];
            black_box(encode_write(1, &[], &t, &mut out).unwrap());
        })
    });

    // Twin: decode four angles, the §10 façade (FK with closure monitor, Jacobian, margin, velocity
    // filter, observer) and the redundancy resolution, encode four torques.
    let p = DeviceParams {
        s: 0.038,
        l1: 0.07,
        l2: 0.09,
        r_c: 0.02,
        workspace_center_y: 0.10,
        workspace_half_width: 0.015,
        n_g: 1.0,
        tau_max: 0.123,
        closure_tol: 2e-3,
        ..DeviceParams::default()
    };
    let mut dev = TwinPantograph::new(p, 0.001, ObserverKind::Momentum).unwrap();
    let qt = dev.kin.ik(&[0.0, 0.10, 0.0]).unwrap();
    let n4 = encode_reply(1, &[], &qt.map(|v| v.to_degrees() as f32), &mut reply).unwrap();
    c.bench_function("haply_twin_exchange_work", |b| {
        b.iter(|| {
            let r = decode_reply(1, 0, 4, black_box(&reply[..n4])).unwrap();
            let q = r.angles_deg.map(|a| (a as f64).to_radians());
            let e = dev.estimate(&q, &[0.0; 4]).unwrap();
            let cmd = dev.torques_for_wrench(&[0.5, -0.2, 0.001], 0.0).unwrap();
            let t = cmd.tau.map(|v| v as f32);
            let mut out = [0u8; WRITE_MAX_LEN];
            black_box((e, encode_write(1, &[], &t, &mut out).unwrap()));
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = bench
}
criterion_main!(benches);
