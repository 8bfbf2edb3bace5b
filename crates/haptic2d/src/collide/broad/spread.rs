//! Spreading the stage over the samples: [`BroadPhase::begin`] (the snapshot, the boxes and
//! their sort) and [`BroadPhase::advance`] (a share of the sweep per sample).
//!
//! Run at once, the stage makes every `N_g`-th sample the slowest (≈ 2.7× the others at 1000
//! bodies): a deadline spike. The margin (`broad/mod.rs`) already allows one period for the update itself,
//! so the work can instead be spread over the `N_g` samples of a period (the world's default):
//!
//! ```text
//! sample k·N_g           publish(set of (k−1)·N_g)   begin(poses of k·N_g)
//! sample k·N_g + j       advance: ⌈remaining/(N_g−j)⌉ boxes                  j = 1 … N_g−2
//! sample k·N_g + N_g−1   advance: the last boxes, then merge the pairs in order (publish only
//!                        hands them over), or patch in place (`publish.rs`)
//! ```
//!
//! The publishing sample sweeps nothing: publishing and `begin` (the snapshot, the boxes and
//! their sort) are its share.
//!
//! `begin` copies the world vertices (the snapshot), so the set published at `(k+1)·N_g` is
//! exactly the set [`BroadPhase::update`] would have computed at `k·N_g` (same pairs, distances
//! and caches: each pair's GJK depends only on its vertices and its own cache, not on the order
//! of the pairs). It is used until `(k+2)·N_g`: a pair it leaves out was `≥ δ_prox` apart at
//! `k·N_g` and, at `v_rel,max`, is still `> δ_c` apart `2·T_g` later, which is the margin rule.
//! A body that moved more than `(δ_prox − δ_c)/2` since the poses its pairs were decided for gets
//! them decided again at once by a partial update (`partial.rs`), which leaves the update in
//! progress going on; the world runs the whole stage at once instead only when many bodies did
//! (`world/proximity.rs`), so fast bodies keep their guarantee.

use super::*;

impl BroadPhase {
    /// Starts an update for the current poses of `colliders`: copies their world vertices, builds
    /// the inflated boxes and sorts them (abandons an update in progress). Nothing is published
    /// until [`publish`](Self::publish).
    pub fn begin(&mut self, colliders: &[Collider]) {
        self.begin_with_motion(colliders, &[]);
    }

    /// [`begin`](Self::begin) with the bodies' odometers now (see
    /// [`update_with_motion`](Self::update_with_motion)).
    pub fn begin_with_motion(&mut self, colliders: &[Collider], odometer: &[f64]) {
        let half = 0.5 * self.delta_prox;
        // 0. The snapshot: the rest of the update reads only this copy.
        self.snapshot.vertices.clear();
        self.snapshot.colliders.clear();
        self.snapshot.odo.clear();
        self.snapshot.bodies.clear();
        for c in colliders {
            let s = self.snapshot.vertices.len() as u32;
            self.snapshot.vertices.extend_from_slice(c.world_vertices());
            self.snapshot
                .colliders
                .push((s, c.world_vertices().len() as u32));
            self.snapshot
                .odo
                .push(odometer.get(c.body).copied().unwrap_or(f64::NAN));
            self.snapshot.bodies.push(body_code(c));
        }
        self.progress = (self.wait == 0).then_some(Certificate::OPEN);
        self.wait = self.wait.saturating_sub(1);
        // 1. Inflated boxes along the sweep axis (`axis.rs`), sorted by (min, index): in the last
        //    update's order, which is nearly sorted when the bodies move little between updates
        //    (insertion sort), or by index (a full sort) when the colliders or the axis changed.
        let axis = sweep_axis(colliders, half);
        let entry = |i: usize, c: &Collider| SweepEntry::along(i, c, c.aabb.inflated(half), axis);
        if self.sweep.len() == colliders.len() && axis == self.axis {
            for e in self.sweep.iter_mut() {
                *e = entry(e.index as usize, &colliders[e.index as usize]);
            }
            sort_sweep(&mut self.sweep);
        } else {
            self.sweep.clear();
            for (i, c) in colliders.iter().enumerate() {
                self.sweep.push(entry(i, c));
            }
            self.sweep.sort_unstable_by(sweep_order);
        }
        self.axis = axis;
        // Both buffers of the per-collider starts, sized here (an update in place leaves them
        // unswapped for many periods, so the second one would otherwise grow late).
        room(&mut self.cache_start, colliders.len() + 1);
        room(&mut self.ready.start, colliders.len() + 1);
        // And the partial update's boxes (`partial.rs`), so that its first run does not allocate.
        room(&mut self.near, colliders.len());
        room(&mut self.fixed_near, colliders.len());
        self.tested.clear();
        self.kept.clear();
        self.fresh.clear();
        self.sorted = false;
        self.all_published = true;
        self.patches.clear();
        // Room for every published pair, so that patching allocates only when the published
        // update has grown (when the other buffers grow too).
        room(&mut self.patches, self.cache_pairs.len());
        room(&mut self.kept, self.cache_pairs.len());
        self.in_place = false;
        self.gjk_iterations = 0;
        self.reused_distances = 0;
        self.next = Some(0);
    }

    /// Advances the update in progress by one sample's share, `samples_left` being the number of
    /// calls left before [`publish`](Self::publish) (this one included; at least 1): the
    /// remaining boxes are split evenly over the `samples_left` calls (`⌈remaining /
    /// samples_left⌉` boxes, each tested against the boxes that start before it ends in x, GJK on
    /// every pair that overlaps); the last call (`samples_left = 1`) sweeps whatever is left and
    /// finishes the result (sorts the pairs, or marks them for patching in place), so the
    /// publishing sample only hands it over. Does nothing when no update is in progress.
    pub fn advance(&mut self, samples_left: usize) {
        let Some(start) = self.next else { return };
        let n = self.sweep.len();
        let share = (n - start).div_ceil(samples_left.max(1));
        let stop = (start + share).min(n);
        match self.progress {
            Some(cert) => self.progress = Some(self.sweep_boxes::<true>(start, stop, cert)),
            None => {
                self.sweep_boxes::<false>(start, stop, Certificate::OPEN);
            }
        }
        self.next = Some(stop);
        if samples_left <= 1 && !self.sorted {
            // Every tested pair is a published one (distinct ones: the sweep meets each pair
            // once), so when the counts agree the tested pairs are exactly the published pairs:
            // sorting them would rebuild the published arrays with the reused entries as they
            // are and the `patches` written over theirs.
            self.in_place = self.all_published
                && self.tested.len() + self.kept.len() == self.cache_pairs.len()
                && self.cache_start.len() == self.snapshot.colliders.len() + 1;
            if !self.in_place {
                self.sort_fresh();
                self.fill_ready();
            }
            self.sorted = true;
        }
    }
}
