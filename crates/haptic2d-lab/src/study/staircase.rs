//! The state of one transformed up/down staircase (Levitt 1971): `down` consecutive correct answers
//! lower the delta by the step factor, one wrong answer raises it; a change of direction is a
//! reversal. The first two reversals use the initial step factor.

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
            self.delta * f
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
}
