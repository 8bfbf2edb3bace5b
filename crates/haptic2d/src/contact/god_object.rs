//! God-object entry point and the crossed-edge rule (§8.3).

/// Entry point of a vertex that crossed an edge line during the last sample: with signed distances
/// `d_prev > 0 ≥ d_now` and edge coordinates `s_prev`, `s_now`,
/// `λ = d_prev/(d_prev − d_now)`, `s_g = clamp(s_prev + λ(s_now − s_prev), 0, L)`.
///
/// Returns `(λ, s_g)`; `None` if the line was not crossed during the sample.
#[inline]
pub fn entry_point(
    d_prev: f64,
    d_now: f64,
    s_prev: f64,
    s_now: f64,
    len: f64,
) -> Option<(f64, f64)> {
    if d_prev > 0.0 && d_now <= 0.0 {
        let lam = d_prev / (d_prev - d_now);
        Some((lam, (s_prev + lam * (s_now - s_prev)).clamp(0.0, len)))
    } else {
        None
    }
}

/// Unclamped crossing coordinate along the edge line, used to test whether the crossing happened
/// within the edge range (m).
#[inline]
pub fn crossing_coordinate(d_prev: f64, d_now: f64, s_prev: f64, s_now: f64) -> f64 {
    let lam = d_prev / (d_prev - d_now);
    s_prev + lam * (s_now - s_prev)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_point_interpolates() {
        let (lam, s) = entry_point(0.001, -0.003, 0.01, 0.014, 0.04).unwrap();
        assert!((lam - 0.25).abs() < 1e-15);
        assert!((s - 0.011).abs() < 1e-15);
        assert!(entry_point(-0.001, -0.002, 0.0, 0.0, 1.0).is_none());
    }
}
