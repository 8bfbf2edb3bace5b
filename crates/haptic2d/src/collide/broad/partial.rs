//! The partial update (issue 42): only the pairs of the bodies that moved past the margin are
//! computed again, at the current poses, and written into the set in use
//! ([`BroadPhase::update_bodies`]).
//!
//! # Why a pair left out stays farther than `δ_c` apart
//!
//! Each body `B` has a global pose `g_B`: the pose its pairs were last decided for (the snapshot
//! of the update that published the set in use, or the pose at its last partial update). Let
//! `D_B(x→y) = |Δp| + |Δθ|·ρ_B`, a bound on how far any point of `B` moves between poses `x`
//! and `y`, and `L = (δ_prox − δ_c)/2`. The world calls a partial update for the bodies `F`
//! that may have moved more than `L` since `g_F` (`world/proximity.rs`), passing
//! `D_B = D_B(g_B→now)` for every other body. The update decides each pair of a moved body
//! `F` again, at the current poses: pair `(F, B)` is in the set when its distance now is
//! `< δ_prox + D_B` (`< δ_prox` when `B` moved past too: its global pose becomes the pose now as
//! well, `D_B = 0`), and then `g_F := now` (the world does that). Pairs of two other bodies are
//! kept as they are.
//!
//! A pair `(F, B)` left out had `dist_now ≥ δ_prox + D_B`. At a later instant, every point of
//! each body has moved at most its `D(now→later)`, so
//! `dist ≥ dist_now − D_F(now→later) − D_B(now→later)`. With `g_F = now`,
//! `D_F(now→later) = D_F(g_F→later)`; for `B`, the triangle inequality on each point's
//! displacement gives `D_B(now→later) ≤ D_B(g_B→now) + D_B(g_B→later) = D_B + D_B(g_B→later)`.
//! While neither body triggers again (`D_F(g_F→later) ≤ L`, `D_B(g_B→later) ≤ L`):
//! `dist ≥ δ_prox + D_B − L − D_B − L = δ_c`, so the pair has no VE candidate. A pair of two
//! bodies that both moved past has `D = 0` on both sides, the same argument with `g = now` for
//! both. A pair of two other bodies keeps the argument of the update that last decided it (a
//! whole update at the poses `g`, or the partial update of one of them, as here). The argument
//! holds for any `g_B` the pair's last decision used, however old, so a spread update in progress
//! goes on: when it publishes, its set replaces the whole set and every `g` becomes its snapshot
//! pose, and a body that has moved past since triggers a partial update again.
//!
//! # The work
//!
//! Each collider of a moved body is tested against the dynamic colliders whose boxes start in an
//! x window around its own (the boxes sorted by their left side, from the last partial update's
//! order; the window is wide by the largest reach and the widest dynamic box) and against every
//! fixed collider (few, and wide: a floor). The gap between two world boxes (a lower bound on the
//! distance, in x or in y) rejects most; the rest get GJK at the current world vertices,
//! warm-started from the published update's cache of the pair when it has one (read only: the
//! published arrays stay those of the update that made them, which the spread update in
//! progress, the skip check and the in-place patch rely on). The pairs found
//! are sorted and merged with the kept ones, so the set stays sorted (`(a, b)`, `a < b`, the
//! order the local stage merges by). Per update: one pass over the colliders (their boxes, a
//! nearly linear sort) and over the set, plus, per moved collider, a binary search and its
//! window.

use super::*;

impl BroadPhase {
    /// The partial update: the pairs of every collider whose body has `moved[body]` are decided
    /// again for the current world features of `colliders`, and written into `set` (the set in
    /// use: sorted, `(a, b)` with `a < b`); the other pairs of `set` are kept.
    ///
    /// A pair of a moved body with a collider of body `B` is in the set when its GJK distance is
    /// `< δ_prox + motion[B]` (`motion[B]` (m): how far any point of `B` may have moved since the
    /// poses its pairs were decided for; not read when `B` moved too, which counts as 0). A NaN
    /// distance or motion keeps the pair. The published update's state (its pairs, caches and
    /// certificate) is not changed. `moved` and `motion` are per body. Returns the number of
    /// GJK distances computed. No allocation once the buffers have grown to the scene's size.
    pub fn update_bodies(
        &mut self,
        colliders: &[Collider],
        moved: &[bool],
        motion: &[f64],
        set: &mut Vec<(u32, u32)>,
    ) -> usize {
        // The largest reach of a pair, and the widest box: the x window of a moved collider's
        // partners in `near`. A NaN motion opens it to every collider.
        let most = motion
            .iter()
            .zip(moved)
            .filter(|(_, &m)| !m)
            .fold(
                0.0f64,
                |w, (&d, _)| if d.is_nan() { f64::INFINITY } else { w.max(d) },
            );
        let reach_max = self.delta_prox + most;
        let widest = self.sort_near(colliders);
        let mut gjk_runs = 0;
        let mut found = std::mem::take(&mut self.found);
        found.clear();
        for (i, ci) in colliders.iter().enumerate() {
            if !moved[ci.body] {
                continue;
            }
            let p = ci.aabb;
            // A partner within reach starts before `p.max.x + reach` and ends after
            // `p.min.x − reach`, so it starts after `p.min.x − reach − widest`; the fixed
            // colliders (a floor, walls: wide boxes, few) are all looked at.
            let lo = p.min.x - reach_max - widest - REUSE_GUARD;
            let hi = p.max.x + reach_max;
            let from = self.near.partition_point(|e| e.min_x < lo);
            let window = self.near[from..].iter().take_while(|e| e.min_x <= hi);
            for e in self.fixed_near.iter().chain(window) {
                let j = e.index as usize;
                let body = (e.body >> 1) as usize;
                let both_moved = moved[body];
                // One body, both fixed, or a pair of two moved bodies met from its other side.
                if body == ci.body || !(ci.dynamic || e.body & 1 == 1) || (both_moved && j < i) {
                    continue;
                }
                let reach = self.delta_prox + if both_moved { 0.0 } else { motion[body] };
                let gap = (e.min_x - p.max.x)
                    .max(p.min.x - e.max_x)
                    .max(e.min_y - p.max.y)
                    .max(p.min.y - e.max_y);
                if gap >= reach {
                    continue; // at least `gap` apart
                }
                let (a, b) = (i.min(j) as u32, i.max(j) as u32);
                let mut cache = self
                    .cached(a, b)
                    .map(|k| self.caches[k])
                    .unwrap_or_default();
                let g = gjk_distance(
                    colliders[a as usize].world_vertices(),
                    colliders[b as usize].world_vertices(),
                    &mut cache,
                );
                gjk_runs += 1;
                if g.distance < reach || g.distance.is_nan() || reach.is_nan() {
                    found.push((a, b));
                }
            }
        }
        self.found = found;
        self.found.sort_unstable();
        // The kept pairs (sorted) merged with the found ones (sorted, none of them kept).
        let moved_pair = |&(a, b): &(u32, u32)| {
            moved[colliders[a as usize].body] || moved[colliders[b as usize].body]
        };
        self.merged.clear();
        room(&mut self.merged, set.len() + self.found.len());
        let mut found = self.found.iter().copied().peekable();
        for &p in set.iter().filter(|p| !moved_pair(p)) {
            while let Some(f) = found.next_if(|f| *f < p) {
                self.merged.push(f);
            }
            self.merged.push(p);
        }
        self.merged.extend(found);
        std::mem::swap(set, &mut self.merged);
        gjk_runs
    }

    /// `near` = the dynamic colliders' world boxes (not inflated) sorted by [`sweep_order`],
    /// from the order of the last partial update (an insertion sort, linear when few boxes
    /// changed places), and `fixed_near` the fixed colliders' boxes; returns the widest dynamic
    /// box's width in x (m).
    fn sort_near(&mut self, colliders: &[Collider]) -> f64 {
        let entry = |i: usize, c: &Collider| SweepEntry::of(i, c, c.aabb);
        self.fixed_near.clear();
        let mut dynamic = 0;
        for (i, c) in colliders.iter().enumerate() {
            if c.dynamic {
                dynamic += 1;
            } else {
                self.fixed_near.push(entry(i, c));
            }
        }
        // The last order is kept when it holds exactly the dynamic colliders: as many, each
        // still dynamic (distinct indices, so then all of them). A collider whose kind changed
        // with the count unchanged makes it rebuild.
        let mut same = self.near.len() == dynamic;
        if same {
            for e in self.near.iter_mut() {
                match colliders.get(e.index as usize) {
                    Some(c) if c.dynamic => *e = entry(e.index as usize, c),
                    _ => {
                        same = false;
                        break;
                    }
                }
            }
        }
        if same {
            sort_sweep(&mut self.near);
        } else {
            self.near.clear();
            let of_dynamic = colliders.iter().enumerate().filter(|(_, c)| c.dynamic);
            self.near.extend(of_dynamic.map(|(i, c)| entry(i, c)));
            self.near.sort_unstable_by(sweep_order);
        }
        self.near.iter().fold(0.0, |w, e| w.max(e.max_x - e.min_x))
    }
}
