//! The study trial on the real-time loop (`haptic2d study run --observer browser`): the per-tick
//! state machine that presents a trial's intervals and takes its answer. It runs inside the haptic
//! tick: no allocation, no lock, no I/O.
//!
//! Per trial (a [`Plan`], built on the main thread with each interval's laws already made):
//!
//! 0. **break** (only before a trial the study's `[breaks]` rest before): the page shows "Take a
//!    break"; the loop holds the world frozen with zero force commanded (as a pause: no stimulus,
//!    the handle free) until the page's `continue_study` for this trial, then the torques ramp in
//!    from zero again as after a pause.
//! 1. **free space**: the interval's stimulus (wall law and friction model, with the trial's
//!    parameters) is installed in the world at the first tick in which the slave body has **no
//!    contact record**. Its contact force is then zero before and after the switch, so the switch
//!    cannot make a step in the force the participant feels; while the handle rests on or presses
//!    the wall, the previous stimulus stays (the page asks the participant to lift the handle off).
//! 2. **presenting**: the participant explores for `interval_s` of loop time (paused ticks do not
//!    count), then the next interval starts at 1.
//! 3. **answer**: after the last interval the page shows the answer buttons (magnitude estimation:
//!    a number entry, the number finite and > 0); the response time is
//!    the monotonic time from entering this phase (the prompt) to the tick that takes the answer.
//!    Only an answer naming the current trial with a choice the task offers is taken; any other is
//!    counted as refused and changes nothing. A press of a device button answers too, timed the
//!    same way ([`crate::study_buttons`]: the mapping, and why a button held through the last
//!    interval does not answer).
//!
//! The device's own safety (torques ramped in from zero at the start, clamped, latched to zero on a
//! stall or a lost device) is the loop's, unchanged.

use crate::run_view::StudyInbox;
use crate::study_buttons::ButtonAnswers;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NormalModel;
use haptic2d::world::World;
use haptic2d_lab::study::file::Task;
use haptic2d_view::StudyView;

/// Most intervals a trial has (3AFC).
pub const MAX_INTERVALS: usize = 3;

/// One trial to present, prepared off the loop thread.
#[derive(Clone, Copy, Debug)]
pub struct Plan {
    /// Trial number (from 1).
    pub trial: u32,
    /// Trials answered in the session before this one.
    pub done: u32,
    /// Trials planned in the session (an upper bound for adaptive methods).
    pub planned: u32,
    /// Intervals of the trial (2 or 3).
    pub intervals: u8,
    /// Each interval's wall law and friction model (the first `intervals` are used).
    pub laws: [(NormalModel, FrictionModel); MAX_INTERVALS],
    /// A rest break comes before this trial (the study's `[breaks]`).
    pub rest: bool,
}

/// What the presenter reports to the main thread.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// The participant answered `trial` with `choice`, `rt_s` seconds after the prompt.
    Answered {
        /// The trial answered.
        trial: u32,
        /// The choice (the interval named from 1, or same–different 0 = same, 1 = different).
        choice: u8,
        /// Response time (s, monotonic clock, from the prompt to the tick that took the answer).
        rt_s: f64,
        /// Magnitude estimation: the number given (`choice` is then 0).
        magnitude: Option<f64>,
    },
    /// The page asked to stop the session.
    Stop,
}

/// Where the trial is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// No trial: waiting for the next plan.
    Idle,
    /// The rest break before the trial: the world is held (no force) until the page continues.
    Break,
    /// Interval `k` (from 0) is installed once the slave leaves every contact.
    FreeSpace(u8),
    /// Interval `k` is presented; `left_s` seconds remain.
    Presenting(u8, f64),
    /// Waiting for the answer since `prompt_ns` (monotonic ns).
    Answer(u64),
    /// The session ends.
    Stopping,
}

/// The state machine (see the module documentation).
#[derive(Clone, Debug)]
pub struct Presenter {
    task: Task,
    interval_s: f64,
    plan: Option<Plan>,
    phase: Phase,
    refused: u32,
    last_saved: u32,
    done: u32,
    planned: u32,
    started: Option<u32>,
    modulus: f64,
    /// The device's buttons now ([`set_buttons`](Self::set_buttons)) and their edge logic.
    buttons: u8,
    device: ButtonAnswers,
}

/// The choices `task` offers.
pub fn valid_choice(task: Task, choice: u8) -> bool {
    match task {
        Task::TwoAfc => (1..=2).contains(&choice),
        Task::ThreeAfc => (1..=3).contains(&choice),
        Task::SameDifferent => choice <= 1,
        // A number, not a choice (`valid_magnitude`).
        Task::Magnitude => false,
    }
}

/// A magnitude estimate the loop takes: finite, > 0 and at most
/// [`MAX_MAGNITUDE`](haptic2d_view::command::MAX_MAGNITUDE) (as the server checks it).
pub fn valid_magnitude(v: f64) -> bool {
    v.is_finite() && v > 0.0 && v <= haptic2d_view::command::MAX_MAGNITUDE
}

/// The task's name on the page.
pub fn task_name(task: Task) -> &'static str {
    match task {
        Task::TwoAfc => "2afc",
        Task::ThreeAfc => "3afc",
        Task::SameDifferent => "same-different",
        Task::Magnitude => "magnitude",
    }
}

/// True when body `slave` has no contact record in `world` (free space).
pub fn in_free_space(world: &World, slave: usize) -> bool {
    !world
        .contact_records()
        .any(|c| c.body_a == slave || c.body_b == slave)
}

impl Presenter {
    /// A presenter for `task` with intervals of `interval_s` seconds of loop time.
    pub fn new(task: Task, interval_s: f64) -> Self {
        Self {
            task,
            interval_s,
            plan: None,
            phase: Phase::Idle,
            refused: 0,
            last_saved: 0,
            done: 0,
            planned: 0,
            started: None,
            modulus: 0.0,
            buttons: 0,
            device: ButtonAnswers::default(),
        }
    }

    /// The device's buttons as read in the last exchange (bit `i` = button `i`), for the next
    /// [`tick`](Self::tick); a device without buttons gives 0.
    pub fn set_buttons(&mut self, buttons: u8) {
        self.buttons = buttons;
    }

    /// The number the reference stands for in a magnitude-estimation study (shown on the page).
    pub fn with_modulus(mut self, modulus: f64) -> Self {
        self.modulus = modulus;
        self
    }

    /// The phase now.
    #[cfg(test)]
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Answers refused so far.
    #[cfg(test)]
    pub fn refused(&self) -> u32 {
        self.refused
    }

    /// Starts presenting `plan` (ignored unless idle: one trial at a time).
    pub fn start(&mut self, plan: Plan) -> bool {
        if self.phase != Phase::Idle {
            return false;
        }
        self.done = plan.done;
        self.planned = plan.planned;
        self.plan = Some(plan);
        if plan.rest {
            self.phase = Phase::Break;
        } else {
            self.phase = Phase::FreeSpace(0);
            self.started = Some(plan.trial);
        }
        true
    }

    /// The trial whose presentation started since the last call (its break over, if it had one):
    /// the per-trial log opens here.
    pub fn take_started(&mut self) -> Option<u32> {
        self.started.take()
    }

    /// True during a rest break: the loop holds the world with zero force.
    pub fn on_break(&self) -> bool {
        self.phase == Phase::Break
    }

    /// One tick: `dt` seconds of loop time (s) not `paused`, at monotonic time `now_ns`, with the
    /// page's study commands since the last tick (`inbox`: answer, magnitude, continue, stop); a
    /// trial's first interval starts only while `watched` (a page is connected: nobody is presented
    /// a stimulus without the page that names the interval). Installs an interval's laws in `world`
    /// (only with `slave` in free space). Returns what the main thread must know. Allocation-free.
    #[allow(clippy::too_many_arguments)]
    pub fn tick(
        &mut self,
        world: &mut World,
        slave: usize,
        dt: f64,
        paused: bool,
        watched: bool,
        now_ns: u64,
        inbox: StudyInbox,
    ) -> Option<Event> {
        if self.phase == Phase::Stopping {
            return None;
        }
        if inbox.stop {
            self.phase = Phase::Stopping;
            return Some(Event::Stop);
        }
        if let Some(trial) = inbox.cont {
            match (self.phase, self.plan) {
                (Phase::Break, Some(plan)) if trial == plan.trial && watched => {
                    self.phase = Phase::FreeSpace(0);
                    self.started = Some(trial);
                }
                // Not this break (another trial, no break, a double press): refused.
                _ => self.refused += 1,
            }
        }
        let answer = inbox.answer;
        let answering = matches!(self.phase, Phase::Answer(_));
        let pressed = self.device.tick(self.task, answering, self.buttons);
        let mut event = None;
        match (self.phase, self.plan) {
            (Phase::FreeSpace(k), Some(plan))
                if (k > 0 || watched) && !paused && in_free_space(world, slave) =>
            {
                let (n, f) = plan.laws[usize::from(k)];
                world.normal = n;
                world.friction = f;
                self.phase = Phase::Presenting(k, self.interval_s);
            }
            (Phase::Presenting(k, left), Some(plan)) => {
                let left = if paused { left } else { left - dt };
                self.phase = if left > 0.0 {
                    Phase::Presenting(k, left)
                } else if k + 1 < plan.intervals {
                    Phase::FreeSpace(k + 1)
                } else {
                    Phase::Answer(now_ns)
                };
            }
            (Phase::Answer(prompt), Some(plan)) => {
                let taken = match (self.task, answer, inbox.magnitude) {
                    (Task::Magnitude, _, Some((t, v))) if t == plan.trial && valid_magnitude(v) => {
                        Some((0, Some(v)))
                    }
                    (_, Some((t, c)), _) if t == plan.trial && valid_choice(self.task, c) => {
                        Some((c, None))
                    }
                    _ => pressed.map(|c| (c, None)),
                };
                if let Some((choice, magnitude)) = taken {
                    event = Some(Event::Answered {
                        trial: plan.trial,
                        choice,
                        rt_s: now_ns.saturating_sub(prompt) as f64 * 1e-9,
                        magnitude,
                    });
                    self.last_saved = plan.trial;
                    self.done = plan.done + 1;
                    self.plan = None;
                    self.phase = Phase::Idle;
                    return event;
                }
                if answer.is_some() || inbox.magnitude.is_some() {
                    self.refused += 1;
                }
                return None;
            }
            _ => {}
        }
        if answer.is_some() || inbox.magnitude.is_some() {
            // Not the answer phase: an early or late answer (a double click) is refused.
            self.refused += 1;
        }
        event
    }

    /// What the page shows.
    pub fn view(&self) -> StudyView {
        let (interval, phase, remaining_s) = match self.phase {
            Phase::Idle => (0, "starting", 0.0),
            Phase::Break => (0, "break", 0.0),
            Phase::FreeSpace(k) => (k + 1, "free_space", self.interval_s),
            Phase::Presenting(k, left) => (k + 1, "presenting", left.max(0.0)),
            Phase::Answer(_) => (0, "answer", 0.0),
            Phase::Stopping => (0, "stopping", 0.0),
        };
        StudyView {
            trial: self.plan.map_or(0, |p| p.trial),
            planned: self.planned,
            done: self.done,
            interval,
            intervals: self.plan.map_or(self.task_intervals(), |p| p.intervals),
            phase,
            remaining_s,
            task: task_name(self.task),
            refused: self.refused,
            last_saved: self.last_saved,
            modulus: if self.task == Task::Magnitude {
                self.modulus
            } else {
                0.0
            },
        }
    }

    fn task_intervals(&self) -> u8 {
        self.task.intervals() as u8
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use haptic2d::scene::builtin;

    /// A presenter on the built-in `box-in-walls` world (1 kHz) and the world's slave, for the
    /// presenter's tests and the buttons' ([`crate::study_buttons`]).
    pub(crate) struct Bench {
        /// The presenter.
        pub p: Presenter,
        /// Its world.
        pub w: World,
        /// The slave body's index.
        pub slave: usize,
    }

    impl Bench {
        /// A presenter of `task` whose intervals last `interval` s.
        pub(crate) fn new(task: Task, interval: f64) -> Self {
            let scene = builtin("box-in-walls", Some(1000.0)).unwrap().unwrap();
            let w = scene.world;
            let slave = w.body_index("box").unwrap();
            Self {
                p: Presenter::new(task, interval),
                w,
                slave,
            }
        }

        /// One 1 ms tick at `now_ns`, unpaused, the page watching, with `inbox`.
        pub(crate) fn tick(&mut self, now_ns: u64, inbox: StudyInbox) -> Option<Event> {
            (self.p).tick(&mut self.w, self.slave, 1e-3, false, true, now_ns, inbox)
        }

        /// Ticks 1 ms apart from `t` ns on, `buttons` held and nothing from the page (no tick
        /// may answer), until the answer phase, within 100 ms; returns its start (ns).
        pub(crate) fn until_answer(&mut self, mut t: u64, buttons: u8) -> u64 {
            while !matches!(self.p.phase(), Phase::Answer(_)) {
                t += 1_000_000;
                self.p.set_buttons(buttons);
                assert_eq!(self.tick(t, StudyInbox::default()), None);
                assert!(t < 100_000_000, "the intervals end");
            }
            t
        }
    }

    /// Two different stimuli: the paper's wall and Minsky's.
    pub(crate) fn two_laws() -> [(NormalModel, FrictionModel); MAX_INTERVALS] {
        let paper = NormalModel::from_name("paper", true).unwrap();
        let minsky = NormalModel::from_name("minsky", true).unwrap();
        let f = FrictionModel::default();
        [(paper, f), (minsky, f), (minsky, f)]
    }

    fn plan(_world: &World, trial: u32) -> Plan {
        Plan {
            trial,
            done: trial - 1,
            planned: 10,
            intervals: 2,
            laws: two_laws(),
            rest: false,
        }
    }

    /// The page's answer `choice` to `trial`.
    fn ans(trial: u32, choice: u8) -> StudyInbox {
        StudyInbox {
            answer: Some((trial, choice)),
            ..StudyInbox::default()
        }
    }

    /// The page's "continue" to `trial` after a break.
    fn inbox_cont(trial: u32) -> StudyInbox {
        StudyInbox {
            cont: Some(trial),
            ..StudyInbox::default()
        }
    }

    /// The page's magnitude `value` for `trial`.
    fn inbox_magnitude(trial: u32, value: f64) -> StudyInbox {
        StudyInbox {
            magnitude: Some((trial, value)),
            ..StudyInbox::default()
        }
    }

    #[test]
    fn answers_for_another_trial_or_outside_the_answer_phase_are_refused() {
        let mut b = Bench::new(Task::TwoAfc, 0.01);
        assert!(b.p.start(plan(&b.w, 3)));
        assert!(!b.p.start(plan(&b.w, 4)), "one trial at a time");
        // An answer while presenting is refused.
        assert_eq!(b.tick(0, ans(3, 1)), None);
        assert_eq!(b.p.refused(), 1);
        let t = b.until_answer(0, 0);
        let prompt = t;
        // Another trial, an impossible choice: refused, still waiting.
        assert_eq!(b.tick(t, ans(2, 1)), None);
        assert_eq!(b.tick(t, ans(3, 3)), None);
        assert_eq!(b.tick(t, ans(3, 0)), None);
        assert_eq!(b.p.refused(), 4);
        assert!(matches!(b.p.phase(), Phase::Answer(_)));
        let ev = b.tick(prompt + 640_000_000, ans(3, 2));
        assert_eq!(
            ev,
            Some(Event::Answered {
                trial: 3,
                choice: 2,
                rt_s: 0.64,
                magnitude: None
            })
        );
        assert_eq!(b.p.phase(), Phase::Idle);
        // A second click on the same answer: refused.
        assert_eq!(b.tick(t, ans(3, 2)), None);
        assert_eq!(b.p.refused(), 5);
        assert_eq!(b.p.view().last_saved, 3);
        assert_eq!(b.p.view().done, 3);
    }

    #[test]
    fn paused_ticks_do_not_count_toward_an_interval() {
        let mut b = Bench::new(Task::TwoAfc, 0.005);
        b.p.start(plan(&b.w, 1));
        b.tick(0, StudyInbox::default());
        assert_eq!(b.p.phase(), Phase::Presenting(0, 0.005));
        for _ in 0..100 {
            let paused = true;
            (b.p).tick(
                &mut b.w,
                b.slave,
                1e-3,
                paused,
                true,
                0,
                StudyInbox::default(),
            );
        }
        assert_eq!(b.p.phase(), Phase::Presenting(0, 0.005));
        for _ in 0..5 {
            b.tick(0, StudyInbox::default());
        }
        assert_eq!(b.p.phase(), Phase::FreeSpace(1));
    }

    #[test]
    fn same_different_takes_same_and_different_and_three_afc_takes_three_intervals() {
        assert!(valid_choice(Task::SameDifferent, 0) && valid_choice(Task::SameDifferent, 1));
        assert!(!valid_choice(Task::SameDifferent, 2));
        assert!(!valid_choice(Task::TwoAfc, 0) && !valid_choice(Task::TwoAfc, 3));
        assert!(valid_choice(Task::ThreeAfc, 3) && !valid_choice(Task::ThreeAfc, 0));
    }

    /// A trial with a rest break before it: the loop holds (`on_break`, no law installed, no
    /// trial log opened) until the page continues this trial, with a page connected; a continue for
    /// another trial, or a second one, is refused and changes nothing.
    #[test]
    fn a_break_holds_the_trial_until_the_page_continues_it() {
        let Bench {
            mut p,
            mut w,
            slave,
        } = Bench::new(Task::TwoAfc, 0.005);
        let before = w.normal;
        assert!(p.start(Plan {
            rest: true,
            ..plan(&w, 5)
        }));
        assert_eq!((p.phase(), p.view().phase), (Phase::Break, "break"));
        let idle = StudyInbox::default();
        for _ in 0..1000 {
            assert_eq!(p.tick(&mut w, slave, 1e-3, false, true, 0, idle), None);
        }
        assert!(p.on_break() && p.take_started().is_none());
        assert_eq!(w.normal, before, "no stimulus during the break");
        // An answer, a continue for another trial, a continue with no page: refused or held.
        p.tick(&mut w, slave, 1e-3, false, true, 0, ans(5, 1));
        p.tick(&mut w, slave, 1e-3, false, true, 0, inbox_cont(4));
        assert_eq!(p.refused(), 2);
        p.tick(&mut w, slave, 1e-3, false, false, 0, inbox_cont(5));
        assert!(p.on_break(), "nobody continues without the page");
        assert_eq!(p.refused(), 3);
        p.tick(&mut w, slave, 1e-3, false, true, 0, inbox_cont(5));
        // The box is in free space: the first interval is installed in the same tick.
        assert_eq!(p.phase(), Phase::Presenting(0, 0.005));
        assert_eq!(
            p.take_started(),
            Some(5),
            "the trial (and its log) starts now"
        );
        assert_eq!(p.take_started(), None);
        p.tick(&mut w, slave, 1e-3, false, true, 0, inbox_cont(5));
        assert_eq!(p.refused(), 4, "a second continue is refused");
        assert_eq!(w.normal, two_laws()[0].0, "the first interval is presented");
        // Without a break the trial starts at once.
        let mut q = Presenter::new(Task::TwoAfc, 0.005);
        q.start(plan(&w, 1));
        assert_eq!(q.take_started(), Some(1));
    }

    /// Magnitude estimation takes a finite number above 0 for the trial presented (its `choice`
    /// is 0, as the simulated path's) and refuses interval choices and bad numbers.
    #[test]
    fn magnitude_takes_a_positive_number_for_its_trial_and_refuses_choices() {
        let mut b = Bench::new(Task::Magnitude, 0.005);
        assert_eq!(b.p.view().task, "magnitude");
        b.p.start(plan(&b.w, 2));
        let t = b.until_answer(0, 0);
        for bad in [
            ans(2, 1),
            inbox_magnitude(1, 50.0),
            inbox_magnitude(2, 0.0),
            inbox_magnitude(2, -3.0),
            inbox_magnitude(2, f64::NAN),
            inbox_magnitude(2, f64::INFINITY),
        ] {
            assert_eq!(b.tick(t, bad), None);
        }
        assert_eq!(b.p.refused(), 6);
        let ev = b.tick(t + 2_000_000_000, inbox_magnitude(2, 137.5));
        assert_eq!(
            ev,
            Some(Event::Answered {
                trial: 2,
                choice: 0,
                rt_s: 2.0,
                magnitude: Some(137.5)
            })
        );
        // A magnitude in a 2AFC study is refused.
        let mut q = Bench::new(Task::TwoAfc, 0.005);
        q.p.start(plan(&q.w, 1));
        let t = q.until_answer(0, 0);
        assert_eq!(q.tick(t, inbox_magnitude(1, 5.0)), None);
        assert_eq!(q.p.refused(), 1);
    }
}
