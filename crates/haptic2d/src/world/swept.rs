//! §0.5 step 10d, the swept test (time of impact, `collide/toi.rs`, MODELS §9.7), and the state it
//! keeps: each collider's thickness, the bodies' velocities before integration and its scratch.

use crate::body::Body;
use crate::collide::{
    allowed_depth, body_thickness, swept_put_back, Collider, SweepScratch, SweptShape,
};
use crate::geom::{Pose, Vec2};

use super::point_motion;

/// The swept test and its state.
#[derive(Clone, Debug)]
pub(super) struct SweptTest {
    /// Minimum width of each collider (m).
    thickness: Vec<f64>,
    /// The smallest of `thickness` (m).
    thinnest: f64,
    /// Velocities `(v, ω)` before this sample's integration, per body.
    vel_before: Vec<(Vec2, f64)>,
    /// Point-motion bound of each body over this sample (m), whatever its kind (a kinematic
    /// body's motion counts in its pairs' swept test).
    reach: Vec<f64>,
    /// Fraction of the sample each body keeps after the swept test (1 = all of it).
    put_back: Vec<f64>,
    /// Scratch of the swept test.
    sweep: SweepScratch,
    /// Number of samples at which the swept test put a body back.
    pub(super) hits: u64,
}

impl SweptTest {
    /// The test for `bodies` bodies and `colliders`.
    pub(super) fn new(bodies: usize, colliders: &[Collider]) -> Self {
        let thickness: Vec<f64> = colliders.iter().map(|c| body_thickness(&c.local)).collect();
        let thinnest = thickness.iter().fold(f64::INFINITY, |a, &t| a.min(t));
        let max_vertices = colliders.iter().map(|c| c.len()).max().unwrap_or(4);
        Self {
            thickness,
            thinnest,
            vel_before: vec![(Vec2::ZERO, 0.0); bodies],
            reach: vec![0.0; bodies],
            put_back: vec![1.0; bodies],
            sweep: SweepScratch::with_capacity(max_vertices),
            hits: 0,
        }
    }

    /// Remembers body `i`'s velocity before its integration (the start of the swept motion).
    #[inline]
    pub(super) fn remember(&mut self, i: usize, b: &Body) {
        self.vel_before[i] = (b.vel, b.omega);
    }

    /// The swept test for every proximate pair of `pairs` whose motion this sample (from `prev`
    /// to the bodies' poses now) could carry it past the allowed depth: bodies are put back to
    /// the fraction `λ_t` of the sample (pose and velocity interpolated), the smallest over their
    /// pairs. A cheap bound skips the pass when no body moved more than half the smallest allowed
    /// depth. `radius` is each body's vertex radius (m), `delta_c` the contact tolerance (m).
    pub(super) fn run(
        &mut self,
        delta_c: f64,
        bodies: &mut [Body],
        colliders: &[Collider],
        pairs: &[(u32, u32)],
        prev: &[Pose],
        radius: &[f64],
    ) {
        let dc = delta_c;
        let mut max_motion = 0.0f64;
        for (i, b) in bodies.iter().enumerate() {
            let p = prev[i];
            let m = point_motion(&p, &b.pose, radius[i]);
            self.reach[i] = m;
            max_motion = max_motion.max(if b.is_dynamic() { m } else { 0.0 });
        }
        let least_allowed = allowed_depth(dc, self.thinnest, self.thinnest);
        if 2.0 * max_motion <= least_allowed {
            return;
        }
        self.put_back.fill(1.0);
        // A dynamic body's motion this sample (m), 0 for any other (the swept boxes' growth).
        let motion = |i: usize| {
            if bodies[i].is_dynamic() {
                self.reach[i]
            } else {
                0.0
            }
        };
        let mut hit = false;
        for &(ca, cb) in pairs {
            let (ca, cb) = (ca as usize, cb as usize);
            let (ia, ib) = (colliders[ca].body, colliders[cb].body);
            if slow_pair(self.reach[ia], self.reach[ib], least_allowed) {
                continue;
            }
            let side = |c: usize, i: usize| SweptShape {
                shape: &colliders[c].local,
                start: prev[i],
                end: bodies[i].pose,
                radius: radius[i],
                seams: colliders[c].seams,
            };
            // Swept boxes apart: the start AABBs (this sample's colliders), each grown by its
            // body's motion, do not overlap, so the pair cannot touch during the sample.
            let (ba, bb) = (&colliders[ca].aabb, &colliders[cb].aabb);
            let grow = motion(ia) + motion(ib);
            if ba.min.x - bb.max.x > grow
                || bb.min.x - ba.max.x > grow
                || ba.min.y - bb.max.y > grow
                || bb.min.y - ba.max.y > grow
            {
                continue;
            }
            let allowed = allowed_depth(dc, self.thickness[ca], self.thickness[cb]);
            if let Some(l) = swept_put_back(&side(ca, ia), &side(cb, ib), allowed, &mut self.sweep)
            {
                self.put_back[ia] = self.put_back[ia].min(l);
                self.put_back[ib] = self.put_back[ib].min(l);
                hit = true;
            }
        }
        if !hit {
            return;
        }
        self.hits += 1;
        for (i, b) in bodies.iter_mut().enumerate() {
            let lam = self.put_back[i];
            if lam >= 1.0 || !b.is_dynamic() {
                continue;
            }
            let (p0, (v0, w0)) = (prev[i], self.vel_before[i]);
            b.pose.pos = p0.pos + (b.pose.pos - p0.pos) * lam;
            b.pose.angle = p0.angle + (b.pose.angle - p0.angle) * lam;
            b.vel = v0 + (b.vel - v0) * lam;
            b.omega = w0 + (b.omega - w0) * lam;
        }
    }
}

/// Whether a pair whose bodies' point motions this sample are `reach_a` and `reach_b` (m) is
/// too slow for the swept test to act (`swept_put_back` returns `None` when the pair's relative
/// motion `m ≤ allowed`), for every pair allowed at least `least_allowed` (m): `m ≤ reach_a +
/// reach_b` (the triangle inequality, `pair_motion`), and the factor `1 + 1e-9` covers the
/// rounding of both sides (a few units of 1.1e-16 relative) many times over. NaN is not slow.
#[inline(always)]
fn slow_pair(reach_a: f64, reach_b: f64, least_allowed: f64) -> bool {
    (reach_a + reach_b) * (1.0 + 1e-9) <= least_allowed
}

#[cfg(test)]
mod tests {
    use super::slow_pair;
    use crate::collide::SweptShape;
    use crate::geom::{ConvexPolygon, Pose};
    use crate::world::point_motion;

    /// The bound `slow_pair` rests on, for the swept test's own shapes: over 20 000 motions
    /// of every scale (1e-9 m to 1 m) in every direction, the world's point motion of a body is
    /// bit for bit the swept shape's `motion()` (the terms of `pair_motion`, whose bound by the
    /// sum of the two is pinned in `collide/toi.rs`); a pair exactly at the bound is slow, one
    /// two parts in 1e9 under it is not, and NaN is never slow.
    #[test]
    fn slow_pair_is_the_sum_of_the_swept_motions_with_its_margin() {
        let square = ConvexPolygon::rectangle(0.1, 0.1).unwrap();
        for k in 0..20_000 {
            let (x, scale) = (k as f64, 10f64.powf(-9.0 * k as f64 / 20_000.0));
            let start = Pose::new(0.5 * x.sin(), 0.5 * (1.3 * x).cos(), 0.7 * (0.9 * x).sin());
            let end = Pose::new(
                start.pos.x + scale * (2.1 * x).cos(),
                start.pos.y + scale * (2.1 * x).sin(),
                start.angle + scale * (0.37 * x).sin(),
            );
            let radius = 0.1 + 0.05 * (0.11 * x).sin();
            let shape = SweptShape {
                shape: &square,
                start,
                end,
                radius,
                seams: 0,
            };
            let m = point_motion(&start, &end, radius);
            assert_eq!(m.to_bits(), shape.motion().to_bits(), "at {k}");
            let other = scale * (0.5 + 0.5 * (0.23 * x).cos());
            let bound = (m + other) * (1.0 + 1e-9);
            assert!(slow_pair(m, other, bound));
            assert!(!slow_pair(m, other, bound * (1.0 - 1e-9) * (1.0 - 1e-9)));
        }
        assert!(!slow_pair(f64::NAN, 0.0, 1.0));
    }
}
