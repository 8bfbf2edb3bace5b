//! The global proximity stage (§9.1): inflated AABBs, sort-and-sweep on x, then GJK distance.
//!
//! # The algorithm
//!
//! Every `N_g` samples (`T_g = 20 ms` by default):
//!
//! 1. Each collider's world AABB is enlarged by `δ_prox/2` on every side, so two boxes overlap
//!    whenever the polygons are closer than `δ_prox` (a necessary condition).
//! 2. Sort-and-sweep: the boxes are sorted by `(min.x, collider index)` (a total order, so the
//!    result does not depend on the sort algorithm) and each box is tested only against the boxes
//!    that start before it ends in x; y overlap is then checked directly. Pairs on the same body and
//!    pairs of two fixed colliders are skipped.
//! 3. Each surviving pair gets a warm-started GJK distance (§9.2; one [`GjkCache`] per pair, kept
//!    while the pair keeps overlapping in the AABB test). Pairs with distance `< δ_prox` form the
//!    proximity set, a sorted list of `(a, b)` collider indices with `a < b`.
//!
//! # The margin
//!
//! The proximity set must not miss a collision until the next global update. The distance of two
//! bodies decreases at most at `v_rel,max`; allowing one period for the update itself and one for
//! its result to be consumed (it may run on another thread, §0.5 step 3), a pair found farther than
//! `δ_prox` is still farther than `δ_c` — so still without VE candidates — for `2·T_g`:
//!
//! ```text
//! δ_prox ≥ 2·v_rel,max·T_g + δ_c      (1 m/s, 0.02 s, 0.002 m → 0.042 m)
//! ```

use super::gjk::{gjk_distance, GjkCache};
use super::Collider;
use crate::geom::Aabb;

/// Default proximity distance `δ_prox` (m), §9.1: `2·(1 m/s)·(0.02 s) + 0.002 m`.
pub const DEFAULT_DELTA_PROX: f64 = 0.042;

/// The smallest proximity distance `δ_prox = 2·v_rel,max·T_g + δ_c` (m) that cannot miss a
/// collision between global updates (§9.1), for the largest relative speed of any two points
/// `v_rel_max` (m/s), the global period `t_g` (s) and the contact distance tolerance `delta_c` (m).
pub fn required_delta_prox(v_rel_max: f64, t_g: f64, delta_c: f64) -> f64 {
    2.0 * v_rel_max * t_g + delta_c
}

/// Work counters of the last [`BroadPhase::update`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BroadStats {
    /// Pairs whose inflated AABBs overlap (after the same-body / fixed–fixed filters).
    pub aabb_pairs: usize,
    /// Pairs found within `δ_prox` by GJK.
    pub proximate_pairs: usize,
    /// GJK iterations spent on all pairs.
    pub gjk_iterations: u64,
}

/// One box in the sweep: inflated `min.x`, `max.x` and the collider index.
#[derive(Clone, Copy, Debug)]
struct SweepEntry {
    min_x: f64,
    max_x: f64,
    index: u32,
}

/// The global proximity stage with its reusable buffers and per-pair GJK caches.
#[derive(Clone, Debug)]
pub struct BroadPhase {
    delta_prox: f64,
    boxes: Vec<Aabb>,
    sweep: Vec<SweepEntry>,
    tested: Vec<(u32, u32)>,
    cache_pairs: Vec<(u32, u32)>,
    caches: Vec<GjkCache>,
    new_cache_pairs: Vec<(u32, u32)>,
    new_caches: Vec<GjkCache>,
    distances: Vec<f64>,
    stats: BroadStats,
}

impl BroadPhase {
    /// A global stage with proximity distance `delta_prox` (m, finite, > 0; default
    /// [`DEFAULT_DELTA_PROX`]).
    pub fn new(delta_prox: f64) -> Result<Self, String> {
        if !(delta_prox.is_finite() && delta_prox > 0.0) {
            return Err(format!(
                "delta_prox (proximity distance) must be a finite distance > 0 m, got {delta_prox}"
            ));
        }
        Ok(Self {
            delta_prox,
            boxes: Vec::new(),
            sweep: Vec::new(),
            tested: Vec::new(),
            cache_pairs: Vec::new(),
            caches: Vec::new(),
            new_cache_pairs: Vec::new(),
            new_caches: Vec::new(),
            distances: Vec::new(),
            stats: BroadStats::default(),
        })
    }

    /// The proximity distance `δ_prox` (m).
    pub fn delta_prox(&self) -> f64 {
        self.delta_prox
    }

    /// Counters of the last update.
    pub fn stats(&self) -> BroadStats {
        self.stats
    }

    /// GJK distances (m) of the AABB-overlapping pairs of the last update, with those pairs (sorted).
    pub fn tested_pairs(&self) -> (&[(u32, u32)], &[f64]) {
        (&self.cache_pairs, &self.distances)
    }

    /// Computes the proximity set of `colliders` (world features must be current) into `out`
    /// (cleared first): sorted `(a, b)` collider indices, `a < b`, with GJK distance `< δ_prox`.
    /// No allocation once the buffers have grown to the scene's size.
    pub fn update(&mut self, colliders: &[Collider], out: &mut Vec<(u32, u32)>) {
        out.clear();
        let half = 0.5 * self.delta_prox;

        // 1. Inflated boxes, sorted by (min.x, index).
        self.boxes.clear();
        self.sweep.clear();
        for (i, c) in colliders.iter().enumerate() {
            let bx = c.aabb.inflated(half);
            self.boxes.push(bx);
            self.sweep.push(SweepEntry {
                min_x: bx.min.x,
                max_x: bx.max.x,
                index: i as u32,
            });
        }
        self.sweep
            .sort_unstable_by(|p, q| p.min_x.total_cmp(&q.min_x).then(p.index.cmp(&q.index)));

        // 2. Sweep on x, test y, filter same-body and fixed–fixed pairs.
        self.tested.clear();
        for i in 0..self.sweep.len() {
            let ei = self.sweep[i];
            for ej in &self.sweep[i + 1..] {
                if ej.min_x > ei.max_x {
                    break;
                }
                let (a, b) = (ei.index.min(ej.index), ei.index.max(ej.index));
                let (ca, cb) = (&colliders[a as usize], &colliders[b as usize]);
                if ca.body == cb.body || !(ca.dynamic || cb.dynamic) {
                    continue;
                }
                if self.boxes[a as usize].overlaps(&self.boxes[b as usize]) {
                    self.tested.push((a, b));
                }
            }
        }
        self.tested.sort_unstable();

        // 3. Warm-started GJK per pair; the caches follow the (sorted) pair list.
        self.new_cache_pairs.clear();
        self.new_caches.clear();
        self.distances.clear();
        let mut gjk_iterations = 0;
        for &(a, b) in &self.tested {
            let mut cache = match self.cache_pairs.binary_search(&(a, b)) {
                Ok(k) => self.caches[k],
                Err(_) => GjkCache::new(),
            };
            let g = gjk_distance(
                &colliders[a as usize].world_vertices,
                &colliders[b as usize].world_vertices,
                &mut cache,
            );
            gjk_iterations += g.iterations as u64;
            if g.distance < self.delta_prox {
                out.push((a, b));
            }
            self.new_cache_pairs.push((a, b));
            self.new_caches.push(cache);
            self.distances.push(g.distance);
        }
        std::mem::swap(&mut self.cache_pairs, &mut self.new_cache_pairs);
        std::mem::swap(&mut self.caches, &mut self.new_caches);
        self.stats = BroadStats {
            aabb_pairs: self.tested.len(),
            proximate_pairs: out.len(),
            gjk_iterations,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{ConvexPolygon, Pose};

    fn square(body: usize, dynamic: bool, x: f64, y: f64) -> Collider {
        Collider::new(
            body,
            dynamic,
            ConvexPolygon::rectangle(0.04, 0.04).unwrap(),
            &Pose::new(x, y, 0.0),
        )
    }

    #[test]
    fn margin_rule_gives_default() {
        assert!((required_delta_prox(1.0, 0.02, 0.002) - DEFAULT_DELTA_PROX).abs() < 1e-15);
        assert!(BroadPhase::new(0.0).is_err());
        assert!(BroadPhase::new(f64::NAN).is_err());
    }

    #[test]
    fn filters_and_threshold() {
        let cols = vec![
            square(0, false, 0.0, 0.0),
            square(1, false, 0.06, 0.0),  // fixed–fixed with 0: skipped
            square(2, true, 0.0, 0.081),  // 0.041 from 0: proximate
            square(2, true, 0.0, 0.0805), // same body as 2: never paired with it
            square(3, true, 0.2, 0.0),    // far from everything
            square(4, true, 0.0, -0.083), // 0.043 from 0: not proximate
        ];
        let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        let mut out = Vec::new();
        bp.update(&cols, &mut out);
        assert_eq!(out, vec![(0, 2), (0, 3)]);
    }
}
