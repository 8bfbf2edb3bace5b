//! The force pass in blocks for lean law slots (issue 42 item 1, after Box2D's wide contact
//! solver): the paper's pair of laws ([`PaperLaw`] with its impact surface offset, and the
//! [`ResetIntegrator`] scaling its strain limit) run on [`W`] Continuous records at once, their
//! inputs and slot states gathered into small structure-of-arrays lanes ([`Lanes`]), the laws'
//! branches written as selects so that LLVM may vectorise the lanes (SSE2 `f64x2`), and the
//! results scattered back; the loaded list and the wrenches then follow record by record, in
//! record order, as in the scalar pass.
//!
//! Every lane runs the same IEEE operations in the same order as the scalar laws
//! (`ContactNormal::force`, `PaperLaw::force`, `ResetIntegrator::loaded`, its shell's unloaded
//! reset and `spring_energy`), so the forces, states and energies are bit for bit the scalar
//! pass's (pinned by the seeded test below). The constants the laws compute on every call
//! (`0.5·Kc`, `−Kc`, `1 + a`, `(1 + a)·Kr`) are computed once: the same operations on the same
//! values.

use super::{ForcePass, Tally};
use crate::contact::lean_law::{LeanState, LeanStore};
use crate::contact::record::{ContactState, VeContact};
use crate::laws::friction::{FrictionMode, LoadScaling, ResetIntegrator};
use crate::laws::normal::PaperLaw;

/// Records in a block.
const W: usize = 4;

/// The shared parameters of the lean slots, with the constants the laws derive from them.
#[derive(Clone, Copy, Debug)]
struct Params {
    /// `0.5·Kc` (N/m), `−Kc` (N/m) and `Bc` (N·s/m) of the paper's law.
    half_kc: f64,
    neg_kc: f64,
    bc: f64,
    /// `Kr` (N/m), `−Kr`, `μk`, `β` (N·s/m), `1 + a = 1 + (μs/μk − 1)` and `(1 + a)·Kr` (N/m).
    kr: f64,
    neg_kr: f64,
    mu_k: f64,
    beta: f64,
    one_a: f64,
    one_a_kr: f64,
}

/// A block of records: the laws' inputs, the slots' states (read and written) and the results.
#[derive(Clone, Copy, Debug, Default)]
struct Lanes {
    /// Signed distance history (m), and whether it has three samples (the SEH estimate).
    d0: [f64; W],
    d1: [f64; W],
    d2: [f64; W],
    seh: [bool; W],
    /// `C0` (m/s), `s` (m), `Δs = s − s_prev` (m) and `S0` (m/s).
    c0: [f64; W],
    s: [f64; W],
    ds: [f64; W],
    s0: [f64; W],
    /// Slot state: surface offset `σ` (m), strain `p` (m), stiffness of the last sample (N/m),
    /// slip (else stick).
    offset: [f64; W],
    p: [f64; W],
    k_used: [f64; W],
    slip: [bool; W],
    /// Results: the paper law's stored energy (J), `F_n` (N), `F_t` (N), the god-object `s_g`
    /// (m) and the record's stored energy (J, normal plus friction).
    stored: [f64; W],
    f_n: [f64; W],
    f_t: [f64; W],
    s_g: [f64; W],
    energy: [f64; W],
}

impl Params {
    /// The constants of `paper` and `friction` (whose load scaling is [`LoadScaling::Limit`]).
    fn of(paper: &PaperLaw, friction: &ResetIntegrator) -> Self {
        let one_a = 1.0 + friction.a();
        Self {
            half_kc: 0.5 * paper.kc,
            neg_kc: -paper.kc,
            bc: paper.bc,
            kr: friction.kr,
            neg_kr: -friction.kr,
            mu_k: friction.mu_k,
            beta: friction.beta,
            one_a,
            one_a_kr: one_a * friction.kr,
        }
    }

    /// Runs the laws on every lane of `l` (the lanes past a short block's end too, on stale
    /// values, which nobody reads).
    #[inline(always)]
    fn lanes(&self, l: &mut Lanes) {
        for i in 0..W {
            // The surface offset (`ContactNormal::force`): `σ ← min(σ, δ)` while `σ > 0`, and
            // the law acts on the history shifted by `σ` while it stays positive.
            let depth = (-l.d0[i]).max(0.0);
            let offset = if l.offset[i] > 0.0 && depth < l.offset[i] {
                depth
            } else {
                l.offset[i]
            };
            let shifted = offset > 0.0;
            let x0 = if shifted { l.d0[i] + offset } else { l.d0[i] };
            let x1 = if shifted { l.d1[i] + offset } else { l.d1[i] };
            let x2 = if shifted { l.d2[i] + offset } else { l.d2[i] };
            // The paper's law (`PaperLaw::force`).
            let delta = (-x0).max(0.0);
            let stored = self.half_kc * delta * delta;
            let seh = if l.seh[i] {
                2.0 * x0 - 1.5 * x1 + 0.5 * x2
            } else {
                x0
            };
            let push = (self.neg_kc * seh - self.bc * l.c0[i]).max(0.0);
            let f_n = if x0 > 0.0 { 0.0 } else { push };
            // The reset integrator (`ResetIntegrator::loaded` while `F_n > 0`, else the shell's
            // reset: stick, `p = 0`, no force).
            let loaded = f_n > 0.0;
            let p0 = self.mu_k * f_n / self.kr;
            let (ds, p_star) = (l.ds[i], l.p[i] + l.ds[i]);
            let slip_up = ds > 0.0 && p_star >= p0;
            let slip_down = ds < 0.0 && p_star <= -p0;
            // `p_star.clamp(−p0, p0)`.
            let low = if p_star < -p0 { -p0 } else { p_star };
            let stick_p = if low > p0 { p0 } else { low };
            let slip = slip_up || slip_down;
            let held = if slip_up {
                p0
            } else if slip_down {
                -p0
            } else {
                stick_p
            };
            let f_slip = self.neg_kr * held;
            let f_stick = -(self.one_a_kr * stick_p + self.beta * l.s0[i]);
            let f_t = if slip { f_slip } else { f_stick };
            let p = if loaded { held } else { 0.0 };
            let k_used = if loaded { self.kr } else { l.k_used[i] };
            let slip = loaded && slip;
            // `spring_energy`: `½(1 + a)·Kr·p²` in stick, `½Kr·p²` in slip.
            let k = if slip { k_used } else { self.one_a * k_used };
            l.offset[i] = offset;
            l.p[i] = p;
            l.k_used[i] = k_used;
            l.slip[i] = slip;
            l.stored[i] = stored;
            l.f_n[i] = f_n;
            l.f_t[i] = if loaded { f_t } else { 0.0 };
            l.s_g[i] = l.s[i] - p;
            l.energy[i] = stored + 0.5 * k * p * p;
        }
    }
}

impl ForcePass<'_> {
    /// The pass without the classical model's external force, on lean slots: in blocks of `W`
    /// records when the friction scales its strain limit with the load, else the scalar pass.
    /// Returns what [`run`](Self::run) returns, bit for bit.
    #[inline(never)]
    pub(super) fn run_lean(mut self, store: &mut LeanStore) -> (f64, usize, usize, bool) {
        if store.parts_mut().1.scaling != LoadScaling::Limit {
            return self.run::<_, false>(store);
        }
        let (paper, friction, slots) = store.parts_mut();
        let params = Params::of(paper, friction);
        let (entries, mut t) = self.begin();
        let mut lanes = Lanes::default();
        let (mut block, mut n) = ([0usize; W], 0);
        for idx in 0..entries.len() {
            if entries[idx].state != Some(ContactState::Continuous) {
                continue;
            }
            block[n] = idx;
            n += 1;
            if n == W {
                self.block(&params, &mut lanes, slots, entries, &block, &mut t);
                n = 0;
            }
        }
        self.block(&params, &mut lanes, slots, entries, &block[..n], &mut t);
        debug_assert_eq!(self.keys.len(), self.loaded.len());
        (t.stored, t.records, t.breaks, t.rewrite)
    }

    /// The records `block` (ascending, at most `W`, each with its own slot): gathers their inputs
    /// and slot states into `lanes`, runs the laws, scatters the results, then lists and applies
    /// each record in order (`finish`).
    #[inline(always)]
    fn block(
        &mut self,
        params: &Params,
        lanes: &mut Lanes,
        slots: &mut [LeanState],
        entries: &mut [VeContact],
        block: &[usize],
        t: &mut Tally,
    ) {
        for (i, &idx) in block.iter().enumerate().take(W) {
            let e = &entries[idx];
            let st = &slots[e.law as usize];
            [lanes.d0[i], lanes.d1[i], lanes.d2[i]] = e.d;
            lanes.seh[i] = e.hist >= 3;
            lanes.c0[i] = e.c0;
            lanes.s[i] = e.s;
            lanes.ds[i] = e.s - e.s_prev;
            lanes.s0[i] = e.s0;
            lanes.offset[i] = st.offset;
            lanes.p[i] = st.p;
            lanes.k_used[i] = st.k_used;
            lanes.slip[i] = st.mode == FrictionMode::Slip;
        }
        params.lanes(lanes);
        for (i, &idx) in block.iter().enumerate().take(W) {
            let e = &mut entries[idx];
            t.count(e.law);
            slots[e.law as usize] = LeanState {
                offset: lanes.offset[i],
                stored: lanes.stored[i],
                p: lanes.p[i],
                k_used: lanes.k_used[i],
                mode: if lanes.slip[i] {
                    FrictionMode::Slip
                } else {
                    FrictionMode::Stick
                },
            };
            e.f_n = lanes.f_n[i];
            e.f_t = lanes.f_t[i];
            e.s_g = lanes.s_g[i];
            t.stored += lanes.energy[i];
            self.finish::<false>(t, idx, e);
        }
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
