//! The chain damper's row set: which loaded contacts are chain contacts (a dynamic body touching
//! two or more others), their greedy graph colours, and the rows in colour order, built from
//! scratch, patched from the last sample's when a few contacts changed, or refreshed in place when
//! none did (steps 2–4 of [`ChainDamping::apply`]).

use super::*;
use crate::buffers::room;

/// The rows the patches may append to a build of `rows` rows before the next build
/// (`patch_rows`' budget: at most an eighth of the rows, at least 16), which a build leaves room
/// for so that a patch allocates nothing.
fn patch_room(rows: usize) -> usize {
    rows / 7 + 20
}

impl ChainDamping {
    /// Grows the row buffers to hold `contacts` loaded contacts as rows (a build and the patches
    /// after it: `place_rows`' room) and the per-body ones to `bodies` bodies, so that a sample
    /// with at most that many allocates nothing. Changes no result: only capacities.
    pub fn reserve(&mut self, contacts: usize, bodies: usize) {
        room(&mut self.partner, bodies);
        room(&mut self.multi, bodies);
        room(&mut self.solver, bodies);
        room(&mut self.star, bodies);
        room(&mut self.used, bodies);
        room(&mut self.dynamic, bodies);
        let n = contacts + patch_room(contacts);
        room(&mut self.sorted, n);
        room(&mut self.src, n);
        room(&mut self.colour_of, n);
        room(&mut self.hole_next, n);
        room(&mut self.colour, n);
        room(&mut self.keys, n);
        room(&mut self.prev_keys, n);
        room(&mut self.prev_lambda, n);
        room(&mut self.place, n);
        room(&mut self.new_place, n);
        room(&mut self.dead, n);
        room(&mut self.born, n);
    }

    /// Steps 2–4 from scratch: the chain contacts of `loaded` (`keys` in key order, `place` the
    /// place of each in `sorted`), each with its colour, as rows in colour order (`sorted`, with
    /// `src` the loaded-list index of each), each warm-started from the last sample's impulse of
    /// the same key within this sample's bound, applied to `solver`. `partners_found`: step 2
    /// ([`find_partners`](Self::find_partners)) already ran for `loaded`. Returns `(g, h)` of
    /// [`scale_warm_start`](Self::scale_warm_start): `g = λ₀ᵀ·J·v*` and `h = λ₀ᵀ·(W + K⁻¹)·λ₀`
    /// (see [`curvature`](Self::curvature); `r = T/τ`).
    ///
    /// Two passes over the contacts, the colours first, so that each row is written once, to its
    /// place in colour order; the sums and the warm impulses go in key order.
    pub(super) fn build_rows(
        &mut self,
        r: f64,
        dt: f64,
        loaded: Loaded<'_>,
        partners_found: bool,
    ) -> (f64, f64) {
        // The last sample's impulses by key.
        std::mem::swap(&mut self.prev_keys, &mut self.keys);
        self.prev_lambda.clear();
        let sorted = &self.sorted;
        self.prev_lambda
            .extend(self.place.iter().map(|&p| sorted[p as usize].lambda));
        if !partners_found {
            self.find_partners(loaded.contacts);
        }
        self.generation = loaded.generation;
        self.loaded_len = loaded.contacts.len();
        // 3–4. The colours, then the rows in their places. The colouring first takes every
        //      chain contact's effective mass as finite and positive, as it nearly always is; if
        //      placing the rows meets one that is not, both run again with the check, so that
        //      such a contact takes no colour.
        self.colour_rows(r, dt, loaded.contacts, false);
        let (g, k) = match self.place_rows(r, dt, loaded, true) {
            Some(gk) => gk,
            None => {
                self.colour_rows(r, dt, loaded.contacts, true);
                let gk = self.place_rows(r, dt, loaded, false);
                debug_assert!(gk.is_some(), "a checked colouring places every row");
                gk.unwrap_or_default()
            }
        };
        (g, self.curvature(k / r))
    }

    /// Step 2: which dynamic bodies touch two or more other bodies through the contacts of
    /// `loaded` (`multi`; `partner` is scratch).
    pub(super) fn find_partners(&mut self, loaded: &[LoadedContact]) {
        let dynamic = &self.dynamic;
        self.partner.fill(NONE);
        self.multi.fill(false);
        for e in loaded {
            for (x, y) in [(e.body_a, e.body_b), (e.body_b, e.body_a)] {
                if !dynamic[x as usize] {
                    continue;
                }
                let p = &mut self.partner[x as usize];
                if *p == NONE {
                    *p = y;
                } else if *p != y {
                    self.multi[x as usize] = true;
                }
            }
        }
    }

    /// Step 3 of [`build_rows`](Self::build_rows): the colour of each chain contact of `loaded`
    /// in key order (`colour`, and `per_colour` the rows of each), greedy: the lowest colour
    /// neither body has yet (fixed bodies take any number). With `check`, a contact whose
    /// effective mass is not finite and positive is no row: it takes no colour and sets
    /// `dropped`.
    pub(super) fn colour_rows(&mut self, r: f64, dt: f64, loaded: &[LoadedContact], check: bool) {
        self.colour.clear();
        self.per_colour.fill(0);
        self.used.fill(0);
        self.dropped = false;
        let (dynamic, multi, used) = (&self.dynamic, &self.multi, &mut self.used);
        for e in loaded {
            let (a, b) = (e.body_a as usize, e.body_b as usize);
            if !is_chain(multi, a, b) {
                continue;
            }
            if check && !Row::build(e, a as u32, b as u32, &self.star, r, dt, 0.0).valid() {
                self.dropped = true;
                continue;
            }
            let c = take_colour(dynamic, used, a, b);
            self.colour.push(c);
            self.per_colour[c as usize] += 1;
        }
    }

    /// Step 4 of [`build_rows`](Self::build_rows): the rows, in key order, written straight to
    /// their places in colour order (`per_colour` becomes each colour's next position: a stable
    /// counting sort), each warm-started from the last sample's impulse of the same key (a merge
    /// of two key-sorted lists) within this sample's bound, and that impulse applied to
    /// `solver`. Returns `g = λ₀ᵀ·J·v*` and `Σ λ₀ᵢ²·wᵢ`; `None` if `abort_on_invalid` and a
    /// chain contact's effective mass is not finite and positive (the colours did not leave it
    /// out), else such a contact is skipped.
    pub(super) fn place_rows(
        &mut self,
        r: f64,
        dt: f64,
        loaded: Loaded<'_>,
        abort_on_invalid: bool,
    ) -> Option<(f64, f64)> {
        let mut at = 0u32;
        for k in self.per_colour.iter_mut() {
            let count = *k;
            *k = at;
            at += count;
        }
        let n = self.colour.len();
        self.sorted.clear();
        self.sorted.resize(n, Row::NONE);
        self.src.clear();
        self.src.resize(n, 0);
        self.colour_of.clear();
        self.colour_of.resize(n, 0);
        self.hole_next.clear();
        self.hole_next.resize(n, NONE);
        self.hole_head.fill(NONE);
        (self.holes, self.appended) = (0, 0);
        self.keys.clear();
        self.place.clear();
        // Room for the rows the patches may append before the next build (`patch_room`).
        let extra = patch_room(n);
        self.sorted.reserve(extra);
        self.src.reserve(extra);
        self.colour_of.reserve(extra);
        self.hole_next.reserve(extra);
        for keys in [&mut self.keys, &mut self.prev_keys] {
            keys.reserve(n + extra);
        }
        self.place.reserve(n + extra);
        self.new_place.reserve(n + extra);
        self.dead.clear();
        self.dead.reserve(extra);
        self.born.clear();
        self.born.reserve(extra);
        // A refresh that gave up may have applied impulses: start again from `v*`.
        self.reset_solver();
        let (star, multi) = (&self.star, &self.multi);
        let (mut g, mut k) = (0.0, 0.0);
        let mut j = 0;
        for (i, (e, &key)) in loaded.contacts.iter().zip(loaded.keys).enumerate() {
            let (a, b) = (e.body_a as usize, e.body_b as usize);
            if !is_chain(multi, a, b) {
                continue;
            }
            while j < self.prev_keys.len() && self.prev_keys[j] < key {
                j += 1;
            }
            let prev = if j < self.prev_keys.len() && self.prev_keys[j] == key {
                self.prev_lambda[j]
            } else {
                0.0
            };
            let row = Row::build(e, a as u32, b as u32, star, r, dt, prev);
            if !row.valid() {
                if abort_on_invalid {
                    return None;
                }
                continue;
            }
            // g = λ₀ᵀ·J·v* (see `scale_warm_start`), and the warm impulse applied.
            if row.lambda != 0.0 {
                g += row.lambda * row.v_rel_star(star);
                row.apply(row.lambda, &mut self.solver);
            }
            k += row.lambda * row.lambda * row.w;
            let index = self.keys.len();
            let colour = self.colour[index];
            let p = &mut self.per_colour[colour as usize];
            self.sorted[*p as usize] = row;
            self.src[*p as usize] = i as u32;
            self.colour_of[*p as usize] = colour;
            self.place.push(*p);
            *p += 1;
            self.keys.push(key);
        }
        Some((g, k))
    }

    /// Steps 3–4 when a few loaded contacts changed (after step 2,
    /// [`find_partners`](Self::find_partners), for `loaded`): a merge of the last sample's keys
    /// with the new ones. A row whose contact is still a chain contact keeps its place and its
    /// colour (its loaded index is updated). A row whose contact is gone, or no longer a chain
    /// contact, becomes a hole: a no-op row (zero normal, lever arms, mass and bound, so a sweep
    /// leaves every velocity as it was) that gives back its colour. A new chain contact takes
    /// the lowest colour neither body has, and a hole of that colour or else a new place after
    /// the colour buckets. The caller then refreshes the rows
    /// ([`refresh_rows`](Self::refresh_rows)): the new ones start from a zero impulse, as a
    /// build would start them, and every other row from its own last impulse, so the rows are a
    /// build's, in another order.
    ///
    /// Returns `false`, having changed nothing a build reads, when the holes and appended rows
    /// since the last build could exceed an eighth of the rows (at least 16): the sweeps would
    /// then lose the colour order that lets the processor overlap their updates, so the caller
    /// builds the rows from scratch.
    pub(super) fn patch_rows(&mut self, loaded: Loaded<'_>) -> bool {
        self.new_place.clear();
        self.dead.clear();
        self.born.clear();
        // The new keys go to `prev_keys`, which a build overwrites.
        self.prev_keys.clear();
        let (old_keys, old_place) = (&self.keys[..], &self.place[..]);
        let (new_keys, new_place) = (&mut self.prev_keys, &mut self.new_place);
        let (src, dead, born, multi) = (&mut self.src, &mut self.dead, &mut self.born, &self.multi);
        // The budget below cannot exceed this one (the new rows are at most the loaded
        // contacts), so the merge gives up as soon as the changes pass it.
        let (spent, limit) = (
            self.holes + self.appended,
            (loaded.contacts.len() / 8).max(16),
        );
        let mut j = 0;
        for (i, (e, &key)) in loaded.contacts.iter().zip(loaded.keys).enumerate() {
            // Most keys are the next old one; otherwise old keys before this one died.
            let mut old = NONE;
            if old_keys.get(j) == Some(&key) {
                old = old_place[j];
                j += 1;
            } else {
                while j < old_keys.len() && old_keys[j] < key {
                    dead.push(old_place[j]);
                    j += 1;
                }
                if spent + dead.len() + born.len() > limit {
                    return false;
                }
                if old_keys.get(j) == Some(&key) {
                    old = old_place[j];
                    j += 1;
                }
            }
            if is_chain(multi, e.body_a as usize, e.body_b as usize) {
                if old == NONE {
                    born.push((i as u32, new_place.len() as u32));
                } else {
                    // A build rewrites every `src`, so this write is safe if the patch gives up.
                    src[old as usize] = i as u32;
                }
                new_place.push(old);
                new_keys.push(key);
            } else if old != NONE {
                dead.push(old);
            }
        }
        dead.extend_from_slice(&old_place[j..]);
        let dynamic = &self.dynamic;
        let budget = (self.new_place.len() / 8).max(16);
        if self.holes + self.appended + self.dead.len() + self.born.len() > budget {
            return false;
        }
        let used = &mut self.used;
        for &p in &self.dead {
            let p = p as usize;
            let (row, c) = (self.sorted[p], self.colour_of[p]);
            if c < COLOURS {
                for x in [row.a as usize, row.b as usize] {
                    if dynamic[x] {
                        used[x] &= !(1u64 << c);
                    }
                }
            }
            self.sorted[p] = Row::NONE;
            self.src[p] = NONE;
            self.hole_next[p] = self.hole_head[c as usize];
            self.hole_head[c as usize] = p as u32;
            self.holes += 1;
        }
        for &(i, k) in &self.born {
            let e = &loaded.contacts[i as usize];
            let (a, b) = (e.body_a as usize, e.body_b as usize);
            let c = take_colour(dynamic, used, a, b);
            let head = self.hole_head[c as usize];
            let p = if head != NONE {
                self.hole_head[c as usize] = self.hole_next[head as usize];
                self.hole_next[head as usize] = NONE;
                self.holes -= 1;
                head as usize
            } else {
                self.sorted.push(Row::NONE);
                self.src.push(NONE);
                self.colour_of.push(c);
                self.hole_next.push(NONE);
                self.appended += 1;
                self.sorted.len() - 1
            };
            // The refresh builds the row from the contact, from a zero impulse.
            self.sorted[p] = Row {
                a: a as u32,
                b: b as u32,
                ..Row::NONE
            };
            self.src[p] = i;
            self.colour_of[p] = c;
            self.new_place[k as usize] = p as u32;
        }
        self.last_patch_size = (self.dead.len(), self.born.len());
        std::mem::swap(&mut self.keys, &mut self.prev_keys);
        std::mem::swap(&mut self.place, &mut self.new_place);
        self.generation = loaded.generation;
        self.loaded_len = loaded.contacts.len();
        true
    }

    /// Steps 2–4 when `loaded` holds the same contacts as the last sample (same keys in the same
    /// order, same dynamic bodies): the chain contacts, their colours and order are then those of
    /// the last sample, so its rows (colour order) are refreshed in place from the new
    /// geometry, each warm-started from its own last impulse within this sample's bound — what
    /// [`build_rows`](Self::build_rows) would build, without the key merge and the colouring.
    /// Returns `(g, h)` of [`scale_warm_start`](Self::scale_warm_start), or `None` (the caller
    /// builds from scratch) if a row's effective mass is no longer finite.
    pub(super) fn refresh_rows(
        &mut self,
        r: f64,
        dt: f64,
        loaded: &[LoadedContact],
    ) -> Option<(f64, f64)> {
        // `solver` holds `v*` (step 1): nothing has applied an impulse to it yet. Slices: their
        // lengths and addresses stay in registers over the loop, and `solver` cut to `star`'s
        // length (both are the bodies') lets the compiler drop its index checks after `star`'s.
        let (rows, src) = (&mut self.sorted[..], &self.src[..]);
        let star = &self.star[..];
        let solver = &mut self.solver[..star.len()];
        let (mut g, mut k) = (0.0, 0.0);
        // Checked once at the end (no branch per row): if a row failed, the caller rebuilds from
        // scratch, from `star` and the rows' impulses; every row keeps `max(λ, lo)` or 0 here,
        // which `build_rows` maps the same way.
        let mut valid = true;
        for (row, &i) in rows.iter_mut().zip(src) {
            if i == NONE {
                continue; // a hole left by a patch: a no-op row
            }
            *row = Row::build(&loaded[i as usize], row.a, row.b, star, r, dt, row.lambda);
            valid &= row.valid();
            if row.lambda != 0.0 {
                g += row.lambda * row.v_rel_star(star);
                k += row.lambda * row.lambda * row.w;
                row.apply(row.lambda, solver);
            }
        }
        valid.then(|| (g, self.curvature(k / r)))
    }
}

/// Whether the contact between bodies `a` and `b` is a chain contact: one of them is dynamic and
/// touches two or more other bodies (`multi`, which
/// [`find_partners`](ChainDamping::find_partners) sets for dynamic bodies only). The colouring,
/// the placing of the rows and a patch must agree on it contact by contact, so all ask here.
#[inline(always)]
fn is_chain(multi: &[bool], a: usize, b: usize) -> bool {
    multi[a] || multi[b]
}

/// The greedy colour of a row between bodies `a` and `b`: the lowest colour neither dynamic body
/// has yet (`used`, one bit per colour; fixed bodies take any number), now taken by both; or the
/// overflow colour [`COLOURS`] when none is free.
#[inline(always)]
fn take_colour(dynamic: &[bool], used: &mut [u64], a: usize, b: usize) -> u32 {
    let (dyn_a, dyn_b) = (dynamic[a], dynamic[b]);
    let taken = if dyn_a { used[a] } else { 0 } | if dyn_b { used[b] } else { 0 };
    let c = (!taken).trailing_zeros().min(COLOURS);
    if c < COLOURS {
        used[a] |= (dyn_a as u64) << c;
        used[b] |= (dyn_b as u64) << c;
    }
    c
}
