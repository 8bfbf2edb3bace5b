//! The state of one transformed up/down staircase (Levitt 1971): `down` consecutive correct answers
//! lower the delta by the step factor, one wrong answer raises it; a change of direction is a
//! reversal. The first two reversals use the initial step factor. A weighted staircase (Kaernbach
//! 1991: `down` = 1) steps down by the factor `f` after every correct answer and up by `f^w` after
//! every wrong one, `w = p/(1 − p)`, so that it converges on `p` correct.

use super::method::StaircaseSpec;

/// One running staircase.
#[derive(Clone, Debug, PartialEq)]
pub struct Staircase {
    /// The delta of the next trial (unit of the varied parameter).
    pub delta: f64,
    /// Trials answered so far.
    pub trials: u32,
    /// Reversals so far.
    pub reversals: u32,
    /// Consecutive correct answers since the last step.
    pub run: u32,
    /// Direction of the last step: −1 down, +1 up, 0 none yet.
    last_dir: i8,
    spec: StaircaseSpec,
}

impl Staircase {
    /// A staircase starting at `start`.
    pub fn new(spec: &StaircaseSpec, start: f64) -> Self {
        Self {
            delta: start.clamp(spec.min_delta, spec.max_delta),
            trials: 0,
            reversals: 0,
            run: 0,
            last_dir: 0,
            spec: spec.clone(),
        }
    }

    /// The stopping rule: the trial or reversal count is reached.
    pub fn done(&self) -> bool {
        self.trials >= self.spec.max_trials || self.reversals >= self.spec.max_reversals
    }

    /// Records the answer to a trial at [`delta`](Self::delta) and moves the staircase.
    pub fn update(&mut self, correct: bool) {
        self.trials += 1;
        let dir: i8 = if correct {
            self.run += 1;
            if self.run < self.spec.down {
                return;
            }
            self.run = 0;
            -1
        } else {
            self.run = 0;
            1
        };
        if self.last_dir != 0 && dir != self.last_dir {
            self.reversals += 1;
        }
        self.last_dir = dir;
        let f = if self.reversals < 2 {
            self.spec.initial_step_factor
        } else {
            self.spec.step_factor
        };
        let next = if dir < 0 {
            self.delta / f
        } else {
            self.delta * f.powf(self.spec.up_weight)
        };
        self.delta = next.clamp(self.spec.min_delta, self.spec.max_delta);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(down: u32) -> StaircaseSpec {
        StaircaseSpec {
            down,
            up_weight: 1.0,
            starts: vec![100.0],
            step_factor: 2.0,
            initial_step_factor: 2.0,
            max_trials: 100,
            max_reversals: 4,
            min_delta: 1.0,
            max_delta: 1000.0,
        }
    }

    #[test]
    fn two_down_one_up_steps_and_counts_reversals() {
        let mut s = Staircase::new(&spec(2), 100.0);
        s.update(true);
        assert_eq!(
            s.delta, 100.0,
            "one correct answer does not step a 2-down staircase"
        );
        s.update(true);
        assert_eq!(s.delta, 50.0);
        s.update(false);
        assert_eq!((s.delta, s.reversals), (100.0, 1));
        s.update(true);
        s.update(true);
        assert_eq!((s.delta, s.reversals), (50.0, 2));
        assert!(!s.done());
        s.update(false);
        s.update(true);
        s.update(true);
        assert_eq!(s.reversals, 4);
        assert!(s.done(), "stops at max_reversals");
    }

    #[test]
    fn three_down_needs_three_correct_answers_and_clamps_at_min_delta() {
        let mut s = Staircase::new(&spec(3), 4.0);
        s.update(true);
        s.update(true);
        assert_eq!(s.delta, 4.0);
        s.update(true);
        assert_eq!(s.delta, 2.0);
        for _ in 0..6 {
            s.update(true);
        }
        assert_eq!(s.delta, 1.0, "clamped at min_delta");
    }

    /// Levitt's targets: 2-down converges on 70.7 %, 3-down on 79.4 % correct.
    #[test]
    fn the_rules_target_levitts_proportions() {
        assert!(
            (spec(2).target() - 0.5f64.sqrt()).abs() < 1e-12,
            "2-down targets √½"
        );
        assert!((spec(3).target() - 0.7937).abs() < 1e-4);
    }

    /// Kaernbach (1991): a weighted staircase targeting `p` steps up by `p/(1 − p)` down steps,
    /// and on an observer whose proportion correct is the logistic `P(Δ)` its deltas settle where
    /// `P = p`: with small steps the median of the second half of a long run is within 5 % of
    /// `P⁻¹(p)`.
    #[test]
    fn a_weighted_staircase_converges_on_its_target_proportion() {
        use crate::study::rng::Rng;
        for &p in &[0.6, 0.75, 0.9] {
            let s = StaircaseSpec {
                down: 1,
                up_weight: p / (1.0 - p),
                starts: vec![100.0],
                step_factor: 1.02,
                initial_step_factor: 1.02,
                max_trials: 40_000,
                max_reversals: u32::MAX,
                min_delta: 0.01,
                max_delta: 1e4,
            };
            assert!((s.target() - p).abs() < 1e-12);
            // 2AFC: P(Δ) = 0.5 + 0.5·(1 − exp(−(Δ/50)²)); P⁻¹(p) = 50·sqrt(−ln(2 − 2p)).
            let prob = |d: f64| 0.5 + 0.5 * (1.0 - (-(d / 50.0).powi(2)).exp());
            let expected = 50.0 * (-(2.0 - 2.0 * p).ln()).sqrt();
            let mut st = Staircase::new(&s, 100.0);
            let mut rng = Rng::new(7);
            let mut late = Vec::new();
            for k in 0..40_000 {
                let correct = rng.uniform() < prob(st.delta);
                if k >= 20_000 {
                    late.push(st.delta.ln());
                }
                st.update(correct);
            }
            late.sort_by(f64::total_cmp);
            let median = late[late.len() / 2].exp();
            assert!(
                (median / expected - 1.0).abs() < 0.05,
                "p = {p}: settles at {median}, expected {expected}"
            );
        }
    }
}
