//! Skipping an update that cannot change the set (issue 17): the certificate of an update and
//! the check against it ([`BroadPhase::still_exact`], [`BroadPhase::skip_update`]).
//!
//! The sweep also records how close each of its decisions came to going the other way: the
//! smallest gap between the inflated boxes of two colliders it did not pair (`gap`), and the
//! smallest distance of a paired pair's distance interval from `δ_prox` (`slack`). While no
//! vertex has moved by half the smaller of the two since the update's snapshot, no pair can have
//! changed side, so a new update would compute the same set ([`BroadPhase::still_exact`]). The
//! world then skips the periodic update ([`WorldParams::proximity_skip`](crate::world::WorldParams)):
//! a pile at rest (pile:100, the pyramid, the paper's box scenes) does no global work at all.
//! One pair near a threshold is enough to fail the check, so a large settling pile rarely
//! passes it; after a failed check the next updates skip the bookkeeping
//! ([`BroadPhase::skip_update`]).

use super::*;

impl BroadPhase {
    /// Whether an update now, for the current world features of `colliders`, would compute the
    /// proximity set the last published update computed, so that it may be skipped (issue 17).
    /// False while an update is in progress, or for colliders other than the published
    /// update's (count, vertex counts, bodies and dynamic flags).
    ///
    /// **Why it holds.** Let `M` be the largest distance a vertex has moved since the published
    /// update's snapshot (the snapshot keeps the vertices). Every point of a convex polygon is a
    /// convex combination of its vertices, so it has moved by at most `M` as well: a pair's
    /// distance, and each side of its colliders' boxes, changed by at most `2·M`.
    /// - A pair the sweep paired has a GJK distance interval (its distance at its odometer
    ///   reference, grown by the motion up to the snapshot) that was `slack` away from `δ_prox`
    ///   (beyond the reuse guard): while `2·M < slack`, it is on the same side of `δ_prox`, so in
    ///   the set or out of it as before.
    /// - A pair the sweep did not pair (of two bodies, not both fixed) had inflated boxes `gap` or
    ///   more apart in x or in y, so the colliders were more than `δ_prox + gap` apart: while
    ///   `2·M < gap` they are still more than `δ_prox` apart, and out of the set.
    ///
    /// So while `2·M < min(slack, gap)`, every pair is in the set exactly when it was, and an
    /// update would give the same set (its internal distances and caches aside). The published
    /// set is then as good as a new one for the margin rule (`broad/mod.rs`). Costs one pass over
    /// the colliders' world vertices.
    pub fn still_exact(&self, colliders: &[Collider]) -> bool {
        let snap = &self.snapshot;
        let Some(c) = self.certificate else {
            return false;
        };
        if self.next.is_some()
            || colliders.len() != snap.colliders.len()
            || !(c.gap > 0.0 && c.slack > 0.0)
        {
            return false;
        }
        let limit = 0.5 * c.gap.min(c.slack);
        let limit_sq = limit * limit;
        for (i, col) in colliders.iter().enumerate() {
            let now = col.world_vertices();
            let then = snap.vertices(i as u32);
            if now.len() != then.len() || body_code(col) != snap.bodies[i] {
                return false;
            }
            for (p, q) in now.iter().zip(then) {
                // A NaN vertex fails too.
                let moved_sq = (*p - *q).length_squared();
                if moved_sq >= limit_sq || moved_sq.is_nan() {
                    return false;
                }
            }
        }
        true
    }

    /// [`still_exact`](Self::still_exact), with a backoff for worlds where it keeps failing
    /// (a settling pile:1000 has thousands of pairs, and one of them near a threshold is
    /// enough): after a failed check the next 1, 2, 4, … (at most 16) updates
    /// compute no certificate, so their sweep records no slack and no check reads the vertices;
    /// a check that holds resets it. Returns whether the periodic update may be skipped.
    pub fn skip_update(&mut self, colliders: &[Collider]) -> bool {
        if self.certificate.is_none() {
            return false; // no certificate to check
        }
        if self.still_exact(colliders) {
            self.backoff = 0;
            return true;
        }
        self.backoff = (2 * self.backoff).clamp(1, MAX_BACKOFF);
        self.wait = self.backoff;
        // Checked once: the next update makes a new one, if any.
        self.certificate = None;
        false
    }
}
