//! Tests of the sweep's arithmetic (session 29's speed-ups must not change one bit): the sweep
//! against the update written out in scalars, operation by operation, and the finiteness test
//! against `f64::is_finite`.

use super::*;

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// `count` bodies with random velocities and masses, some fixed (zero inverse masses).
fn random_bodies(rng: &mut Rng, count: usize) -> Vec<SolverBody> {
    (0..count)
        .map(|i| {
            let fixed = i % 5 == 0;
            SolverBody {
                v: Vec2::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)),
                omega: rng.uniform(-3.0, 3.0),
                inv_mass: if fixed { 0.0 } else { rng.uniform(0.1, 10.0) },
                inv_inertia: if fixed { 0.0 } else { rng.uniform(1.0, 900.0) },
            }
        })
        .collect()
}

/// `count` random rows between distinct bodies of `bodies` bodies (unit normals, a few holes).
fn random_rows(rng: &mut Rng, count: usize, bodies: usize) -> Vec<Row> {
    (0..count)
        .map(|k| {
            if k % 17 == 3 {
                return Row::NONE; // a hole
            }
            let a = (rng.next() % bodies as u64) as u32;
            let b = (a + 1 + (rng.next() % (bodies as u64 - 1)) as u32) % bodies as u32;
            let angle = rng.uniform(-3.2, 3.2);
            let w = rng.uniform(0.05, 20.0);
            Row {
                a,
                b,
                n: Vec2::new(angle.cos(), angle.sin()),
                rna: rng.uniform(-0.1, 0.1),
                rnb: rng.uniform(-0.1, 0.1),
                w,
                neg_c: -(5.0 / (6.0 * w)),
                lo: -rng.uniform(0.0, 0.02),
                lambda: rng.uniform(-0.01, 0.02),
            }
        })
        .collect()
}

/// One projected Gauss–Seidel sweep written out in scalars, in the order of MODELS' update:
/// `v_rel = (v_a − v_b)·n + ω_a·(r_A×n) − ω_b·(r_B×n)`, `λ' = max(−c·(v_rel − w·λ), lo)`, and
/// `Δλ = λ' − λ` applied to both bodies; the scale always multiplies.
fn sweep_in_scalars(rows: &mut [Row], s: &mut [SolverBody], scale: f64) -> f64 {
    let mut largest = 0.0f64;
    for k in 0..rows.len() {
        let (a, b) = (rows[k].a as usize, rows[k].b as usize);
        let (nx, ny) = (rows[k].n.x, rows[k].n.y);
        let lambda = rows[k].lambda * scale;
        let dot = (s[a].v.x - s[b].v.x) * nx + (s[a].v.y - s[b].v.y) * ny;
        let v_rel = dot + s[a].omega * rows[k].rna - s[b].omega * rows[k].rnb;
        let c = -rows[k].neg_c;
        let push = -c * (v_rel - rows[k].w * lambda);
        let new = if push > rows[k].lo { push } else { rows[k].lo };
        let d = new - lambda;
        rows[k].lambda = new;
        let ka = s[a].inv_mass * d;
        s[a].v.x += nx * ka;
        s[a].v.y += ny * ka;
        s[a].omega += s[a].inv_inertia * rows[k].rna * d;
        let kb = s[b].inv_mass * d;
        s[b].v.x -= nx * kb;
        s[b].v.y -= ny * kb;
        s[b].omega -= s[b].inv_inertia * rows[k].rnb * d;
        let change = (d * rows[k].w).abs();
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
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for case in 0..40 {
        let bodies = 2 + case % 30;
        let mut s_fast = random_bodies(&mut rng, bodies);
        let mut rows_fast = random_rows(&mut rng, 3 * bodies, bodies);
        let (mut s_ref, mut rows_ref) = (s_fast.clone(), rows_fast.clone());
        let warm = rng.uniform(0.0, 1.0);
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
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let random = (0..200_000).map(|_| f64::from_bits(rng.next()));
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
