//! Same–different trials analysed by signal detection, under the differencing model (Macmillan &
//! Creelman, *Detection Theory*, 2nd ed. 2005, ch. 9): the observer perceives the two intervals
//! with unit-variance Gaussian noise and answers "different" when the percepts differ by more than
//! a criterion `k`. With the percepts' mean difference `d'` (0 on a "same" trial), the difference
//! is `N(±d', 2)`, so
//!
//! - false alarms: `F = P(|N(0, 2)| > k) = 2·Φ(−k/√2)`,
//! - hits: `H(d') = Φ((d' − k)/√2) + Φ((−d' − k)/√2)`.
//!
//! A Weber-law observer has `d'(Δ) = a·ln(1 + Δ/ref)`; `a` and `k` are fitted by maximum likelihood
//! to the "different" answers of the same trials and of every comparison level. The JND reported is
//! the increment whose `d'` is `√2·z₀.₇₅` = 0.954, the `d'` that gives 75 % correct in 2AFC: the
//! same sensitivity, whatever the criterion.

use super::fit::Point;
use super::numeric::{nelder_mead, norm_cdf, Z75};
use super::rng::Rng;

/// The `d'` of the 2AFC 75 % point.
pub const D_75: f64 = std::f64::consts::SQRT_2 * Z75;

/// A fitted differencing model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SdFit {
    /// `a` in `d' = a·ln(1 + Δ/ref)`.
    pub slope: f64,
    /// The criterion `k` (units of the percept noise).
    pub criterion: f64,
}

impl SdFit {
    /// `P("different")` at log ratio `x = ln(1 + Δ/ref)` (`x = 0`: a same trial).
    pub fn p_different(&self, x: f64) -> f64 {
        hit_rate(self.slope * x, self.criterion)
    }
    /// The JND: the `Δ/ref` whose `d'` is [`D_75`], times `reference`.
    pub fn jnd(&self, reference: f64) -> f64 {
        reference * ((D_75 / self.slope).exp() - 1.0)
    }
}

/// `P("different")` for mean percept difference `d` and criterion `k` (`d = 0`: false alarms).
pub fn hit_rate(d: f64, k: f64) -> f64 {
    let s = std::f64::consts::SQRT_2;
    norm_cdf((d - k) / s) + norm_cdf((-d - k) / s)
}

/// Fits `a` and `k` to `points` (`x = ln(1 + Δ/ref)`, `x = 0` for the same trials, `k` =
/// "different" answers).
pub fn fit(points: &[Point]) -> Result<SdFit, String> {
    if !points.iter().any(|p| p.x == 0.0 && p.n > 0) || !points.iter().any(|p| p.x > 0.0 && p.n > 0)
    {
        return Err("a same–different fit needs same trials and different trials".into());
    }
    let mut nll = |t: &[f64]| -> f64 {
        if !t.iter().all(|v| v.is_finite() && v.abs() < 30.0) {
            return 1e300;
        }
        let f = SdFit {
            slope: t[0].exp(),
            criterion: t[1].exp(),
        };
        points
            .iter()
            .map(|p| {
                let q = f.p_different(p.x).clamp(1e-12, 1.0 - 1e-12);
                -(f64::from(p.k) * q.ln() + f64::from(p.n - p.k) * (1.0 - q).ln())
            })
            .sum()
    };
    let mut best: Option<(Vec<f64>, f64)> = None;
    for a in [1.0f64, 5.0, 20.0] {
        for k in [0.5f64, 1.5, 3.0] {
            let (t, v) = nelder_mead(&mut nll, &[a.ln(), k.ln()], &[0.5, 0.5], 2000, 1e-10);
            if best.as_ref().is_none_or(|(_, b)| v < *b) {
                best = Some((t, v));
            }
        }
    }
    let (t, v) = best.ok_or("no fit")?;
    if v >= 1e299 {
        return Err("the same–different fit did not converge".into());
    }
    Ok(SdFit {
        slope: t[0].exp(),
        criterion: t[1].exp(),
    })
}

/// Parametric bootstrap of [`fit`]: `reps` data sets drawn from `fitted` at the same levels and
/// counts, refitted.
pub fn bootstrap(fitted: &SdFit, points: &[Point], reps: u32, seed: u64) -> Vec<SdFit> {
    let mut rng = Rng::new(seed);
    (0..reps)
        .filter_map(|_| {
            let sim: Vec<Point> = points
                .iter()
                .map(|p| {
                    let q = fitted.p_different(p.x);
                    let k = (0..p.n).filter(|_| rng.uniform() < q).count() as u32;
                    Point { k, ..*p }
                })
                .collect();
            fit(&sim).ok()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With no difference the hit rate is the false-alarm rate; a huge difference is always
    /// "different"; the criterion of F = 0.2 is √2·z₀.₉ = 1.8124.
    #[test]
    fn the_differencing_model_has_its_textbook_limits() {
        assert!((hit_rate(0.0, 1.8124) - 0.2).abs() < 1e-3);
        assert!(hit_rate(20.0, 1.8) > 0.999_999);
        assert!(hit_rate(1.0, 1.8) > hit_rate(0.0, 1.8));
    }

    /// Expected counts drawn from a known model are fitted back.
    #[test]
    fn fit_recovers_slope_and_criterion_from_noise_free_counts() {
        let truth = SdFit {
            slope: 7.0,
            criterion: 1.8,
        };
        let pts: Vec<Point> = [0.0, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4]
            .iter()
            .map(|&x| Point {
                x,
                n: 100_000,
                k: (truth.p_different(x) * 100_000.0).round() as u32,
            })
            .collect();
        let f = fit(&pts).unwrap();
        assert!(
            (f.slope / 7.0 - 1.0).abs() < 0.01 && (f.criterion / 1.8 - 1.0).abs() < 0.01,
            "{f:?}"
        );
    }
}
