//! QUEST: Bayesian adaptive placement of the stimulus (Watson & Pelli 1983), on a grid posterior
//! over the threshold.
//!
//! The observer is assumed to answer with `P(correct | Δ) = γ + (1 − γ − δ)·F(Δ; T)`,
//! `F = 1 − exp(−ln 2·(Δ/T)^β)`: a Weibull whose threshold `T` is the delta where `F = 0.5` (75 %
//! correct in 2AFC without lapses, the analysis' JND definition), with a known slope `β`, lapse `δ`
//! and the task's guess rate `γ`. The prior on `log₁₀ T` is normal (mean `log₁₀ start`, sd
//! `prior_sd`), held on a grid of `GRID` points spanning `[min_delta, max_delta]`. After each
//! answer the posterior is multiplied by the likelihood of the answer; the next trial is placed at
//! the posterior mean of `log₁₀ T` (King-Smith et al. 1994) or at its mode (Watson & Pelli's
//! original), clamped to the grid. The estimate is the posterior mean, with the 2.5 % and 97.5 %
//! posterior quantiles as its 95 % credible interval.

use super::method::QuestSpec;

/// Points of the posterior grid.
pub const GRID: usize = 400;

/// One running QUEST.
#[derive(Clone, Debug, PartialEq)]
pub struct Quest {
    spec: QuestSpec,
    guess: f64,
    /// `log₁₀ T` of each grid point.
    grid: Vec<f64>,
    /// Log posterior (unnormalised) on the grid.
    log_post: Vec<f64>,
    /// The delta of the next trial.
    pub delta: f64,
    /// Trials answered so far.
    pub trials: u32,
}

impl Quest {
    /// A QUEST for a task of guess rate `guess`.
    pub fn new(spec: &QuestSpec, guess: f64) -> Self {
        let (lo, hi) = (spec.min_delta.log10(), spec.max_delta.log10());
        let grid: Vec<f64> = (0..GRID)
            .map(|i| lo + (hi - lo) * i as f64 / (GRID - 1) as f64)
            .collect();
        let m = spec.start.log10();
        let log_post = grid
            .iter()
            .map(|g| -0.5 * ((g - m) / spec.prior_sd).powi(2))
            .collect();
        let mut q = Self {
            spec: spec.clone(),
            guess,
            grid,
            log_post,
            delta: spec.start,
            trials: 0,
        };
        q.delta = q.placement();
        q
    }

    /// `P(correct | delta)` if the threshold were `10^log_t`.
    pub fn p_correct(&self, delta: f64, log_t: f64) -> f64 {
        let f = 1.0
            - (-(std::f64::consts::LN_2) * (delta / 10f64.powf(log_t)).powf(self.spec.beta)).exp();
        self.guess + (1.0 - self.guess - self.spec.lapse) * f
    }

    /// The stopping rule: `max_trials` answered.
    pub fn done(&self) -> bool {
        self.trials >= self.spec.max_trials
    }

    /// Records the answer to a trial at [`delta`](Self::delta) and places the next one.
    pub fn update(&mut self, correct: bool) {
        let d = self.delta;
        for i in 0..GRID {
            let p = self.p_correct(d, self.grid[i]).clamp(1e-12, 1.0 - 1e-12);
            self.log_post[i] += if correct { p.ln() } else { (1.0 - p).ln() };
        }
        self.trials += 1;
        self.delta = self.placement();
    }

    /// The normalised posterior on the grid.
    pub fn posterior(&self) -> Vec<f64> {
        let m = self
            .log_post
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let w: Vec<f64> = self.log_post.iter().map(|l| (l - m).exp()).collect();
        let s: f64 = w.iter().sum();
        w.into_iter().map(|x| x / s).collect()
    }

    fn placement(&self) -> f64 {
        let post = self.posterior();
        let log_t = if self.spec.place_at_mode {
            let i = (0..GRID)
                .max_by(|&a, &b| post[a].total_cmp(&post[b]))
                .unwrap_or(0);
            self.grid[i]
        } else {
            (0..GRID).map(|i| post[i] * self.grid[i]).sum()
        };
        10f64
            .powf(log_t)
            .clamp(self.spec.min_delta, self.spec.max_delta)
    }

    /// The threshold estimate `10^E[log₁₀ T]` and its 95 % credible interval.
    pub fn estimate(&self) -> (f64, (f64, f64)) {
        let post = self.posterior();
        let mean: f64 = (0..GRID).map(|i| post[i] * self.grid[i]).sum();
        let q = |target: f64| {
            let mut c = 0.0;
            for (p, g) in post.iter().zip(&self.grid) {
                c += p;
                if c >= target {
                    return 10f64.powf(*g);
                }
            }
            10f64.powf(self.grid[GRID - 1])
        };
        (10f64.powf(mean), (q(0.025), q(0.975)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> QuestSpec {
        QuestSpec {
            start: 100.0,
            prior_sd: 0.5,
            beta: 2.0,
            lapse: 0.01,
            max_trials: 50,
            min_delta: 10.0,
            max_delta: 1000.0,
            place_at_mode: false,
        }
    }

    /// With no answers the placement is the prior's centre (the grid, 10 to 1000, is symmetric about
    /// it in log units); a correct answer moves it down, a wrong
    /// one up (the likelihood of a correct answer favours lower thresholds).
    #[test]
    fn correct_answers_lower_the_placement_and_wrong_ones_raise_it() {
        let q0 = Quest::new(&spec(), 0.5);
        assert!((q0.delta / 100.0 - 1.0).abs() < 0.02, "{}", q0.delta);
        let mut up = q0.clone();
        up.update(false);
        let mut down = q0.clone();
        down.update(true);
        assert!(
            down.delta < q0.delta && up.delta > q0.delta,
            "{} {} {}",
            down.delta,
            q0.delta,
            up.delta
        );
    }

    /// An ideal observer drawn from QUEST's own model with threshold 40 (a deterministic
    /// pseudo-random stream): after 200 trials the 95 % credible interval contains 40.
    #[test]
    fn quest_finds_the_threshold_of_an_observer_of_its_own_model() {
        let mut s = spec();
        s.max_trials = 200;
        let mut q = Quest::new(&s, 0.5);
        let mut rng = super::super::rng::Rng::new(5);
        while !q.done() {
            let p = q.p_correct(q.delta, 40f64.log10());
            q.update(rng.uniform() < p);
        }
        let (t, (lo, hi)) = q.estimate();
        assert!(
            lo <= 40.0 && 40.0 <= hi && hi / lo < 2.0,
            "{t} [{lo}, {hi}]"
        );
    }
}
