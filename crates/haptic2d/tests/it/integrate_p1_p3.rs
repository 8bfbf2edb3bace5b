//! §6.6 checks P1–P3 on single bodies (P4 runs through the world, see `world_f4.rs` and `world_f7.rs`).

use haptic2d::body::Body;
use haptic2d::geom::{Pose, Vec2};
use haptic2d::integrate::{integrate_body, min_mass, IntegrationMode};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn mass(m: f64) -> Body {
    Body::dynamic("m", m, 1.0, Pose::IDENTITY)
}

/// Runs a free mass under a random held force; returns min over k of `W_k − (E_k − E_0)`.
fn p1_margin(mode: IntegrationMode) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut b = mass(0.5);
    let (dt, mut w, mut worst) = (0.002, 0.0, f64::INFINITY);
    let e0 = b.kinetic_energy();
    for _ in 0..10_000 {
        let f = rng.random_range(-5.0..5.0);
        b.force = Vec2::new(f, 0.0);
        let x0 = b.pose.pos.x;
        integrate_body(&mut b, dt, mode);
        w += f * (b.pose.pos.x - x0);
        worst = worst.min(w - (b.kinetic_energy() - e0));
    }
    worst
}

#[test]
fn p1_semi_implicit_mass_is_passive() {
    assert!(p1_margin(IntegrationMode::SemiImplicit) >= -1e-12);
    // Explicit Euler generates T²F²/(2m) per step: it must violate the bound.
    assert!(p1_margin(IntegrationMode::ExplicitEuler) < -1e-6);
    // Exact ZOH is lossless: the margin stays at round-off level.
    assert!(p1_margin(IntegrationMode::ExactZoh).abs() < 1e-9);
}

#[test]
fn p2_zoh_spring_on_semi_implicit_mass_keeps_amplitude() {
    let (k, m, dt) = (2000.0, 0.5, 0.002);
    let mut b = mass(m);
    b.pose.pos.x = 0.01;
    let shadow = |x: f64, v: f64, v_next: f64| 0.5 * m * v * v_next + 0.5 * k * x * x;
    let mut prev: Option<(f64, f64)> = None; // (x_k, v_k) of the previous sample
    let mut h0 = None;
    let (mut max_amp_late, mut max_amp_early) = (0.0f64, 0.0f64);
    for step in 0..100_000 {
        let (x, v) = (b.pose.pos.x, b.vel.x);
        if let Some((xp, vp)) = prev {
            // ½m v_{k-1} v_k + ½K x_{k-1}²
            let h = shadow(xp, vp, v);
            let h0 = *h0.get_or_insert(h);
            assert!(
                ((h - h0) / h0).abs() < 1e-9,
                "shadow energy drifted at step {step}: {h} vs {h0}"
            );
        }
        prev = Some((x, v));
        if step < 1000 {
            max_amp_early = max_amp_early.max(x.abs());
        }
        if step >= 99_000 {
            max_amp_late = max_amp_late.max(x.abs());
        }
        b.force = Vec2::new(-k * x, 0.0); // ZOH spring on the start-of-interval displacement
        integrate_body(&mut b, dt, IntegrationMode::SemiImplicit);
    }
    assert!(
        (max_amp_late / max_amp_early - 1.0).abs() < 0.01,
        "{max_amp_early} → {max_amp_late}"
    );
}

/// Peak |x| over the last 1000 of `n` steps of a semi-implicit mass on a ZOH spring–damper.
fn spring_damper_peak(m: f64, k: f64, c: f64, dt: f64, n: usize) -> f64 {
    let mut b = mass(m);
    b.pose.pos.x = 1e-3;
    let mut peak = 0.0f64;
    for i in 0..n {
        b.force = Vec2::new(-k * b.pose.pos.x - c * b.vel.x, 0.0);
        integrate_body(&mut b, dt, IntegrationMode::SemiImplicit);
        if i + 1000 >= n {
            peak = peak.max(b.pose.pos.x.abs());
        }
        if !b.pose.pos.x.is_finite() || b.pose.pos.x.abs() > 1e3 {
            return f64::INFINITY;
        }
    }
    peak
}

#[test]
fn p3_min_mass_is_the_stability_boundary() {
    let (k, c, dt) = (2000.0, 10.0, 0.002);
    let m0 = min_mass(k, c, dt);
    assert!((m0 - 0.012).abs() < 1e-15, "worked example of §6.4");
    assert!(
        spring_damper_peak(0.99 * m0, k, c, dt, 10_000) > 1.0,
        "0.99·min_mass must diverge"
    );
    assert!(
        spring_damper_peak(1.01 * m0, k, c, dt, 10_000) < 1e-3,
        "1.01·min_mass must not diverge"
    );
}
