//! The force pass in blocks for lean law slots (issue 42 item 1, after Box2D's wide contact
//! solver): the paper's pair of laws ([`PaperLaw`] with its impact surface offset, and the
//! [`ResetIntegrator`] scaling its strain limit) run on two Continuous records at once, their
//! inputs and slot states gathered straight from the records into two-lane registers ([`Pair`],
//! SSE2 `f64x2` on x86-64), the laws' branches written as selects, and the results scattered
//! back; the loaded list and the wrenches then follow record by record, in record order, as in
//! the scalar pass.
//!
//! Every lane runs the same IEEE operations in the same order as the scalar laws
//! (`ContactNormal::force`, `PaperLaw::force`, `ResetIntegrator::loaded`, its shell's unloaded
//! reset and `spring_energy`), so the forces, states and energies are bit for bit the scalar
//! pass's (pinned by the seeded test below). The constants the laws compute on every call
//! (`0.5·Kc`, `−Kc`, `1 + a`, `(1 + a)·Kr`) are computed once: the same operations on the same
//! values.

mod pair;

use super::{ForcePass, Tally};
use crate::contact::lean_law::{LeanState, LeanStore};
use crate::contact::record::{ContactState, VeContact};
use crate::laws::friction::{FrictionMode, LoadScaling, ResetIntegrator};
use crate::laws::normal::PaperLaw;
use pair::Pair;

/// The shared parameters of the lean slots, with the constants the laws derive from them, in
/// both lanes.
#[derive(Clone, Copy, Debug)]
struct Params {
    /// `0.5·Kc` (N/m), `−Kc` (N/m) and `Bc` (N·s/m) of the paper's law.
    half_kc: Pair,
    neg_kc: Pair,
    bc: Pair,
    /// `Kr` (N/m), `−Kr`, `μk`, `β` (N·s/m), `1 + a = 1 + (μs/μk − 1)` and `(1 + a)·Kr` (N/m).
    kr: Pair,
    neg_kr: Pair,
    mu_k: Pair,
    beta: Pair,
    one_a: Pair,
    one_a_kr: Pair,
}

/// Two records' law inputs and slot states.
#[derive(Clone, Copy, Debug)]
struct Inputs {
    /// Signed distance history (m) and its length (samples, 1 to 3).
    d: [Pair; 3],
    hist: [u8; 2],
    /// `C0` (m/s), `s` (m), `Δs = s − s_prev` (m) and `S0` (m/s).
    c0: Pair,
    s: Pair,
    ds: Pair,
    s0: Pair,
    /// Slot state: surface offset `σ` (m), strain `p` (m), stiffness of the last sample (N/m).
    offset: Pair,
    p: Pair,
    k_used: Pair,
}

/// Two records' results and new slot states.
#[derive(Clone, Copy, Debug)]
struct Outputs {
    /// Slot state: surface offset `σ` (m), the paper law's stored energy (J), strain `p` (m),
    /// stiffness (N/m), slip (else stick).
    offset: Pair,
    stored: Pair,
    p: Pair,
    k_used: Pair,
    slip: [bool; 2],
    /// `F_n` (N), `F_t` (N), the god-object `s_g` (m), the record's stored energy (J, normal
    /// plus friction).
    f_n: Pair,
    f_t: Pair,
    s_g: Pair,
    energy: Pair,
}

impl Params {
    /// The constants of `paper` and `friction` (whose load scaling is [`LoadScaling::Limit`]).
    fn of(paper: &PaperLaw, friction: &ResetIntegrator) -> Self {
        let one_a = 1.0 + friction.a();
        Self {
            half_kc: Pair::splat(0.5 * paper.kc),
            neg_kc: Pair::splat(-paper.kc),
            bc: Pair::splat(paper.bc),
            kr: Pair::splat(friction.kr),
            neg_kr: Pair::splat(-friction.kr),
            mu_k: Pair::splat(friction.mu_k),
            beta: Pair::splat(friction.beta),
            one_a: Pair::splat(one_a),
            one_a_kr: Pair::splat(one_a * friction.kr),
        }
    }

    /// Runs the laws on both lanes of `i`.
    #[inline(always)]
    fn laws(&self, i: &Inputs) -> Outputs {
        let (zero, half) = (Pair::splat(0.0), Pair::splat(0.5));
        // The surface offset (`ContactNormal::force`): `σ ← min(σ, δ)` while `σ > 0`, and the
        // law acts on the history shifted by `σ` while it stays positive.
        let depth = (-i.d[0]).max0();
        let had = i.offset.gt(zero);
        // Without an offset in either lane, both keep theirs and the history as it is (the
        // selects below would pick exactly that).
        let (offset, [x0, x1, x2]) = if had.any() {
            let offset = had.and(depth.lt(i.offset)).select(depth, i.offset);
            let shifted = offset.gt(zero);
            (offset, i.d.map(|d| shifted.select(d + offset, d)))
        } else {
            (i.offset, i.d)
        };
        // The paper's law (`PaperLaw::force`).
        let delta = (-x0).max0();
        let stored = self.half_kc * delta * delta;
        let extrapolated = Pair::splat(2.0) * x0 - Pair::splat(1.5) * x1 + half * x2;
        let seh = if i.hist[0] >= 3 && i.hist[1] >= 3 {
            extrapolated
        } else {
            let hist = Pair::new(i.hist[0] as f64, i.hist[1] as f64);
            hist.ge(Pair::splat(3.0)).select(extrapolated, x0)
        };
        let push = (self.neg_kc * seh - self.bc * i.c0).max0();
        let f_n = x0.gt(zero).clear(push);
        // The reset integrator (`ResetIntegrator::loaded` while `F_n > 0`, else the shell's
        // reset: stick, `p = 0`, no force).
        let loaded = f_n.gt(zero);
        let p0 = self.mu_k * f_n / self.kr;
        let p_star = i.p + i.ds;
        let slip_up = i.ds.gt(zero).and(p_star.ge(p0));
        let slip_down = i.ds.lt(zero).and(p_star.le(-p0));
        // `p_star.clamp(−p0, p0)`.
        let low = p_star.lt(-p0).select(-p0, p_star);
        let stick_p = low.gt(p0).select(p0, low);
        let f_stick = -(self.one_a_kr * stick_p + self.beta * i.s0);
        let k_used = loaded.select(self.kr, i.k_used);
        // `spring_energy`: `½(1 + a)·Kr·p²` in stick, `½Kr·p²` in slip.
        let slip = loaded.and(slip_up.or(slip_down));
        // Without a loaded slip in either lane, the selects would pick the stick values (or
        // values that `loaded` clears: an unloaded lane's strain is `+0.0`).
        let (held, f_t, k, slip) = if slip.any() {
            let held = slip_up.select(p0, slip_down.select(-p0, stick_p));
            let f_slip = self.neg_kr * held;
            let k = slip.select(k_used, self.one_a * k_used);
            (held, slip.select(f_slip, f_stick), k, slip.bits())
        } else {
            (stick_p, f_stick, self.one_a * k_used, [false; 2])
        };
        let p = loaded.keep(held);
        Outputs {
            offset,
            stored,
            p,
            k_used,
            slip,
            f_n,
            f_t: loaded.keep(f_t),
            s_g: i.s - p,
            energy: stored + half * k * p * p,
        }
    }
}

impl ForcePass<'_> {
    /// The pass without the classical model's external force, on lean slots: two records at a
    /// time when the friction scales its strain limit with the load, else the scalar pass.
    /// Returns what [`run`](Self::run) returns, bit for bit.
    #[inline(never)]
    pub(super) fn run_lean(mut self, store: &mut LeanStore) -> (f64, usize, usize, bool) {
        if store.parts_mut().1.scaling != LoadScaling::Limit {
            return self.run::<_, false>(store);
        }
        let (paper, friction, slots) = store.parts_mut();
        let params = Params::of(paper, friction);
        let (entries, mut t) = self.begin();
        let mut first = None;
        for idx in 0..entries.len() {
            if entries[idx].state != Some(ContactState::Continuous) {
                continue;
            }
            match first.take() {
                None => first = Some(idx),
                Some(a) => self.pair(&params, slots, entries, [a, idx], &mut t),
            }
        }
        if let Some(a) = first {
            // The last record alone: the second lane computes it again, and is dropped.
            self.pair(&params, slots, entries, [a, a], &mut t);
        }
        debug_assert_eq!(self.keys.len(), self.loaded.len());
        (t.stored, t.records, t.breaks, t.rewrite)
    }

    /// The records `idx` (ascending, each with its own slot; both the same for a record alone):
    /// gathers their inputs and slot states, runs the laws, scatters the results, then lists and
    /// applies each record in order (`finish`).
    #[inline(always)]
    fn pair(
        &mut self,
        params: &Params,
        slots: &mut [LeanState],
        entries: &mut [VeContact],
        idx: [usize; 2],
        t: &mut Tally,
    ) {
        let (a, b) = (&entries[idx[0]], &entries[idx[1]]);
        let (sa, sb) = (&slots[a.law as usize], &slots[b.law as usize]);
        let two = |f: fn(&VeContact) -> f64| Pair::new(f(a), f(b));
        let inputs = Inputs {
            d: [0, 1, 2].map(|j| Pair::new(a.d[j], b.d[j])),
            hist: [a.hist, b.hist],
            c0: two(|e| e.c0),
            s: two(|e| e.s),
            ds: two(|e| e.s - e.s_prev),
            s0: two(|e| e.s0),
            offset: Pair::new(sa.offset, sb.offset),
            p: Pair::new(sa.p, sb.p),
            k_used: Pair::new(sa.k_used, sb.k_used),
        };
        let out = params.laws(&inputs);
        self.put(slots, entries, idx[0], &out, 0, t);
        if idx[1] != idx[0] {
            self.put(slots, entries, idx[1], &out, 1, t);
        }
    }

    /// Lane `lane` of `out` into record `idx` and its slot, then the record's `finish`.
    #[inline(always)]
    fn put(
        &mut self,
        slots: &mut [LeanState],
        entries: &mut [VeContact],
        idx: usize,
        out: &Outputs,
        lane: usize,
        t: &mut Tally,
    ) {
        let e = &mut entries[idx];
        t.count(e.law);
        slots[e.law as usize] = LeanState {
            offset: out.offset.lanes()[lane],
            stored: out.stored.lanes()[lane],
            p: out.p.lanes()[lane],
            k_used: out.k_used.lanes()[lane],
            mode: if out.slip[lane] {
                FrictionMode::Slip
            } else {
                FrictionMode::Stick
            },
        };
        e.f_n = out.f_n.lanes()[lane];
        e.f_t = out.f_t.lanes()[lane];
        e.s_g = out.s_g.lanes()[lane];
        t.stored += out.energy.lanes()[lane];
        self.finish::<false>(t, idx, e);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::lean_law::lean_pair;
    use crate::contact::test_pile::shove;
    use crate::contact::Wrench2;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A draw for a length (m) or speed (m/s) near `scale`: a quarter of the time an edge value
    /// (exact zeros of both signs, `±scale`), else uniform in `±2·scale`.
    fn draw(rng: &mut ChaCha8Rng, scale: f64) -> f64 {
        if rng.random_range(0..4) == 0 {
            [0.0, -0.0, scale, -scale][rng.random_range(0..4)]
        } else {
            rng.random_range(-2.0 * scale..2.0 * scale)
        }
    }

    /// One random sample: the records (geometry from a settled pile:20, shoved; states, depths,
    /// histories, speeds and edge coordinates drawn), the slots' states and the struck entries.
    fn sample(
        rng: &mut ChaCha8Rng,
        template: &[VeContact],
        store: &mut LeanStore,
    ) -> (Vec<VeContact>, Vec<usize>) {
        let mut slots: Vec<u32> = (0..template.len() as u32).collect();
        // Slots mostly in record order, sometimes shuffled (the pass counts the breaks).
        if rng.random_range(0..2) == 0 {
            for i in (1..slots.len()).rev() {
                slots.swap(i, rng.random_range(0..=i));
            }
        }
        let mut records = template.to_vec();
        for (e, &slot) in records.iter_mut().zip(&slots) {
            e.state = match rng.random_range(0..10) {
                0 => None,
                1 => Some(ContactState::Colliding),
                _ => Some(ContactState::Continuous),
            };
            e.law = slot;
            e.d = [draw(rng, 1e-3), draw(rng, 1e-3), draw(rng, 1e-3)];
            e.hist = rng.random_range(1..=3);
            e.c0 = draw(rng, 0.05);
            e.s = draw(rng, 0.05);
            // Δs of both signs, exactly zero a third of the time.
            e.s_prev = if rng.random_range(0..3) == 0 {
                e.s
            } else {
                e.s + draw(rng, 2e-4)
            };
            e.s0 = draw(rng, 0.05);
            e.loaded = rng.random();
            (e.f_n, e.f_t, e.s_g) = (f64::NAN, f64::NAN, f64::NAN);
        }
        let (_, friction, states) = store.parts_mut();
        let kr = friction.kr;
        for (st, e) in states.iter_mut().zip(&records) {
            // No offset, an offset above, at or below the depth.
            st.offset = match rng.random_range(0..4) {
                0 => 0.0,
                1 => -e.d[0],
                _ => draw(rng, 1e-3).abs(),
            };
            st.stored = draw(rng, 1.0);
            st.p = draw(rng, 1e-4);
            st.k_used = if rng.random() { kr } else { kr * 0.5 };
            st.mode = if rng.random() {
                FrictionMode::Slip
            } else {
                FrictionMode::Stick
            };
        }
        let struck = (0..records.len())
            .filter(|_| rng.random_range(0..8) == 0)
            .collect();
        (records, struck)
    }

    /// The pass's outputs, compared by their bits (`Debug` prints every bit of a float but a
    /// NaN's payload, and tells `−0.0` from `0.0`).
    fn run(
        wide: bool,
        records: &mut [VeContact],
        store: &mut LeanStore,
        struck: &[usize],
        bodies: &[crate::body::Body],
        rewrite: bool,
        keys: &[crate::collide::VeCandidate],
    ) -> String {
        let mut wrenches = vec![Wrench2::default(); bodies.len()];
        let (mut loaded, mut keys) = (Vec::new(), keys.to_vec());
        let pass = ForcePass {
            entries: records,
            loaded: &mut loaded,
            keys: &mut keys,
            rewrite,
            nonfric: &mut [],
            impact_entries: struck,
            v_damp: 0.02,
            dt: 1e-3,
            bodies,
            needs_ext: false,
            wrenches: &mut wrenches,
        };
        let (stored, n, breaks, rewritten) = if wide {
            pass.run_lean(store)
        } else {
            pass.run::<_, false>(store)
        };
        let states = store.parts_mut().2.to_vec();
        format!(
            "{:?}",
            (stored.to_bits(), n, breaks, rewritten, records, states),
        ) + &format!("{:?}", (loaded, keys, wrenches))
    }

    /// The block pass gives every record's forces, god-object and loaded flag, every slot's state,
    /// the loaded list and its keys, the wrenches, the stored energy and the counts bit for bit as
    /// the scalar pass, over 3 000 seeded random samples of a pile:20's records (about 9 in 10
    /// Continuous, so blocks of every length end the pass): depths of both signs and exact zeros,
    /// histories of 1 to 3 samples, offsets above, at and below the depth, strains inside and
    /// beyond the limit, steps of both signs and none, struck records, keys kept or rewritten.
    /// It also counts that the edge cases occurred.
    #[test]
    fn the_block_pass_matches_the_scalar_pass_bit_for_bit() {
        let mut w = crate::scene::builtin("pile:20", None)
            .unwrap()
            .unwrap()
            .world;
        for k in 0..400 {
            if k == 300 {
                shove(&mut w);
            }
            w.step();
        }
        let (paper, reset) = lean_pair(&w.normal, &w.friction).expect("the paper's pair");
        let template = w.contacts().entries().to_vec();
        assert!(template.len() > 20, "{} records", template.len());
        let mut store = LeanStore::with_capacity(template.len());
        let mut free = Vec::new();
        for e in &template {
            store.put(&mut free, paper, reset, e.s);
        }
        let mut rng = ChaCha8Rng::seed_from_u64(33);
        let (mut unloaded, mut slips, mut sticks, mut shifted, mut short) = (0, 0, 0, 0, 0);
        for trial in 0..3000 {
            let (records, struck) = sample(&mut rng, &template, &mut store);
            let rewrite = rng.random();
            let keys: Vec<_> = records.iter().filter(|e| e.loaded).map(|e| e.key).collect();
            let before = store.clone();
            let (mut a, mut b) = (records.clone(), records.clone());
            let (mut sa, mut sb) = (before.clone(), before.clone());
            let scalar = run(false, &mut a, &mut sa, &struck, &w.bodies, rewrite, &keys);
            let wide = run(true, &mut b, &mut sb, &struck, &w.bodies, rewrite, &keys);
            assert_eq!(scalar, wide, "trial {trial}");
            let (_, _, old) = store.parts_mut();
            let old = old.to_vec();
            let (_, _, new) = sa.parts_mut();
            for (e, r) in a.iter().zip(&records) {
                if e.state != Some(ContactState::Continuous) {
                    continue;
                }
                let (st, was) = (&new[e.law as usize], &old[e.law as usize]);
                unloaded += (e.f_n == 0.0) as usize;
                slips += (st.mode == FrictionMode::Slip) as usize;
                sticks += (e.f_n > 0.0 && st.mode == FrictionMode::Stick) as usize;
                shifted += (st.offset > 0.0 && was.offset > 0.0) as usize;
                short += (r.hist < 3 && e.f_n > 0.0) as usize;
            }
        }
        for (what, n) in [
            ("unloaded", unloaded),
            ("slip", slips),
            ("stick", sticks),
            ("offset", shifted),
            ("short history", short),
        ] {
            assert!(n > 5_000, "{n} {what} records");
        }
    }
}
