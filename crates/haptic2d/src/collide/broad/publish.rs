//! Publishing an update: the fresh pairs sorted and merged with the published ones, or patched
//! in place ([`BroadPhase::publish`]).
//!
//! When every pair an update tests is one of the published update's (every lookup found its
//! entry, and the counts agree), rebuilding the published arrays would change only the entries
//! that needed GJK. The update then writes just those entries over the published ones and
//! rebuilds the set only if one of them changed side of `δ_prox` (`BroadStats::in_place`). A
//! settled pile:1000 takes this path in 143 of 150 updates.
//!
//! Otherwise the published pairs the sweep met again are already in pair order: the few pairs
//! the published update did not have are sorted, and the two lists merged in one pass over the
//! published arrays (a pile that is still moving; pile:1000 between 1 and 2 s, 37 of 100
//! updates).

use super::*;

impl BroadPhase {
    /// `order` = `fresh` sorted by pair: a counting sort on the first collider, then an insertion
    /// sort of each collider's few pairs on the second (pairs are unique, so the order is the one
    /// any sort gives).
    pub(super) fn sort_fresh(&mut self) {
        let n = self.snapshot.colliders.len();
        self.bucket.clear();
        self.bucket.resize(n + 1, 0);
        for &k in &self.fresh {
            self.bucket[self.tested[k as usize].pair.0 as usize + 1] += 1;
        }
        for i in 0..n {
            self.bucket[i + 1] += self.bucket[i];
        }
        self.order.clear();
        self.order.resize(self.fresh.len(), 0);
        for &k in &self.fresh {
            let at = &mut self.bucket[self.tested[k as usize].pair.0 as usize];
            self.order[*at as usize] = k;
            *at += 1;
        }
        // `bucket[a]` is now the end of collider a's pairs; sort each run on the second collider.
        let mut from = 0;
        for a in 0..n {
            let to = self.bucket[a] as usize;
            for i in from + 1..to {
                let k = self.order[i];
                let key = self.tested[k as usize].pair.1;
                let mut j = i;
                while j > from && self.tested[self.order[j - 1] as usize].pair.1 > key {
                    self.order[j] = self.order[j - 1];
                    j -= 1;
                }
                self.order[j] = k;
            }
            from = to;
        }
    }

    /// Writes the sorted result of the update in progress into `ready` (the set, the pairs'
    /// caches and distances, where each first collider's pairs start, the counters), so that
    /// publishing is a swap.
    ///
    /// The result is the published pairs the sweep met again (their published entries where the
    /// distance was reused, their new GJK results otherwise) and the fresh pairs: two lists in
    /// pair order, merged. The published arrays are read in order, so a pile whose pairs change
    /// by a few per update costs one sequential pass, not a sort of every pair (issue 17: the
    /// sort made the last share of such an update 1.5 times a sample's median at pile:1000).
    pub(super) fn fill_ready(&mut self) {
        // Where each published pair comes from (the published arrays have not changed since the
        // sweep looked them up: only `publish` writes them).
        self.source.clear();
        self.source.resize(self.cache_pairs.len(), DROPPED);
        for &k in &self.kept {
            self.source[k as usize] = KEPT;
        }
        for &(k, t) in &self.patches {
            self.source[k as usize] = t;
        }
        let r = &mut self.ready;
        r.clear();
        r.reserve(self.tested.len() + self.kept.len());
        let mut fresh = self
            .order
            .iter()
            .map(|&t| &self.tested[t as usize])
            .peekable();
        for (k, &source) in self.source.iter().enumerate() {
            let entry = match source {
                DROPPED => continue,
                KEPT => Tested {
                    pair: self.cache_pairs[k],
                    cache: self.caches[k],
                    distance: self.distances[k],
                    odo_ref: self.odo_refs[k],
                },
                t => self.tested[t as usize],
            };
            while let Some(f) = fresh.next_if(|f| f.pair < entry.pair) {
                r.push(f, self.delta_prox);
            }
            r.push(&entry, self.delta_prox);
        }
        for f in fresh {
            r.push(f, self.delta_prox);
        }
        r.finish(self.snapshot.colliders.len());
        r.stats = BroadStats {
            aabb_pairs: r.pairs.len(),
            proximate_pairs: r.set.len(),
            gjk_iterations: self.gjk_iterations,
            reused_distances: self.reused_distances,
            in_place: false,
        };
    }

    /// Writes the GJK results of an update in place (`patches`) into the published arrays; the
    /// proximity set is rebuilt from the distances when a patched pair changed side of `δ_prox`.
    pub(super) fn patch(&mut self) {
        let mut crossed = false;
        for &(k, t) in &self.patches {
            let (k, t) = (k as usize, &self.tested[t as usize]);
            crossed |= (self.distances[k] < self.delta_prox) != (t.distance < self.delta_prox);
            self.caches[k] = t.cache;
            self.distances[k] = t.distance;
            self.odo_refs[k] = t.odo_ref;
        }
        if crossed {
            self.set.clear();
            for (&p, &d) in self.cache_pairs.iter().zip(&self.distances) {
                if d < self.delta_prox {
                    self.set.push(p);
                }
            }
        }
    }

    /// Finishes the update in progress (sweeps what is left) and writes its proximity set into
    /// `out` (cleared first; sorted, `a < b`, GJK distance `< δ_prox`); the pairs' caches become
    /// the warm starts of the next update. Leaves `out` untouched when no update is in progress.
    pub fn publish(&mut self, out: &mut Vec<(u32, u32)>) {
        if self.next.is_none() {
            return;
        }
        self.advance(1);
        self.next = None;
        self.certificate = self.progress;
        if self.in_place {
            self.patch();
            if *out != self.set {
                out.clone_from(&self.set);
            }
            self.stats = BroadStats {
                aabb_pairs: self.tested.len() + self.kept.len(),
                proximate_pairs: self.set.len(),
                gjk_iterations: self.gjk_iterations,
                reused_distances: self.reused_distances,
                in_place: true,
            };
            return;
        }
        // Everything was written by the last `advance`: publishing swaps the buffers.
        let r = &mut self.ready;
        std::mem::swap(out, &mut r.set);
        std::mem::swap(&mut self.cache_pairs, &mut r.pairs);
        std::mem::swap(&mut self.caches, &mut r.caches);
        std::mem::swap(&mut self.distances, &mut r.distances);
        std::mem::swap(&mut self.odo_refs, &mut r.odo_refs);
        std::mem::swap(&mut self.cache_start, &mut r.start);
        // An update in place has these pairs, so its set has at most as many: with this room in
        // the copy and in both buffers that take turns as the caller's, it allocates nothing.
        let most = self.cache_pairs.len();
        self.set.clone_from(out);
        room(&mut self.set, most);
        room(&mut r.set, most);
        self.stats = r.stats;
    }
}
