//! The sweep and the pair test: sort-and-sweep over the inflated boxes (64 boxes at a time in y),
//! then GJK on each pair, or a distance reused when the bodies cannot have changed its side.
//!
//! # Distances that need no GJK (issue 17)
//!
//! Given the bodies' odometers (bounds on how far any point of a body has moved, m), a pair
//! tested by the last update at distance `D` whose bodies have moved `m` in all since that
//! distance was computed is now between `D − m` and `D + m` apart. When that interval is on one
//! side of `δ_prox` (by a 1 µm guard), the pair's side of the test is known: GJK is skipped and
//! the pair keeps its distance, cache and odometer reference (`BroadStats::reused_distances`).
//! A pile at rest moves micrometres per period, so its pairs are re-tested only in the sweep.

use super::*;

impl BroadPhase {
    /// Steps 2–3 of an update for the sweep entries `start..stop`. With `CERTIFY`, returns the
    /// certificate `cert` of the update so far with each of these decisions' slack taken in
    /// (without, `cert` unchanged).
    pub(super) fn sweep_boxes<const CERTIFY: bool>(
        &mut self,
        start: usize,
        stop: usize,
        mut cert: Certificate,
    ) -> Certificate {
        // 2. Sweep along the axis (`axis.rs`; said here for x), test y, filter same-body and
        //    fixed–fixed pairs; 3. warm-started GJK per pair (each pair's result depends on its
        //    own cache only, so the order of this loop does not change any result).
        // Same body, or both fixed (the dynamic flags are the low bits): never a pair.
        let unpaired = |p: &SweepEntry, q: &SweepEntry| {
            p.body >> 1 == q.body >> 1 || (p.body | q.body) & 1 == 0
        };
        let n = self.sweep.len();
        for i in start..stop {
            let ei = self.sweep[i];
            // The run of boxes that start before `ei` ends in x (sorted by start), 64 at a time,
            // and a bit for each that overlaps `ei` (the rest of `Aabb::overlaps`, closed
            // intervals, from the entries alone: in y, which rejects most of a pile's column).
            // The bits are set without a branch: whether a box of another row overlaps is what a
            // branch predictor cannot guess.
            let mut from = i + 1;
            let end = loop {
                let to = (from + 64).min(n);
                let mut end = to;
                let mut bits = 0u64;
                // With `CERTIFY`, a bit for each box apart in y by less than the gap so far.
                let (mut nearer, gap) = (0u64, cert.gap);
                for (k, ej) in self.sweep[from..to].iter().enumerate() {
                    if ej.min_x > ei.max_x {
                        end = from + k;
                        break;
                    }
                    let overlaps =
                        (ej.min_y <= ei.max_y) & (ei.min_y <= ej.max_y) & (ei.min_x <= ej.max_x);
                    if CERTIFY {
                        let lower = y_gap(&ei, ej) < gap;
                        nearer |= ((lower & !overlaps) as u64) << k;
                    }
                    bits |= (overlaps as u64) << k;
                }
                // The y gap to a box it could be paired with but does not overlap: only the
                // boxes that can lower the gap are looked at again (the smallest of the same
                // values; the others are at least the gap already).
                while CERTIFY && nearer != 0 {
                    let ej = self.sweep[from + nearer.trailing_zeros() as usize];
                    nearer &= nearer - 1;
                    if !unpaired(&ei, &ej) {
                        cert.gap = cert.gap.min(y_gap(&ei, &ej));
                    }
                }
                while bits != 0 {
                    let ej = self.sweep[from + bits.trailing_zeros() as usize];
                    bits &= bits - 1;
                    if !unpaired(&ei, &ej) {
                        self.test_pair::<CERTIFY>(&ei, &ej, &mut cert);
                    }
                }
                if end < to || to == n {
                    break end;
                }
                from = to;
            };
            if CERTIFY && end < n {
                // Every later box starts at least this far beyond `ei`'s end (the gap to the
                // first one it could be paired with, looking a few entries ahead).
                let rest = &self.sweep[end..];
                let beyond = rest
                    .iter()
                    .take(GAP_LOOKAHEAD)
                    .find(|e| !unpaired(&ei, e))
                    .or(rest.get(GAP_LOOKAHEAD - 1));
                if let Some(e) = beyond {
                    cert.gap = cert.gap.min(e.min_x - ei.max_x);
                }
            }
        }
        cert
    }

    /// Step 3 for one pair of overlapping boxes: its last distance reused when the motion cannot
    /// have moved it across `δ_prox`, warm-started GJK otherwise. With `CERTIFY`, takes the
    /// decision's slack into `cert`.
    #[inline(always)]
    pub(super) fn test_pair<const CERTIFY: bool>(
        &mut self,
        ei: &SweepEntry,
        ej: &SweepEntry,
        cert: &mut Certificate,
    ) {
        let (a, b) = (ei.index.min(ej.index), ei.index.max(ej.index));
        let odo = self.snapshot.odo[a as usize] + self.snapshot.odo[b as usize];
        let last = self.cached(a, b);
        if let Some(k) = last {
            // The pair's side of δ_prox is known from its last distance and the motion.
            let (d, moved) = (self.distances[k], odo - self.odo_refs[k]);
            let below = (self.delta_prox - REUSE_GUARD) - (d + moved);
            let above = (d - moved) - (self.delta_prox + REUSE_GUARD);
            if below > 0.0 || above > 0.0 {
                if CERTIFY {
                    cert.slack = cert.slack.min(below.max(above));
                }
                self.reused_distances += 1;
                self.kept.push(k as u32);
                return;
            }
        }
        match last {
            Some(k) => self.patches.push((k as u32, self.tested.len() as u32)),
            None => {
                self.all_published = false;
                self.fresh.push(self.tested.len() as u32);
            }
        }
        let mut cache = last.map(|k| self.caches[k]).unwrap_or_default();
        let g = gjk_distance(
            self.snapshot.vertices(a),
            self.snapshot.vertices(b),
            &mut cache,
        );
        self.gjk_iterations += g.iterations as u64;
        if CERTIFY {
            let slack = (g.distance - self.delta_prox).abs() - REUSE_GUARD;
            cert.slack = cert.slack.min(slack);
        }
        self.tested.push(Tested {
            pair: (a, b),
            cache,
            distance: g.distance,
            odo_ref: odo,
        });
    }

    /// Where pair `(a, b)` is in the published update (its cache, distance and odometer
    /// reference), if it tested the pair.
    #[inline]
    pub(super) fn cached(&self, a: u32, b: u32) -> Option<usize> {
        let from = *self.cache_start.get(a as usize)? as usize;
        let to = *self.cache_start.get(a as usize + 1)? as usize;
        Some(from + self.cache_pairs[from..to].iter().position(|p| p.1 == b)?)
    }
}

/// The gap in y between the boxes of two sweep entries (m; negative when they overlap in y).
#[inline(always)]
fn y_gap(p: &SweepEntry, q: &SweepEntry) -> f64 {
    (q.min_y - p.max_y).max(p.min_y - q.max_y)
}
