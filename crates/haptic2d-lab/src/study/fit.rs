//! Maximum-likelihood fit of a psychometric function with a fixed guess rate and a free, bounded
//! lapse rate, and its parametric bootstrap.
//!
//! `P(correct | x) = γ + (1 − γ − λ)·F(x; α, β)` with `F` a Weibull `1 − exp(−(x/α)^β)` (for
//! increments `x > 0`) or a cumulative normal `Φ((x − α)/β)`. The threshold (the JND of a 2AFC
//! discrimination) is the `x` where `F = 0.5`, i.e. 75 % correct for γ = 0.5 and no lapses:
//! `α·(ln 2)^(1/β)` for the Weibull, `α` for the normal.

use super::numeric::{nelder_mead, norm_cdf};
use super::rng::Rng;

/// The shape of `F`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Weibull `1 − exp(−(x/α)^β)`.
    Weibull,
    /// Cumulative normal `Φ((x − α)/β)`.
    Normal,
}

impl Shape {
    /// Parses `weibull` or `normal`.
    pub fn from_name(s: &str) -> Result<Shape, String> {
        match s {
            "weibull" => Ok(Shape::Weibull),
            "normal" => Ok(Shape::Normal),
            _ => Err(format!(
                "unknown psychometric shape `{s}`: use weibull or normal"
            )),
        }
    }
    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Shape::Weibull => "weibull",
            Shape::Normal => "normal",
        }
    }
}

/// Trials at one stimulus level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Stimulus level (delta).
    pub x: f64,
    /// Trials.
    pub n: u32,
    /// Correct answers.
    pub k: u32,
}

/// A fitted psychometric function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PsyFit {
    /// Shape.
    pub shape: Shape,
    /// Location/scale `α` (unit of `x`).
    pub alpha: f64,
    /// Slope `β` (Weibull: dimensionless; normal: unit of `x`).
    pub beta: f64,
    /// Guess rate `γ` (fixed; with `symmetric`, it is `λ/2`).
    pub guess: f64,
    /// The PSE form `P = λ/2 + (1 − λ)·F`: lapses answer at random on either side (a
    /// "which was stiffer" judgement of two different stimuli, no correct answer).
    pub symmetric: bool,
    /// Lapse rate `λ` (fitted).
    pub lapse: f64,
    /// Negative log-likelihood at the optimum.
    pub nll: f64,
}

impl PsyFit {
    /// `F(x)`.
    pub fn core(&self, x: f64) -> f64 {
        core(self.shape, x, self.alpha, self.beta)
    }
    /// `P(correct | x)`.
    pub fn p(&self, x: f64) -> f64 {
        let g = if self.symmetric {
            self.lapse / 2.0
        } else {
            self.guess
        };
        g + (1.0 - g - self.lapse) * self.core(x)
    }
    /// The PSE form's just-noticeable difference: the distance from `F = 0.5` to `F = 0.75`
    /// (`β·z₀.₇₅` for the normal).
    pub fn spread(&self) -> f64 {
        match self.shape {
            Shape::Normal => self.beta * super::numeric::Z75,
            Shape::Weibull => self.alpha * (4f64.ln()).powf(1.0 / self.beta) - self.threshold(),
        }
    }
    /// The threshold: `x` at `F = 0.5`.
    pub fn threshold(&self) -> f64 {
        match self.shape {
            Shape::Weibull => self.alpha * std::f64::consts::LN_2.powf(1.0 / self.beta),
            Shape::Normal => self.alpha,
        }
    }
}

fn core(shape: Shape, x: f64, alpha: f64, beta: f64) -> f64 {
    match shape {
        Shape::Weibull => {
            if x <= 0.0 {
                0.0
            } else {
                1.0 - (-(x / alpha).powf(beta)).exp()
            }
        }
        Shape::Normal => norm_cdf((x - alpha) / beta),
    }
}

fn nll(points: &[Point], p: &dyn Fn(f64) -> f64) -> f64 {
    points
        .iter()
        .map(|pt| {
            let q = p(pt.x).clamp(1e-12, 1.0 - 1e-12);
            -(f64::from(pt.k) * q.ln() + f64::from(pt.n - pt.k) * (1.0 - q).ln())
        })
        .sum()
}

/// Fits `points` by maximum likelihood, guess rate `guess`, lapse rate in `[0, max_lapse]`.
pub fn fit(points: &[Point], shape: Shape, guess: f64, max_lapse: f64) -> Result<PsyFit, String> {
    fit_form(points, shape, guess, false, max_lapse)
}

/// Fits the PSE form `λ/2 + (1 − λ)·F` (lapse rate in `[0, max_lapse]`): `F` a cumulative normal
/// of the comparison's value, `α` the PSE.
pub fn fit_pse(points: &[Point], max_lapse: f64) -> Result<PsyFit, String> {
    fit_form(points, Shape::Normal, 0.0, true, max_lapse)
}

fn fit_form(
    points: &[Point],
    shape: Shape,
    guess: f64,
    symmetric: bool,
    max_lapse: f64,
) -> Result<PsyFit, String> {
    let pts: Vec<Point> = points.iter().copied().filter(|p| p.n > 0).collect();
    if pts.len() < 2 {
        return Err(format!(
            "{} stimulus levels with trials: a fit needs at least 2",
            pts.len()
        ));
    }
    if shape == Shape::Weibull && pts.iter().any(|p| p.x.is_nan() || p.x <= 0.0) {
        return Err("a Weibull needs positive stimulus levels".into());
    }
    let scale = pts
        .iter()
        .map(|p| p.x.abs())
        .fold(0.0, f64::max)
        .max(1e-300);
    let sig = |c: f64| max_lapse / (1.0 + (-c).exp());
    let unpack = |t: &[f64]| -> (f64, f64, f64) {
        match shape {
            Shape::Weibull => (t[0].exp() * scale, t[1].exp(), sig(t[2])),
            Shape::Normal => (t[0] * scale, t[1].exp() * scale, sig(t[2])),
        }
    };
    let mut obj = |t: &[f64]| -> f64 {
        let beta_ok = match shape {
            Shape::Weibull => (0.2f64.ln()..=30f64.ln()).contains(&t[1]),
            Shape::Normal => (1e-3f64.ln()..=10f64.ln()).contains(&t[1]),
        };
        if !beta_ok || !t.iter().all(|v| v.is_finite()) || t[0].abs() > 50.0 {
            return 1e300;
        }
        let (a, b, l) = unpack(t);
        let g = if symmetric { l / 2.0 } else { guess };
        nll(&pts, &|x| g + (1.0 - g - l) * core(shape, x, a, b))
    };
    let mut best: Option<(Vec<f64>, f64)> = None;
    let firsts: &[f64] = match shape {
        Shape::Weibull => &[0.1f64.ln(), 0.3f64.ln(), 0.7f64.ln()],
        Shape::Normal => &[0.1, 0.4, 0.8],
    };
    let slopes: &[f64] = match shape {
        Shape::Weibull => &[1.2f64.ln(), 3f64.ln()],
        Shape::Normal => &[0.05f64.ln(), 0.3f64.ln()],
    };
    for &a in firsts {
        for &b in slopes {
            let (t, v) = nelder_mead(&mut obj, &[a, b, -1.0], &[0.3, 0.3, 1.0], 3000, 1e-10);
            if best.as_ref().is_none_or(|(_, bv)| v < *bv) {
                best = Some((t, v));
            }
        }
    }
    let (t, v) = best.ok_or("no fit")?;
    let (alpha, beta, lapse) = unpack(&t);
    if v.is_nan() || v >= 1e299 {
        return Err("the fit did not converge".into());
    }
    Ok(PsyFit {
        shape,
        alpha,
        beta,
        guess,
        symmetric,
        lapse,
        nll: v,
    })
}

/// Parametric bootstrap: `reps` data sets drawn from `fitted` at the levels and trial counts of
/// `points`, each refitted; returns the thresholds of the fits that converged, sorted.
pub fn bootstrap_thresholds(
    fitted: &PsyFit,
    points: &[Point],
    reps: u32,
    seed: u64,
    max_lapse: f64,
) -> Vec<f64> {
    let mut t: Vec<f64> = bootstrap(fitted, points, reps, seed, max_lapse)
        .into_iter()
        .map(|f| f.threshold())
        .filter(|t| t.is_finite())
        .collect();
    t.sort_by(f64::total_cmp);
    t
}

/// Parametric bootstrap: `reps` data sets drawn from `fitted` at the levels and trial counts of
/// `points`, each refitted in the same form; returns the fits that converged.
pub fn bootstrap(
    fitted: &PsyFit,
    points: &[Point],
    reps: u32,
    seed: u64,
    max_lapse: f64,
) -> Vec<PsyFit> {
    let mut rng = Rng::new(seed);
    let mut out = Vec::with_capacity(reps as usize);
    for _ in 0..reps {
        let sim: Vec<Point> = points
            .iter()
            .map(|p| {
                let q = fitted.p(p.x);
                let k = (0..p.n).filter(|_| rng.uniform() < q).count() as u32;
                Point { k, ..*p }
            })
            .collect();
        if let Ok(f) = fit_form(
            &sim,
            fitted.shape,
            fitted.guess,
            fitted.symmetric,
            max_lapse,
        ) {
            out.push(f);
        }
    }
    out
}

/// The `q`-quantile (0..1) of sorted values (linear interpolation).
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let i = h.floor() as usize;
    let j = (i + 1).min(sorted.len() - 1);
    sorted[i] + (h - i as f64) * (sorted[j] - sorted[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Data drawn exactly from a known Weibull (expected counts) give back its threshold.
    #[test]
    fn fit_recovers_the_threshold_of_noise_free_data() {
        let truth = PsyFit {
            shape: Shape::Weibull,
            alpha: 120.0,
            beta: 2.5,
            guess: 0.5,
            symmetric: false,
            lapse: 0.02,
            nll: 0.0,
        };
        let pts: Vec<Point> = [30.0, 60.0, 90.0, 120.0, 180.0, 270.0]
            .iter()
            .map(|&x| Point {
                x,
                n: 10_000,
                k: (truth.p(x) * 10_000.0).round() as u32,
            })
            .collect();
        let f = fit(&pts, Shape::Weibull, 0.5, 0.06).unwrap();
        assert!(
            (f.threshold() / truth.threshold() - 1.0).abs() < 0.01,
            "{f:?}"
        );
        let n = fit(&pts, Shape::Normal, 0.5, 0.06).unwrap();
        assert!(
            (n.threshold() / truth.threshold() - 1.0).abs() < 0.1,
            "{n:?}"
        );
    }

    #[test]
    fn quantiles_interpolate() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&v, 0.5), 3.0);
        assert_eq!(quantile(&v, 0.125), 1.5);
    }
}
