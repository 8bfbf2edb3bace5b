//! `f64` as CSV text, fast: exactly the characters of Rust's `{}` (`Display`), from `ryu`'s
//! shortest round-trip digits.
//!
//! `Display` writes the shortest digit string that reads back as the same `f64` (the one nearest
//! the value), with no exponent: `1`, `0.5`, `-0`, `0.0000001`, `1000000000000000000000`, `NaN`,
//! `inf`. Going through `core::fmt` costs about a thousand instructions a number, so a world CSV
//! row of a thousand bodies (six numbers each) cost more than the world step that produced it
//! (`simulate pile:1000 --out`: 6.4 M instructions a row against about 4 M a step). `ryu` finds
//! the same digits (both give the shortest round-trip string nearest the value); this module
//! places them as `Display` does. The tests compare the two on millions of values.

/// Appends `x` to `out` exactly as `write!(out, "{x}")` would.
pub fn push_f64(out: &mut String, x: f64) {
    if !x.is_finite() {
        out.push_str(if x.is_nan() {
            "NaN"
        } else if x > 0.0 {
            "inf"
        } else {
            "-inf"
        });
        return;
    }
    if may_tie(x) {
        use std::fmt::Write as _;
        let _ = write!(out, "{x}");
        return;
    }
    if x.is_sign_negative() {
        out.push('-');
    }
    let mut buf = ryu::Buffer::new();
    let s = buf.format_finite(x.abs()).as_bytes();
    let n = s.len();
    // `ryu` writes `e` and a signed exponent of at most three digits last, if at all.
    let e_at = (n.saturating_sub(5)..n).rev().find(|&i| s[i] == b'e');
    let Some(e_at) = e_at else {
        // Plain: `Display`'s characters, but for `ryu`'s `.0` after an integer.
        let t = if s.ends_with(b".0") { &s[..n - 2] } else { s };
        out.push_str(std::str::from_utf8(t).unwrap_or_default());
        return;
    };
    // `d` or `d.ddd`, then the exponent: the value is `0.dddd × 10^(exponent + 1)`.
    let mut d = Digits::default();
    d.push(s[0]);
    for &b in s.get(2..e_at).unwrap_or_default() {
        d.push(b);
    }
    let (negative, magnitude) = match s.get(e_at + 1..).unwrap_or_default() {
        [b'-', rest @ ..] => (true, rest),
        rest => (false, rest),
    };
    let exp = magnitude
        .iter()
        .fold(0i32, |a, &b| 10 * a + i32::from(b - b'0'));
    place(out, d, if negative { 1 - exp } else { exp + 1 });
}

/// Whether `x` may be a tie, where `ryu` and `Display` part: two shortest digit strings equally
/// near the value, which `ryu` breaks to the even digit and `Display` upwards (`2⁻²⁵ =
/// 2.98023223876953125e-8` is `…312` to `ryu` and `…313` to `Display`). The value must then be
/// exactly a decimal of at most 18 significant digits. With `x = m·2^e`, `m` odd: for `e < 0`
/// that decimal is `m·5^(−e)` shifted, which has more than 18 digits once `−e > 26` (`5²⁷ >
/// 10¹⁸`) or when the product says so; an integer (`e ≥ 0`) is always taken as a possible tie.
/// Those few values (dyadic fractions such as 0.5 and 2⁻²⁵, integers, zero) go to `Display`
/// itself.
fn may_tie(x: f64) -> bool {
    let bits = x.to_bits();
    let (frac, biased) = (bits & ((1 << 52) - 1), ((bits >> 52) & 0x7ff) as i32);
    let (mant, exp) = if biased == 0 {
        (frac, -1074)
    } else {
        (frac | (1 << 52), biased - 1075)
    };
    if mant == 0 {
        return true;
    }
    let tz = mant.trailing_zeros();
    let (m, e) = (mant >> tz, exp + tz as i32);
    if e >= 0 {
        return true;
    }
    if -e > 26 {
        return false;
    }
    u128::from(m) * 5u128.pow((-e) as u32) < 1_000_000_000_000_000_000
}

/// Writes `0.digits × 10^point` with no exponent, as `Display` does: `0` for no digits, leading
/// `0.` and zeros below 1, trailing zeros above the last digit, no `.` for an integer.
fn place(out: &mut String, d: Digits, point: i32) {
    let digits = d.as_str();
    let n = digits.len() as i32;
    if n == 0 {
        out.push('0');
    } else if point <= 0 {
        out.push_str("0.");
        zeros(out, -point);
        out.push_str(digits);
    } else if point < n {
        let (int, frac) = digits.split_at(point as usize);
        out.push_str(int);
        out.push('.');
        out.push_str(frac);
    } else {
        out.push_str(digits);
        zeros(out, point - n);
    }
}

fn zeros(out: &mut String, k: i32) {
    for _ in 0..k.max(0) {
        out.push('0');
    }
}

/// Up to 17 significant decimal digits (an `f64`'s shortest round-trip string has at most 17).
#[derive(Default)]
struct Digits {
    bytes: [u8; 24],
    len: usize,
}

impl Digits {
    fn push(&mut self, b: u8) {
        if self.len < self.bytes.len() {
            self.bytes[self.len] = b;
            self.len += 1;
        }
    }

    fn as_str(&self) -> &str {
        // Only ASCII digits are pushed.
        std::str::from_utf8(&self.bytes[..self.len]).unwrap_or("")
    }
}

#[cfg(test)]
mod tests {
    use super::push_f64;

    fn check(x: f64) {
        let mut got = String::new();
        push_f64(&mut got, x);
        assert_eq!(got, format!("{x}"), "bits {:#018x}", x.to_bits());
    }

    /// The special values and the edges of the number line: zeros of both signs, the smallest
    /// subnormal, the subnormal–normal boundary, the largest finite, NaN and the infinities, and
    /// the powers of ten and of two either side of ryu's switch to exponents (1e-5, 1e16).
    #[test]
    fn the_edges_are_written_as_display_writes_them() {
        for x in [
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            f64::MIN_POSITIVE / 2.0,
            5e-324,
            -5e-324,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1.0,
            -1.0,
            0.5,
            0.1,
            0.2 + 0.1,
            123456789.0,
            1e21,
            1e22,
            1.5e300,
            9007199254740993.0,
            // Ties `ryu` breaks to even and `Display` upwards (see `may_tie`): 1658206780088562.25
            // and 2⁻²⁵ = 2.98023223876953125e-8, both exact.
            f64::from_bits(0x4317_9085_685d_83c9),
            2f64.powi(-25),
        ] {
            check(x);
        }
        for k in -330..=310 {
            let p = 10f64.powi(k);
            check(p);
            check(-p);
            check(p * 1.5);
            check(f64::from_bits(p.to_bits() + 1));
            check(f64::from_bits(p.to_bits().saturating_sub(1)));
        }
        for k in -1074..=1023 {
            check(2f64.powi(k));
        }
    }

    /// Two million random bit patterns (every exponent, every mantissa), and a million numbers
    /// of the kind a world CSV holds (positions, velocities and energies from 1e-12 to 1e3, and
    /// short decimals), all written as `Display` writes them.
    #[test]
    fn random_numbers_are_written_as_display_writes_them() {
        // A fixed-seed xorshift: no dependency for the test.
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        for _ in 0..2_000_000 {
            check(f64::from_bits(next()));
        }
        for _ in 0..1_000_000 {
            let r = next();
            let unit = (r >> 11) as f64 / (1u64 << 53) as f64;
            let scale = 10f64.powi((r % 16) as i32 - 12);
            let x = (unit - 0.5) * scale;
            check(x);
            check((x * 1e4).round() / 1e4);
        }
    }
}
