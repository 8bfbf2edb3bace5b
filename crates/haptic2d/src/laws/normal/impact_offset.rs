//! A contact's normal law with the surface offset of a resolved impact (issue 16, docs/MODELS.md
//! §E.7): the penetration that the discrete detection left at the impact sample is not paid back
//! as spring impulse.
//!
//! A record created Colliding is detected up to `|C0|·T` inside the surface (the vertex crossed it
//! between two samples). The impulse (§7) already sets the post-impact velocity by the restitution
//! law; a spring acting on that depth afterwards adds `∫ K·δ dt` on top (0.33 N·s on a 1 kg box
//! dropped flat from 0.5 m at 1 kHz: apex 0.181 m instead of `e²h` = 0.125 m). So the record's law
//! sees the surface moved in to the depth gained in the detection sample, `σ`, and the surface
//! follows the vertex back out, never in:
//!
//! ```text
//! at the impact:  σ ← clamp(δ_k − max(0, δ_{k−1} − σ), σ, δ_k)      (a new record: σ = δ_k)
//! every sample:   σ ← min(σ, max(0, δ_k)),   the law runs on d_j + σ (j = k, k−1, k−2)
//! ```
//!
//! Shifting the whole distance history by the same `σ` keeps every law's rates (`Δd/T`, the SEH
//! extrapolation, whose coefficients sum to 1) unchanged. **Passivity**: every law is monotone in
//! the depth, so the offset only lowers the force, and the stored energy it reports
//! (`½K·(δ − σ)²`) is continuous while `σ` shrinks (it shrinks only where `δ − σ` would be
//! negative, i.e. where the spring is slack), and lower at creation than without the offset; the
//! offset adds no energy anywhere. A body that comes to rest in a plastic impact (`e = 0`) keeps the
//! detection depth `σ ≤ |C0|·T` as an extra penetration for the life of the record (a geometric
//! error of the sampling, like the detection depth itself), instead of being pushed out by it.

use super::{NormalInput, NormalLaw, NormalModel};

/// A contact record's normal law ([`NormalModel`], the copy of the scene's prototype, or any other
/// [`NormalLaw`] `M`) and its impact surface offset `σ` (m, ≥ 0; 0 outside an impact's aftermath).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ContactNormal<M = NormalModel> {
    /// Surface offset `σ` (m): the law acts on the depth beyond it (first: read every sample).
    offset: f64,
    /// The law and its per-contact state.
    pub model: M,
}

impl<M: NormalLaw> ContactNormal<M> {
    /// The law `model` without offset.
    #[inline]
    pub fn new(model: M) -> Self {
        Self { model, offset: 0.0 }
    }

    /// The current surface offset `σ` (m).
    #[inline]
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// The law `model` with surface offset `offset` (m; the lean law slots keep the offset apart
    /// from the law, `contact/lean_law.rs`).
    #[inline(always)]
    pub(crate) fn with_offset(model: M, offset: f64) -> Self {
        Self { model, offset }
    }

    /// The same offset with the law converted by `f` (the contact set's compact and whole slots).
    pub(crate) fn map<N>(self, f: impl FnOnce(M) -> N) -> ContactNormal<N> {
        ContactNormal {
            offset: self.offset,
            model: f(self.model),
        }
    }

    /// Called when the record's impact has been resolved at this sample, with the record's signed
    /// distance history `d` (m, `d[0]` this sample's) and its valid length `hist`: the depth gained
    /// since the last sample, `δ_k − max(0, δ_{k−1} − σ)`, becomes part of the offset (all of `δ_k`
    /// for a vertex that was outside at `k − 1`, or without history).
    pub fn impact_resolved(&mut self, d: [f64; 3], hist: u8) {
        let depth = (-d[0]).max(0.0);
        let before = if hist >= 2 {
            (-d[1] - self.offset).max(0.0)
        } else {
            0.0
        };
        self.offset = (depth - before).clamp(self.offset.min(depth), depth);
    }
}

impl<M: NormalLaw> NormalLaw for ContactNormal<M> {
    fn reset(&mut self) {
        self.offset = 0.0;
        self.model.reset();
    }

    #[inline(always)]
    fn force(&mut self, input: &NormalInput) -> f64 {
        if self.offset > 0.0 {
            // `σ.min(depth)` as one compare-select: the depth is never NaN (`max(−d, 0)`) and
            // `σ > 0` here, so `f64::min`'s NaN fix-up never applies (and equal values have equal
            // bits): the same value, 5 fewer instructions a record with an offset.
            let depth = input.depth();
            if depth < self.offset {
                self.offset = depth;
            }
            if self.offset > 0.0 {
                let mut shifted = *input;
                for d in shifted.d.iter_mut() {
                    *d += self.offset;
                }
                return self.model.force(&shifted);
            }
        }
        self.model.force(input)
    }

    fn stored_energy(&self) -> f64 {
        self.model.stored_energy()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::normal::PaperLaw;

    fn input(d: [f64; 3], c0: f64) -> NormalInput {
        NormalInput {
            d,
            hist: 3,
            c0,
            dt: 1e-3,
            m_eff: 0.5,
        }
    }

    #[test]
    fn new_impact_record_pays_no_spring_for_its_detection_depth() {
        let mut n = ContactNormal::new(NormalModel::Paper(PaperLaw::new(1e5, 40.0)));
        // Detected 2 mm inside, 1 mm outside the sample before: σ = 2 mm.
        n.impact_resolved([-0.002, 0.001, 0.004], 3);
        assert_eq!(n.offset(), 0.002);
        // Separating after the impulse: no force, no stored energy.
        assert_eq!(n.force(&input([-0.002, -0.002, -0.002], 1.0)), 0.0);
        assert_eq!(n.stored_energy(), 0.0);
        // The vertex moves out to 1.5 mm: the surface follows it.
        assert_eq!(n.force(&input([-0.0015, -0.002, -0.002], 0.5)), 0.0);
        assert_eq!(n.offset(), 0.0015);
        // Pressed 0.1 mm beyond the offset surface (at rest): the spring acts on that alone.
        let f = n.force(&input([-0.0016, -0.0016, -0.0016], 0.0));
        assert!((f - 1e5 * 1e-4).abs() < 1e-9, "{f}");
        assert!((n.stored_energy() - 0.5 * 1e5 * 1e-8).abs() < 1e-15);
    }

    #[test]
    fn recollision_exempts_only_the_depth_gained_in_the_detection_sample() {
        let mut n = ContactNormal::new(NormalModel::Paper(PaperLaw::new(1e5, 0.0)));
        // Was 1 mm deep (a resting record), now 1.5 mm: σ = 0.5 mm.
        n.impact_resolved([-0.0015, -0.001, -0.001], 3);
        assert!((n.offset() - 0.0005).abs() < 1e-15);
        let f = n.force(&input([-0.0015, -0.0015, -0.0015], 0.0));
        assert!((f - 100.0).abs() < 1e-9, "{f}");
        // Without history the whole depth is the detection's.
        let mut m = ContactNormal::new(NormalModel::Paper(PaperLaw::new(1e5, 0.0)));
        m.impact_resolved([-0.001, 0.0, 0.0], 1);
        assert_eq!(m.offset(), 0.001);
        m.reset();
        assert_eq!(m.offset(), 0.0);
    }

    /// The offset's update `σ ← min(σ, depth)`, written as a compare-select in `force`, gives the
    /// force, the stored energy and the new offset bit for bit as with `f64::min` (the form it
    /// replaced), over 200 000 seeded random offsets and histories with exact zeros of both signs,
    /// equal values, infinities and NaN among them.
    #[test]
    fn offset_update_answers_as_f64_min_bit_for_bit() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(42);
        let special = [
            0.0,
            -0.0,
            1e-3,
            -1e-3,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let draw = |rng: &mut rand_chacha::ChaCha8Rng| -> f64 {
            if rng.random_range(0..4) == 0 {
                special[rng.random_range(0..special.len())]
            } else {
                rng.random_range(-4e-3..4e-3)
            }
        };
        let mut shifted_runs = 0;
        for _ in 0..200_000 {
            let d = [draw(&mut rng), draw(&mut rng), draw(&mut rng)];
            // Offsets equal to the depth, and above and below it.
            let offset = match rng.random_range(0..3) {
                0 => -d[0],
                _ => draw(&mut rng).abs(),
            };
            let inp = NormalInput {
                hist: rng.random_range(1..4),
                ..input(d, draw(&mut rng))
            };
            let law = NormalModel::Paper(PaperLaw::new(1e5, 40.0));
            let mut fast = ContactNormal::with_offset(law, offset);
            let f = fast.force(&inp);
            // The reference: the update with `f64::min`, then the same law on the same inputs.
            let mut reference = ContactNormal::with_offset(law, offset);
            let g = if reference.offset > 0.0 {
                reference.offset = reference.offset.min(inp.depth());
                if reference.offset > 0.0 {
                    shifted_runs += 1;
                    let mut shifted = inp;
                    for x in shifted.d.iter_mut() {
                        *x += reference.offset;
                    }
                    reference.model.force(&shifted)
                } else {
                    reference.model.force(&inp)
                }
            } else {
                reference.model.force(&inp)
            };
            assert_eq!(f.to_bits(), g.to_bits(), "{d:?} {offset}");
            assert_eq!(fast.offset.to_bits(), reference.offset.to_bits(), "{d:?}");
            assert_eq!(
                fast.stored_energy().to_bits(),
                reference.stored_energy().to_bits()
            );
        }
        assert!(
            shifted_runs > 50_000,
            "{shifted_runs} records with an offset"
        );
    }

    #[test]
    fn offset_never_raises_the_force() {
        let mut plain = NormalModel::Paper(PaperLaw::new(1e5, 40.0));
        let mut off = ContactNormal::new(plain);
        off.impact_resolved([-0.003, 0.0, 0.0], 1);
        let mut d = [-0.003, -0.003, -0.003];
        for k in 0..40 {
            let depth = 0.003 * (1.0 + (k as f64 * 0.7).sin()) / 2.0;
            d = [-depth, d[0], d[1]];
            let inp = input(d, (d[0] - d[1]) / 1e-3);
            let (fp, fo) = (plain.force(&inp), off.force(&inp));
            assert!(fo <= fp + 1e-12, "k {k}: {fo} > {fp}");
            assert!(off.stored_energy() <= plain.stored_energy() + 1e-18);
        }
    }
}
