//! `sin` and `cos` of a body's angle, together, in plain `f64` arithmetic (issue 17).
//!
//! **Why not `f64::sin_cos`.** The world computes one rotation per body per sample (step 0), and
//! the platform's `sincos` took about 8.5 ns of it (1000 bodies: 8.5 of the 17 µs of the poses
//! stage of a settled pile:1000, measured by computing the rotations twice). This version, for the
//! angles bodies have (`|θ| < 2¹⁹·π/2`, about 8·10⁵ rad; larger ones go to `f64::sin_cos`), takes
//! no table and no call, and gives the same bits on every platform and C library: the trajectories
//! no longer depend on the machine's `libm`.
//!
//! **How.** The method and the coefficients of fdlibm (Sun Microsystems, 1993; the `k_sin`,
//! `k_cos` and `e_rem_pio2` of FreeBSD's msun): the angle is reduced to `y = y₀ + y₁ ∈ [−π/4, π/4]`
//! and a quadrant by Cody and Waite's subtraction of `n·π/2`, with `π/2` in three 33-bit parts
//! (exact products for `|n| < 2²⁰`; a second and third part only when the first one cancels most
//! of the angle), then degree-13 and degree-14 minimax polynomials in `y` give `sin` and `cos`,
//! each with an error below one unit in the last place (checked against `f64::sin_cos` in the
//! tests).

/// `2/π`.
const INV_PIO2: f64 = f64::from_bits(0x3FE4_5F30_6DC9_C883); // 6.36619772367581382433e-01
/// The first 33 bits of `π/2`, and `π/2` minus them.
const PIO2_1: f64 = f64::from_bits(0x3FF9_21FB_5440_0000); // 1.57079632673412561417e+00
const PIO2_1T: f64 = f64::from_bits(0x3DD0_B461_1A62_6331); // 6.07710050650619224932e-11
/// The second 33 bits of `π/2`, and `π/2` minus the first 66.
const PIO2_2: f64 = f64::from_bits(0x3DD0_B461_1A60_0000); // 6.07710050630396597660e-11
const PIO2_2T: f64 = f64::from_bits(0x3BA3_198A_2E03_7073); // 2.02226624879595063154e-21
/// The third 33 bits of `π/2`, and `π/2` minus the first 99.
const PIO2_3: f64 = f64::from_bits(0x3BA3_198A_2E00_0000); // 2.02226624871116645580e-21
const PIO2_3T: f64 = f64::from_bits(0x397B_839A_2520_49C1); // 8.47842766036889956997e-32

/// `sin` on `[−π/4, π/4]`: `x + S1·x³ + … + S6·x¹³`.
const S1: f64 = f64::from_bits(0xBFC5_5555_5555_5549); // -1.66666666666666324348e-01
const S2: f64 = f64::from_bits(0x3F81_1111_1110_F8A6); // 8.33333333332248946124e-03
const S3: f64 = f64::from_bits(0xBF2A_01A0_19C1_61D5); // -1.98412698298579493134e-04
const S4: f64 = f64::from_bits(0x3EC7_1DE3_57B1_FE7D); // 2.75573137070700676789e-06
const S5: f64 = f64::from_bits(0xBE5A_E5E6_8A2B_9CEB); // -2.50507602534068634195e-08
const S6: f64 = f64::from_bits(0x3DE5_D93A_5ACF_D57C); // 1.58969099521155010221e-10

/// `cos` on `[−π/4, π/4]`: `1 − x²/2 + C1·x⁴ + … + C6·x¹⁴`.
const C1: f64 = f64::from_bits(0x3FA5_5555_5555_554C); // 4.16666666666666019037e-02
const C2: f64 = f64::from_bits(0xBF56_C16C_16C1_5177); // -1.38888888888741095749e-03
const C3: f64 = f64::from_bits(0x3EFA_01A0_19CB_1590); // 2.48015872894767294178e-05
const C4: f64 = f64::from_bits(0xBE92_7E4F_809C_52AD); // -2.75573143513906633035e-07
const C5: f64 = f64::from_bits(0x3E21_EE9E_BDB4_B1C4); // 2.08757232129817482790e-09
const C6: f64 = f64::from_bits(0xBDA8_FAE9_BE88_38D4); // -1.13596475577881948265e-11

/// `1.5·2⁵²`: adding and subtracting it rounds a number below `2⁵¹` in magnitude to the nearest
/// integer (ties to even), without SSE4.1's `roundsd`.
const ROUND: f64 = 6755399441055744.0;

/// `(sin x, cos x)` (`x` in rad), each within one unit in the last place; NaN for a NaN or
/// infinite `x`. Deterministic: the same bits on every platform for `|x| < 2¹⁹·π/2`; larger
/// angles are passed to `f64::sin_cos`.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let ax = x.abs();
    if ax <= FRAC_PI_4_BELOW {
        if ax < TINY {
            // sin x = x (also keeps the sign of −0) and cos x = 1 to the last place.
            return (x, 1.0);
        }
        return (kernel_sin(x, 0.0, false), kernel_cos(x, 0.0));
    }
    if ax.is_nan() || ax >= MEDIUM {
        // NaN, infinite or beyond the three-part reduction: the platform's.
        return x.sin_cos();
    }
    let (n, y0, y1) = reduce(x);
    let (s, c) = (kernel_sin(y0, y1, true), kernel_cos(y0, y1));
    match n & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// The largest `|x|` the kernels take unreduced: fdlibm's bound, `0x3FE921FB_FFFFFFFF`, the
/// largest double with `π/4`'s high word (a little above `π/4 = 0x3FE921FB_54442D18`; the
/// kernels hold there too).
const FRAC_PI_4_BELOW: f64 = f64::from_bits(0x3FE9_21FB_FFFF_FFFF);
/// Below `2⁻²⁷`, `sin x = x` and `cos x = 1` after rounding.
const TINY: f64 = f64::from_bits(0x3E40_0000_0000_0000);
/// `2¹⁹·π/2` (fdlibm's bound of the medium case, `0x413921FB`): `|n| < 2²⁰` below it.
const MEDIUM: f64 = f64::from_bits(0x4139_21FB_0000_0000);

/// `x = n·π/2 + y₀ + y₁` with `|y₀ + y₁| ≤ π/4` (about), `y₁` the rounding error of `y₀`.
#[inline(always)]
fn reduce(x: f64) -> (i64, f64, f64) {
    let f = (x * INV_PIO2 + ROUND) - ROUND;
    let n = f as i64;
    let mut r = x - f * PIO2_1; // exact: f·PIO2_1 has at most 53 bits
    let mut w = f * PIO2_1T;
    let mut y0 = r - w;
    let exp = |v: f64| ((v.to_bits() >> 52) & 0x7ff) as i64;
    let j = exp(x);
    if j - exp(y0) > 16 {
        // The first part cancelled most of x (x near a multiple of π/2): a second one.
        let t = r;
        w = f * PIO2_2;
        r = t - w;
        w = f * PIO2_2T - ((t - r) - w);
        y0 = r - w;
        if j - exp(y0) > 49 {
            // And a third, as fdlibm has it (below 2¹⁹·π/2 we found no angle whose result it
            // changes: after two parts the error is below 10⁻²⁰ of y).
            let t = r;
            w = f * PIO2_3;
            r = t - w;
            w = f * PIO2_3T - ((t - r) - w);
            y0 = r - w;
        }
    }
    let y1 = (r - y0) - w;
    (n, y0, y1)
}

/// `sin(x + y)` for `|x| ≤ π/4`, `y` a correction below half an ulp of `x` (used when `tail`).
#[inline(always)]
fn kernel_sin(x: f64, y: f64, tail: bool) -> f64 {
    let z = x * x;
    let w = z * z;
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let v = z * x;
    if tail {
        x - ((z * (0.5 * y - v * r) - y) - v * S1)
    } else {
        x + v * (S1 + z * r)
    }
}

/// `cos(x + y)` for `|x| ≤ π/4`, `y` a correction below half an ulp of `x`.
#[inline(always)]
fn kernel_cos(x: f64, y: f64) -> f64 {
    let z = x * x;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + (z * r - x * y))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Units in the last place between `a` and `b` (as ordered integers).
    fn ulps(a: f64, b: f64) -> u64 {
        let key = |v: f64| {
            let i = v.to_bits() as i64;
            if i < 0 {
                i64::MIN - i
            } else {
                i
            }
        };
        key(a).abs_diff(key(b))
    }

    /// A seeded generator (splitmix64) of uniform numbers in `[0, 1)`.
    struct Rng(u64);
    impl Rng {
        fn unit(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Against the platform's `sin_cos` (glibc's is correctly rounded in nearly all cases), on
    /// seeded random angles of every size a body takes, angles at and just off multiples of π/2
    /// (where the reduction cancels and needs its second part; without it this fails) and huge
    /// ones (passed through): at most one ulp apart, and `sin² + cos²` within a few ulps of 1.
    #[test]
    fn sin_cos_is_within_one_ulp_of_the_platforms() {
        let mut rng = Rng(17);
        let (mut worst, mut differ) = (0, 0u32);
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            let (ls, lc) = x.sin_cos();
            // Both within an ulp of the exact value, one of them rounded to nearest: at most one
            // representable number apart, near the zeros of sin and cos too.
            let d = ulps(s, ls).max(ulps(c, lc));
            assert!(
                d <= 1,
                "x = {x:e}: ({s:e}, {c:e}) against ({ls:e}, {lc:e}), {d} ulps"
            );
            worst = worst.max(d);
            differ += (d > 0) as u32;
            let norm = s * s + c * c;
            assert!(
                (norm - 1.0).abs() <= 4.0 * f64::EPSILON,
                "x = {x:e}: s² + c² = {norm}"
            );
        };
        for scale in [
            1e-9, 1e-3, 0.5, 0.785, 1.0, 3.2, 10.0, 100.0, 1e4, 8e5, 1e7, 1e12,
        ] {
            for _ in 0..100_000 {
                check((2.0 * rng.unit() - 1.0) * scale);
            }
        }
        for k in -2000i64..2000 {
            let m = k as f64 * std::f64::consts::FRAC_PI_2;
            for off in [-1e-9, -1e-15, 0.0, 1e-15, 1e-9] {
                check(m + off);
            }
            check(f64::from_bits(m.to_bits().wrapping_add(1)));
        }
        assert!(worst <= 1);
        // Not the platform's function under another name: it rounds differently now and then.
        assert!(differ > 0, "no angle gave a different last bit");
    }

    /// Zeros, the boundaries of the unreduced range and non-finite angles.
    #[test]
    fn sin_cos_special_values() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(-0.0);
        assert!(s == 0.0 && s.is_sign_negative() && c == 1.0);
        assert_eq!(sin_cos(1e-300), (1e-300, 1.0));
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (s, c) = sin_cos(x);
            assert!(s.is_nan() && c.is_nan(), "{x}");
        }
        let (s, c) = sin_cos(std::f64::consts::FRAC_PI_2);
        assert_eq!(s, 1.0);
        assert!((c - 6.123233995736766e-17).abs() < 1e-30, "{c:e}");
        let (s, c) = sin_cos(std::f64::consts::PI);
        assert!(
            (s - 1.2246467991473532e-16).abs() < 1e-30 && c == -1.0,
            "{s:e} {c}"
        );
    }
}
