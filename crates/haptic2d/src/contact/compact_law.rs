//! The compact law slot: every normal law but the hysteretic wall, in 56 bytes instead of the
//! 184 of [`NormalModel`].
//!
//! A [`NormalModel`] is as large as its largest variant, the hysteretic wall (four slide elements
//! with their parameters and states, 176 bytes), so a contact's law slot
//! ([`LawState`]) is 272 bytes although the paper's law and the reset integrator use about 110 of
//! them. The force pass streams every contact's slot each sample, and on a pile of 1000 boxes the
//! slots are a quarter of the step's working set (docs/PERFORMANCE.md, issue 17). The contact set's
//! pool therefore keeps its slots in this form, 144 bytes each, for as long as no record needs
//! the wall ([`LawPool`](super::law_pool::LawPool)). The laws are the same types with the same
//! code: a slot gives bit-identical forces and states in either form.

use super::record::LawState;
use crate::laws::normal::{
    normal_law_dispatch, BrakingPulseLaw, ColgateLaw, MassiePiLaw, MinskyLaw, NormalModel,
    PaperLaw, SehLaw, ZohLaw,
};

/// [`NormalModel`] without [`NormalModel::Hysteretic`]. An explicit tag byte (`repr(u8)`, 56
/// bytes): without it the tag hides in the braking pulse's `bool`, and decoding it cost the force
/// pass about 16 instructions per contact (callgrind, pile:1000).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(u8)]
pub(crate) enum CompactNormal {
    Paper(PaperLaw),
    Zoh(ZohLaw),
    Minsky(MinskyLaw),
    Colgate(ColgateLaw),
    Seh(SehLaw),
    MassiePi(MassiePiLaw),
    BrakingPulse(BrakingPulseLaw),
}

normal_law_dispatch!(CompactNormal {
    Paper,
    Zoh,
    Minsky,
    Colgate,
    Seh,
    MassiePi,
    BrakingPulse,
});

impl CompactNormal {
    /// `model` in compact form, or `None` for the hysteretic wall.
    pub(crate) fn from_model(model: &NormalModel) -> Option<Self> {
        Some(match *model {
            NormalModel::Paper(l) => Self::Paper(l),
            NormalModel::Zoh(l) => Self::Zoh(l),
            NormalModel::Minsky(l) => Self::Minsky(l),
            NormalModel::Colgate(l) => Self::Colgate(l),
            NormalModel::Seh(l) => Self::Seh(l),
            NormalModel::MassiePi(l) => Self::MassiePi(l),
            NormalModel::BrakingPulse(l) => Self::BrakingPulse(l),
            NormalModel::Hysteretic(_) => return None,
        })
    }

    /// The same law and state as a [`NormalModel`].
    pub(crate) fn to_model(self) -> NormalModel {
        match self {
            Self::Paper(l) => NormalModel::Paper(l),
            Self::Zoh(l) => NormalModel::Zoh(l),
            Self::Minsky(l) => NormalModel::Minsky(l),
            Self::Colgate(l) => NormalModel::Colgate(l),
            Self::Seh(l) => NormalModel::Seh(l),
            Self::MassiePi(l) => NormalModel::MassiePi(l),
            Self::BrakingPulse(l) => NormalModel::BrakingPulse(l),
        }
    }
}

impl LawState<CompactNormal> {
    /// The same states with the whole [`NormalModel`] (offset, law and friction unchanged).
    pub(crate) fn widen(&self) -> LawState {
        LawState {
            friction: self.friction,
            normal: self.normal.map(CompactNormal::to_model),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::normal::{ContactNormal, NormalLaw, NORMAL_MODEL_NAMES};

    /// The compact slot is the size the module docs give, and smaller than the whole one.
    #[test]
    fn compact_slot_is_144_bytes_against_272() {
        assert_eq!(std::mem::size_of::<CompactNormal>(), 56);
        assert_eq!(std::mem::size_of::<LawState<CompactNormal>>(), 144);
        assert_eq!(std::mem::size_of::<LawState>(), 272);
    }

    /// Every law but the hysteretic wall has a compact form, which converts back to itself.
    #[test]
    fn every_law_but_the_hysteretic_wall_round_trips() {
        for name in NORMAL_MODEL_NAMES {
            for per in [false, true] {
                let m = NormalModel::from_name(name, per).unwrap();
                match CompactNormal::from_model(&m) {
                    Some(c) => assert_eq!(c.to_model(), m, "{name}"),
                    None => assert_eq!(name, "hysteretic"),
                }
            }
        }
    }

    /// A compact law gives the same forces, states and stored energies as its whole form over a
    /// press-and-release history, and widening a slot mid-contact keeps its state (the next
    /// forces agree too).
    #[test]
    fn compact_law_forces_are_the_whole_laws_bit_for_bit() {
        use crate::laws::normal::NormalInput;
        for name in NORMAL_MODEL_NAMES.iter().filter(|n| **n != "hysteretic") {
            let m = NormalModel::from_name(name, true).unwrap();
            let mut whole = ContactNormal::new(m);
            let mut compact = ContactNormal::new(CompactNormal::from_model(&m).unwrap());
            whole.impact_resolved([-0.002, 0.001, 0.003], 3);
            compact.impact_resolved([-0.002, 0.001, 0.003], 3);
            let mut d = [0.001, 0.002, 0.003];
            for k in 0..400 {
                let x = -0.004 * (k as f64 * 0.05).sin();
                d = [x, d[0], d[1]];
                let input = NormalInput {
                    d,
                    hist: 3,
                    c0: (d[0] - d[1]) / 1e-3,
                    dt: 1e-3,
                    m_eff: 0.7,
                };
                let (fw, fc) = (whole.force(&input), compact.force(&input));
                assert_eq!(fw.to_bits(), fc.to_bits(), "{name} at {k}");
                assert_eq!(
                    whole.stored_energy().to_bits(),
                    compact.stored_energy().to_bits()
                );
                if k == 200 {
                    let slot = LawState {
                        friction: Default::default(),
                        normal: compact,
                    };
                    assert_eq!(slot.widen().normal, whole, "{name} widened at {k}");
                }
            }
        }
    }

    /// A world whose law slots are widened in the middle of a run, with live records, when its
    /// prototype becomes the hysteretic wall, moves bit for bit like one whose slots were whole
    /// from the start (pile:20 shoved sideways at step 300 so that the friction springs carry
    /// load, 700 steps of the paper's law, then the top box tossed up and 800 steps of the wall).
    #[test]
    fn widening_the_law_slots_mid_run_changes_no_trajectory() {
        use crate::contact::law_pool::SlotForm;
        use crate::contact::test_pile::{assert_same_poses, shove, toss_top_box};
        use crate::laws::normal::HystereticLaw;
        let world = crate::scene::builtin("pile:20", None)
            .unwrap()
            .unwrap()
            .world;
        const SWITCH: usize = 700;
        let (mut compact, mut whole) = (world.clone(), world);
        whole.contacts_mut().widen_law_slots();
        for k in 0..1500 {
            if k == 300 {
                // A shove that loads the records' friction springs before the switch.
                shove(&mut compact);
                shove(&mut whole);
            }
            if k == SWITCH {
                assert_ne!(compact.contacts().law_slot_form(), SlotForm::Whole);
                assert!(
                    compact.contacts().contact_count() > 20,
                    "records live at the switch"
                );
                let wall = NormalModel::Hysteretic(HystereticLaw::per_contact());
                compact.normal = wall;
                whole.normal = wall;
                // The top box is tossed up: the others keep their records, and it lands
                // (creating new records, so widening the slots) while they are live.
                toss_top_box(&mut compact);
                toss_top_box(&mut whole);
            }
            compact.step();
            whole.step();
            assert_same_poses(&compact, &whole, k);
        }
        assert_eq!(
            compact.contacts().law_slot_form(),
            SlotForm::Whole,
            "widened after the switch"
        );
    }
}
