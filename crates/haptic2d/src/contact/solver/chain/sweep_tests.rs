//! Tests of the sweep's arithmetic (session 29's speed-ups must not change one bit): the sweep
//! against the update written out in scalars, operation by operation, and the finiteness test
//! against `f64::is_finite`.

use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `count` bodies with random velocities and masses, some fixed (zero inverse masses).
fn random_bodies(rng: &mut ChaCha8Rng, count: usize) -> Vec<SolverBody> {
    (0..count)
        .map(|i| {
            let fixed = i % 5 == 0;
            SolverBody {
                v: Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)),
                omega: rng.random_range(-3.0..3.0),
                inv_mass: if fixed {
                    0.0
                } else {
                    rng.random_range(0.1..10.0)
                },
                inv_inertia: if fixed {
                    0.0
                } else {
                    rng.random_range(1.0..900.0)
                },
            }
        })
        .collect()
}

/// `count` random rows between distinct bodies of `bodies` bodies (unit normals, a few holes).
fn random_rows(rng: &mut ChaCha8Rng, count: usize, bodies: usize) -> Vec<Row> {
    (0..count)
        .map(|k| {
            if k % 17 == 3 {
                return Row::NONE; // a hole
            }
            let a = rng.random_range(0..bodies as u32);
            let b = (a + rng.random_range(1..bodies as u32)) % bodies as u32;
            let angle: f64 = rng.random_range(-3.2..3.2);
            let w = rng.random_range(0.05..20.0);
            Row {
                a,
                b,
                n: Vec2::new(angle.cos(), angle.sin()),
                rna: rng.random_range(-0.1..0.1),
                rnb: rng.random_range(-0.1..0.1),
                w,
                neg_c: -(5.0 / (6.0 * w)),
                lo: -rng.random_range(0.0..0.02),
                lambda: rng.random_range(-0.01..0.02),
            }
        })
        .collect()
}

/// One projected Gauss–Seidel sweep written out in scalars, in the order of MODELS' update:
/// `v_rel = (v_a − v_b)·n + ω_a·(r_A×n) − ω_b·(r_B×n)`, `λ' = max(−c·(v_rel − w·λ), lo)`, and
/// `Δλ = λ' − λ` applied to both bodies; the scale always multiplies.
fn sweep_in_scalars(rows: &mut [Row], s: &mut [SolverBody], scale: f64) -> f64 {
    let mut largest = 0.0f64;
    for row in rows.iter_mut() {
        let (a, b) = (row.a as usize, row.b as usize);
        let (nx, ny) = (row.n.x, row.n.y);
        let lambda = row.lambda * scale;
        let dot = (s[a].v.x - s[b].v.x) * nx + (s[a].v.y - s[b].v.y) * ny;
        let v_rel = dot + s[a].omega * row.rna - s[b].omega * row.rnb;
        let c = -row.neg_c;
        let push = -c * (v_rel - row.w * lambda);
        let new = if push > row.lo { push } else { row.lo };
        let d = new - lambda;
        row.lambda = new;
        let ka = s[a].inv_mass * d;
        s[a].v.x += nx * ka;
        s[a].v.y += ny * ka;
        s[a].omega += s[a].inv_inertia * row.rna * d;
        let kb = s[b].inv_mass * d;
        s[b].v.x -= nx * kb;
        s[b].v.y -= ny * kb;
        s[b].omega -= s[b].inv_inertia * row.rnb * d;
        let change = (d * row.w).abs();
        largest = if change > largest { change } else { largest };
    }
    largest
}

/// The bits of the bodies' velocities.
fn velocity_bits(s: &[SolverBody]) -> Vec<[u64; 3]> {
    s.iter()
        .map(|b| [b.v.x.to_bits(), b.v.y.to_bits(), b.omega.to_bits()])
        .collect()
}

/// `sweep` — the slices, and the unit scale inlined without its multiplication — gives the
/// scalar update's impulses, velocities and largest change bit for bit, sweep after sweep, for
/// the warm start's scale and for 1, over seeded random rows and bodies.
#[test]
fn sweep_gives_the_scalar_update_bit_for_bit() {
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    for case in 0..40 {
        let bodies = 2 + case % 30;
        let mut s_fast = random_bodies(&mut rng, bodies);
        let mut rows_fast = random_rows(&mut rng, 3 * bodies, bodies);
        let (mut s_ref, mut rows_ref) = (s_fast.clone(), rows_fast.clone());
        let warm = rng.random_range(0.0..1.0);
        for k in 0..6 {
            let scale = if k == 0 { warm } else { 1.0 };
            let fast = if k == 0 {
                sweep(&mut rows_fast, &mut s_fast, scale)
            } else {
                sweep(&mut rows_fast, &mut s_fast, 1.0)
            };
            let reference = sweep_in_scalars(&mut rows_ref, &mut s_ref, scale);
            assert_eq!(fast.to_bits(), reference.to_bits(), "case {case} sweep {k}");
            assert_eq!(velocity_bits(&s_fast), velocity_bits(&s_ref), "case {case}");
            for (x, y) in rows_fast.iter().zip(&rows_ref) {
                assert_eq!(
                    x.lambda.to_bits(),
                    y.lambda.to_bits(),
                    "case {case} sweep {k}"
                );
            }
        }
    }
}

/// `finite` answers as `f64::is_finite`, and `Row::valid` as `w > 0 && w.is_finite()`, on the
/// special values (zeros, subnormals, the extremes, infinities, NaNs with and without payload
/// and sign) and on 200 000 seeded random bit patterns (every exponent, so NaNs and infinities
/// among them).
#[test]
fn finite_and_valid_answer_as_is_finite() {
    let specials = [
        0.0,
        -0.0,
        f64::MIN_POSITIVE,
        f64::MIN_POSITIVE / 4.0,
        -f64::MIN_POSITIVE / 4.0,
        f64::from_bits(1),
        f64::MAX,
        f64::MIN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        -f64::NAN,
        f64::from_bits(0x7ff0_0000_0000_0001),
        f64::from_bits(0xfff8_0000_0000_1234),
        1.0,
        -1.0,
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let random = (0..200_000).map(|_| f64::from_bits(rng.random::<u64>()));
    let (mut nonfinite, mut positive) = (0, 0);
    for x in specials.into_iter().chain(random) {
        assert_eq!(finite(x), x.is_finite(), "{:#x}", x.to_bits());
        let row = Row { w: x, ..Row::NONE };
        assert_eq!(row.valid(), x > 0.0 && x.is_finite(), "{:#x}", x.to_bits());
        nonfinite += !x.is_finite() as u32;
        positive += row.valid() as u32;
    }
    // The random patterns reach both answers of both questions.
    assert!(
        nonfinite > 10 && positive > 10_000,
        "{nonfinite} {positive}"
    );
}
