//! Answers from the device's buttons in the browser study (issue 40 item 2): the participant may
//! answer on the page or on the device. Per tick, inside the haptic tick: no allocation, no lock.
//!
//! The buttons are [`DeviceIo::buttons`](haptic2d_rt::DeviceIo::buttons) as read in the tick's last
//! exchange (bit `i` = button `i` pressed). The mapping (docs/STUDIES.md, "Answering with device
//! buttons"):
//!
//! | task | button 0 | button 1 | button 2 |
//! |---|---|---|---|
//! | 2AFC | first | second | — |
//! | 3AFC | first | second | third |
//! | same–different | same | different | — |
//! | magnitude estimation | — | — | — |
//!
//! A button answers only on its **press** (its bit rising from one tick to the next) **after every
//! button was released at least once since the answer phase began**: a button held through the
//! last interval (the hand resting on it, or a press meant for an earlier prompt) never answers.
//! Two buttons pressed in the same tick answer nothing (ambiguous); a button with no meaning in the
//! task (button 2 in 2AFC, 3–7 always) is ignored. A device without buttons reports 0 and changes
//! nothing.

use haptic2d_lab::study::file::Task;

use crate::study_present::valid_choice;

/// The choice button `button` (0–7) gives in `task` (the interval named from 1; same–different
/// 0 = same, 1 = different), if it gives one.
pub fn choice_of(task: Task, button: u8) -> Option<u8> {
    let c = match task {
        Task::TwoAfc | Task::ThreeAfc => button.checked_add(1)?,
        Task::SameDifferent => button,
        Task::Magnitude => return None,
    };
    valid_choice(task, c).then_some(c)
}

/// The edge logic of the device's buttons over the study's ticks (module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ButtonAnswers {
    /// The buttons of the previous tick.
    last: u8,
    /// Every button was released at some tick since the answer phase began.
    armed: bool,
}

impl ButtonAnswers {
    /// One tick: `answering` is true while the trial waits for its answer, `buttons` the device's
    /// buttons now. Returns the choice a press answers in `task` (see [`choice_of`]), if one does.
    pub fn tick(&mut self, task: Task, answering: bool, buttons: u8) -> Option<u8> {
        let rising = buttons & !self.last;
        self.last = buttons;
        if !answering {
            self.armed = false;
            return None;
        }
        if !self.armed {
            // Armed by a tick with every button up; a press needs a later tick.
            self.armed = buttons == 0;
            return None;
        }
        if rising.count_ones() != 1 {
            return None;
        }
        choice_of(task, rising.trailing_zeros() as u8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buttons_map_to_the_intervals_to_same_or_different_and_magnitude_ignores_them() {
        assert_eq!(choice_of(Task::TwoAfc, 0), Some(1));
        assert_eq!(choice_of(Task::TwoAfc, 1), Some(2));
        assert_eq!(choice_of(Task::TwoAfc, 2), None);
        assert_eq!(choice_of(Task::ThreeAfc, 2), Some(3));
        assert_eq!(choice_of(Task::ThreeAfc, 3), None);
        assert_eq!(choice_of(Task::SameDifferent, 0), Some(0));
        assert_eq!(choice_of(Task::SameDifferent, 1), Some(1));
        assert_eq!(choice_of(Task::SameDifferent, 2), None);
        assert!((0..8).all(|b| choice_of(Task::Magnitude, b).is_none()));
        assert_eq!(choice_of(Task::ThreeAfc, 255), None);
    }

    /// The answers of fresh [`ButtonAnswers`] of a 2AFC task to the ticks `(answer phase,
    /// buttons)` in turn.
    fn two_afc_answers(ticks: &[(bool, u8)]) -> Vec<Option<u8>> {
        let mut b = ButtonAnswers::default();
        ticks
            .iter()
            .map(|&(a, p)| b.tick(Task::TwoAfc, a, p))
            .collect()
    }

    #[test]
    fn a_button_held_through_the_interval_answers_only_after_a_release_and_a_new_press() {
        // Held during the last interval and into the answer phase: no answer, however long.
        let mut ticks = vec![(false, 0b01)];
        ticks.extend([(true, 0b01); 100]);
        // A second button pressed while the first is held: still not armed.
        ticks.extend([(true, 0b11), (true, 0b10)]);
        // Released, then pressed: answers.
        ticks.extend([(true, 0), (true, 0), (true, 0b10)]);
        let mut want = vec![None; ticks.len()];
        *want.last_mut().unwrap() = Some(2);
        assert_eq!(two_afc_answers(&ticks), want);
    }

    #[test]
    fn a_press_answers_once_on_its_rising_edge() {
        let mut b = ButtonAnswers::default();
        assert_eq!(b.tick(Task::ThreeAfc, true, 0), None);
        assert_eq!(b.tick(Task::ThreeAfc, true, 0b100), Some(3));
        // Still held: no second answer.
        assert_eq!(b.tick(Task::ThreeAfc, true, 0b100), None);
    }

    #[test]
    fn a_press_in_the_answer_phases_first_tick_does_not_answer() {
        // Released through the interval, pressed exactly as the answer phase begins: the phase's
        // first tick arms on "all released" only, so this press (begun before the prompt could be
        // seen) needs a release first.
        let ticks = [(false, 0), (true, 0b01), (true, 0), (true, 0b01)];
        assert_eq!(two_afc_answers(&ticks), [None, None, None, Some(1)]);
    }

    #[test]
    fn two_buttons_at_once_or_an_unmapped_button_answer_nothing() {
        let mut b = ButtonAnswers::default();
        b.tick(Task::TwoAfc, true, 0);
        assert_eq!(b.tick(Task::TwoAfc, true, 0b11), None, "ambiguous");
        assert_eq!(b.tick(Task::TwoAfc, true, 0b111), None, "button 2 in 2AFC");
        let mut m = ButtonAnswers::default();
        m.tick(Task::Magnitude, true, 0);
        assert_eq!(m.tick(Task::Magnitude, true, 0b1), None);
    }

    /// The presenter with a device's buttons: trial 4 of a 2-interval `task` presented with
    /// `held` down throughout, up to its answer phase; returns the presenter, the world, the slave
    /// and the prompt's time (ns).
    fn to_answer(
        task: Task,
        held: u8,
    ) -> (
        crate::study_present::Presenter,
        haptic2d::world::World,
        usize,
        u64,
    ) {
        use crate::study_present::Plan;
        use haptic2d::laws::friction::FrictionModel;
        use haptic2d::laws::normal::NormalModel;
        let mut b = crate::study_present::tests::Bench::new(task, 0.005);
        let law = (
            NormalModel::from_name("paper", true).unwrap(),
            FrictionModel::default(),
        );
        b.p.start(Plan {
            trial: 4,
            done: 3,
            planned: 10,
            intervals: 2,
            laws: [law; 3],
            rest: false,
        });
        let t = b.until_answer(0, held);
        (b.p, b.w, b.slave, t)
    }

    /// End to end through the presenter: a button held through the last interval does not answer;
    /// released and pressed, it answers the trial with its choice, the response time measured from
    /// the prompt (the answer phase's start) to the tick of the press, as the page's.
    #[test]
    fn the_presenter_takes_a_press_after_a_release_with_its_response_time() {
        use crate::study_present::{Event, Phase};
        let (mut p, mut w, slave, prompt) = to_answer(Task::TwoAfc, 0b01);
        let mut tick = |p: &mut crate::study_present::Presenter, buttons: u8, at: u64| {
            p.set_buttons(buttons);
            p.tick(&mut w, slave, 1e-3, false, true, at, Default::default())
        };
        for k in 1..=500 {
            assert_eq!(tick(&mut p, 0b01, prompt + k * 1_000_000), None, "held");
        }
        assert_eq!(tick(&mut p, 0, prompt + 501_000_000), None, "released");
        let ev = tick(&mut p, 0b10, prompt + 750_000_000);
        assert_eq!(
            ev,
            Some(Event::Answered {
                trial: 4,
                choice: 2,
                rt_s: 0.75,
                magnitude: None
            })
        );
        assert_eq!(p.phase(), Phase::Idle);
        assert_eq!(p.refused(), 0, "a press is not a refused answer");
        assert_eq!(p.view().last_saved, 4);
    }

    /// A device without buttons (always 0) leaves the page's answer as it was; with a press and a
    /// page answer in one tick the page's is taken; magnitude estimation ignores the buttons.
    #[test]
    fn the_page_answers_as_before_and_magnitude_ignores_the_buttons() {
        use crate::run_view::StudyInbox;
        use crate::study_present::{Event, Phase};
        let page = |choice| StudyInbox {
            answer: Some((4, choice)),
            ..StudyInbox::default()
        };
        let (mut p, mut w, slave, prompt) = to_answer(Task::TwoAfc, 0);
        p.set_buttons(0);
        assert_eq!(
            p.tick(
                &mut w,
                slave,
                1e-3,
                false,
                true,
                prompt + 1,
                Default::default()
            ),
            None
        );
        p.set_buttons(0b01);
        let ev = p.tick(
            &mut w,
            slave,
            1e-3,
            false,
            true,
            prompt + 2_000_000_000,
            page(2),
        );
        assert!(
            matches!(ev, Some(Event::Answered { choice: 2, rt_s, .. }) if rt_s == 2.0),
            "{ev:?}"
        );
        let (mut m, mut w, slave, prompt) = to_answer(Task::Magnitude, 0);
        for (k, b) in [0u8, 1, 0, 2, 0, 4].into_iter().enumerate() {
            m.set_buttons(b);
            let at = prompt + k as u64 * 1_000_000;
            assert_eq!(
                m.tick(&mut w, slave, 1e-3, false, true, at, Default::default()),
                None
            );
        }
        assert!(matches!(m.phase(), Phase::Answer(_)));
    }

    #[test]
    fn leaving_the_answer_phase_disarms() {
        let mut b = ButtonAnswers::default();
        b.tick(Task::SameDifferent, true, 0);
        // The page answered; the next trial presents, the participant presses during it.
        assert_eq!(b.tick(Task::SameDifferent, false, 0), None);
        assert_eq!(b.tick(Task::SameDifferent, false, 0b10), None);
        // Held into the next answer phase: no answer until released and pressed again.
        assert_eq!(b.tick(Task::SameDifferent, true, 0b10), None);
        assert_eq!(b.tick(Task::SameDifferent, true, 0), None);
        assert_eq!(b.tick(Task::SameDifferent, true, 0b10), Some(1));
    }
}
