//! The trial schedule of one session: blocks in order, practice trials at the start of each block,
//! then the block's conditions interleaved at random (constant stimuli: every delta × repeats,
//! shuffled; staircases: a random unfinished staircase each trial), and the interval order of each
//! trial. Every choice comes from one generator seeded by the session seed, so the schedule is a
//! function of the seed and the answers: replaying a session's recorded answers reproduces it
//! trial for trial (that is how a session resumes).

use super::file::{Study, Task};
use super::method::Method;
use super::quest::Quest;
use super::quest_plus::QuestPlus;
use super::rng::Rng;
use super::staircase::Staircase;

/// One scheduled trial.
#[derive(Clone, Debug, PartialEq)]
pub struct TrialSpec {
    /// Trial number in the session, from 1.
    pub trial: u32,
    /// Block number, from 1.
    pub block: u32,
    /// A practice trial (not analysed, does not move a staircase).
    pub practice: bool,
    /// Condition index.
    pub condition: usize,
    /// Staircase index (`None` for constant stimuli and practice).
    pub track: Option<usize>,
    /// Comparison − base value of the varied parameter.
    pub delta: f64,
    /// The interval (1 to the task's number of intervals) presenting the comparison; 0 for a
    /// same–different task's "same" trial (the reference in both intervals).
    pub comparison_interval: u8,
    /// A rest break comes before this trial (the study's `[breaks]`).
    pub rest_before: bool,
}

/// An adaptive track's state: a transformed up/down staircase, a QUEST or a QUEST+.
#[derive(Clone, Debug)]
pub enum Tracker {
    /// A staircase.
    Stair(Staircase),
    /// A QUEST.
    Quest(Quest),
    /// A QUEST+.
    QuestPlus(QuestPlus),
}

impl Tracker {
    /// The delta of its next trial.
    pub fn delta(&self) -> f64 {
        match self {
            Tracker::Stair(s) => s.delta,
            Tracker::Quest(q) => q.delta,
            Tracker::QuestPlus(q) => q.delta,
        }
    }
    /// Its stopping rule is met.
    pub fn done(&self) -> bool {
        match self {
            Tracker::Stair(s) => s.done(),
            Tracker::Quest(q) => q.done(),
            Tracker::QuestPlus(q) => q.done(),
        }
    }
    /// Records an answer.
    pub fn update(&mut self, correct: bool) {
        match self {
            Tracker::Stair(s) => s.update(correct),
            Tracker::Quest(q) => q.update(correct),
            Tracker::QuestPlus(q) => q.update(correct),
        }
    }
    /// The staircase, if it is one.
    pub fn stair(&self) -> Option<&Staircase> {
        match self {
            Tracker::Stair(s) => Some(s),
            Tracker::Quest(_) | Tracker::QuestPlus(_) => None,
        }
    }
    /// The QUEST, if it is one.
    pub fn quest(&self) -> Option<&Quest> {
        match self {
            Tracker::Quest(q) => Some(q),
            Tracker::Stair(_) | Tracker::QuestPlus(_) => None,
        }
    }
    /// A Bayesian track's threshold estimate and 95 % credible interval (QUEST or QUEST+).
    pub fn estimate(&self) -> Option<(f64, (f64, f64))> {
        match self {
            Tracker::Quest(q) => Some(q.estimate()),
            Tracker::QuestPlus(q) => Some(q.estimate()),
            Tracker::Stair(_) => None,
        }
    }
    /// QUEST+'s slope estimate (posterior mean), if it is one.
    pub fn slope_estimate(&self) -> Option<f64> {
        match self {
            Tracker::QuestPlus(q) => Some(q.slope_estimate()),
            Tracker::Stair(_) | Tracker::Quest(_) => None,
        }
    }
}

/// One adaptive track of the session (a staircase or a QUEST).
#[derive(Clone, Debug)]
pub struct Track {
    /// Its condition.
    pub condition: usize,
    /// Its state.
    pub tracker: Tracker,
}

/// The schedule's state.
#[derive(Clone, Debug)]
pub struct Schedule {
    study: Study,
    rng: Rng,
    /// The blocks' indices in the order they run (counterbalancing, `order.rs`).
    order: Vec<usize>,
    /// Position in `order`.
    block: usize,
    started: bool,
    practice_left: u32,
    queue: Vec<(usize, f64)>,
    /// The staircases (all conditions; empty for constant stimuli).
    pub tracks: Vec<Track>,
    trial: u32,
    /// The next trial is the first of its block.
    first_of_block: bool,
}

impl Schedule {
    /// A schedule for `study` from `seed`, its blocks in the file's order.
    pub fn new(study: &Study, seed: u64) -> Self {
        Self::ordered(study, seed, (0..study.blocks.len()).collect())
    }

    /// A schedule for `study` from `seed`, running its blocks in `order` (a permutation of the
    /// block indices: a participant's counterbalanced order, `order.rs`).
    pub fn ordered(study: &Study, seed: u64, order: Vec<usize>) -> Self {
        debug_assert_eq!(order.len(), study.blocks.len());
        let mut tracks = Vec::new();
        match &study.method {
            Method::Staircase(s) => {
                for (c, _) in study.conditions.iter().enumerate() {
                    for &start in &s.starts {
                        tracks.push(Track {
                            condition: c,
                            tracker: Tracker::Stair(Staircase::new(s, start)),
                        });
                    }
                }
            }
            Method::Quest(q) => {
                for (c, _) in study.conditions.iter().enumerate() {
                    tracks.push(Track {
                        condition: c,
                        tracker: Tracker::Quest(Quest::new(q, study.task.guess_rate())),
                    });
                }
            }
            Method::QuestPlus(q) => {
                for (c, _) in study.conditions.iter().enumerate() {
                    tracks.push(Track {
                        condition: c,
                        tracker: Tracker::QuestPlus(QuestPlus::new(q, study.task.guess_rate())),
                    });
                }
            }
            Method::Constant { .. } => {}
        }
        Self {
            study: study.clone(),
            rng: Rng::new(seed),
            order,
            block: 0,
            started: false,
            practice_left: 0,
            queue: Vec::new(),
            tracks,
            trial: 0,
            first_of_block: true,
        }
    }

    fn start_block(&mut self) {
        let b = &self.study.blocks[self.order[self.block]];
        self.practice_left = b.practice;
        self.queue.clear();
        if let Method::Constant { repeats, .. } = &self.study.method {
            for &c in &b.conditions {
                for &d in self.study.deltas(c) {
                    for _ in 0..*repeats {
                        self.queue.push((c, d));
                    }
                }
            }
            self.rng.shuffle(&mut self.queue);
            self.queue.reverse(); // popped from the end: the shuffled order front to back
        }
        self.started = true;
    }

    fn open_tracks(&self) -> Vec<usize> {
        let conds = &self.study.blocks[self.order[self.block]].conditions;
        (0..self.tracks.len())
            .filter(|&t| {
                conds.contains(&self.tracks[t].condition) && !self.tracks[t].tracker.done()
            })
            .collect()
    }

    fn block_left(&self) -> bool {
        match self.study.method {
            Method::Constant { .. } => !self.queue.is_empty(),
            Method::Staircase(_) | Method::Quest(_) | Method::QuestPlus(_) => {
                !self.open_tracks().is_empty()
            }
        }
    }

    /// The next trial, or `None` when the session is over. Call [`record`](Self::record) with its
    /// answer before asking for the next.
    pub fn next_trial(&mut self) -> Option<TrialSpec> {
        loop {
            if self.block >= self.study.blocks.len() {
                return None;
            }
            if !self.started {
                self.start_block();
            }
            if self.block_left() {
                break;
            }
            self.block += 1;
            self.started = false;
            self.first_of_block = true;
        }
        self.trial += 1;
        let breaks = self.study.breaks;
        let rest_before =
            (breaks.every > 0 && self.trial > 1 && (self.trial - 1).is_multiple_of(breaks.every))
                || (breaks.between_blocks && self.block > 0 && self.first_of_block);
        self.first_of_block = false;
        let conds = self.study.blocks[self.order[self.block]].conditions.clone();
        let (condition, track, delta, practice) = if self.practice_left > 0 {
            self.practice_left -= 1;
            let c = conds[self.rng.below(conds.len())];
            (c, None, self.study.practice_delta(c), true)
        } else if let Some((c, d)) = self.queue.pop() {
            (c, None, d, false)
        } else {
            let open = self.open_tracks();
            let t = open[self.rng.below(open.len())];
            (
                self.tracks[t].condition,
                Some(t),
                self.tracks[t].tracker.delta(),
                false,
            )
        };
        // Same–different: a "same" trial (the reference twice) is comparison interval 0.
        let same = self.study.task == Task::SameDifferent && self.rng.below(2) == 0;
        let comparison_interval = if same {
            0
        } else if self.study.task == Task::Magnitude {
            2 // the modulus first, then the comparison
        } else {
            1 + self.rng.below(self.study.task.intervals()) as u8
        };
        Some(TrialSpec {
            trial: self.trial,
            block: self.order[self.block] as u32 + 1,
            practice,
            condition,
            track,
            delta,
            comparison_interval,
            rest_before,
        })
    }

    /// Records the answer to `spec` (moves its staircase).
    pub fn record(&mut self, spec: &TrialSpec, correct: bool) {
        if let Some(t) = spec.track {
            self.tracks[t].tracker.update(correct);
        }
    }

    /// Trials the session will run at most (exact for constant stimuli; the trial limits for
    /// staircases), for progress reports.
    pub fn planned(&self) -> u32 {
        let practice: u32 = self.study.blocks.iter().map(|b| b.practice).sum();
        let n = self.study.conditions.len() as u32;
        practice
            + match &self.study.method {
                Method::Constant { repeats, .. } => {
                    (0..self.study.conditions.len())
                        .map(|c| self.study.deltas(c).len() as u32)
                        .sum::<u32>()
                        * repeats
                }
                Method::Staircase(s) => n * s.starts.len() as u32 * s.max_trials,
                Method::Quest(q) => n * q.max_trials,
                Method::QuestPlus(q) => n * q.max_trials,
            }
    }
}
