//! The depth invariant of [`ContactSet::step`]: the check used where a record is created or handed
//! over, the face-on-face exception, and the debug-build assertion run after every step.

use super::ContactSet;
use crate::collide::{nearest_line, sat_depth, Collider, VeCandidate};

impl ContactSet {
    /// Debug builds: every record satisfies the depth invariant of [`ContactSet::step`], and is no
    /// deeper than its pair's separating-axis depth plus `δ_c`.
    #[cfg(debug_assertions)]
    pub(super) fn assert_depth_invariant(&self, colliders: &[Collider]) {
        // Round-off allowance on distances of a few metres at most.
        const TOL: f64 = 1e-9;
        for e in self.entries.iter().filter(|e| e.is_contact()) {
            let ca = &colliders[e.key.vertex_collider as usize];
            let cb = &colliders[e.key.edge_collider as usize];
            let p = ca.world_vertices()[e.key.vertex as usize];
            let d_e = cb.edge_distance(e.key.edge as usize, p);
            let (j, max_d) = nearest_line(cb, p);
            let face = face_on_face_ok(e.key, colliders, self.delta_c, self.cos_parallel);
            debug_assert!(
                d_e >= max_d - self.delta_c - TOL || face,
                "VE record {:?}: d = {d_e:e} m on its edge, but edge {j}'s line is at {max_d:e} m \
                 (more than δ_c = {} m nearer): its stored energy exceeds the vertex's real depth",
                e.key,
                self.delta_c
            );
            let sat = sat_depth(ca, cb);
            debug_assert!(
                -d_e <= sat + self.delta_c + TOL,
                "VE record {:?}: depth {:e} m exceeds the pair's separating-axis depth {sat:e} m + δ_c",
                e.key,
                -d_e
            );
        }
    }
}

/// The depth invariant of [`ContactSet::step`] for the pair `key` at the current poses:
/// `d_e ≥ max_j d_j − δ_c` over the edge collider's lines `j`, or the face-on-face case
/// ([`face_on_face_ok`]).
#[inline]
pub(super) fn depth_ok(
    key: VeCandidate,
    colliders: &[Collider],
    delta_c: f64,
    cos_parallel: f64,
) -> bool {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let p = ca.world_vertices()[key.vertex as usize];
    cb.edge_distance(key.edge as usize, p) >= nearest_line(cb, p).1 - delta_c
        || face_on_face_ok(key, colliders, delta_c, cos_parallel)
}

/// The face-on-face exception of the depth invariant ([`ContactSet::step`]): edge `e` faces an
/// edge of A at the vertex (`n_e·n_A < −cos_parallel`) and the record is no deeper than the
/// pair's separating-axis depth plus `δ_c`. The SAT depth costs `O((n_a + n_b)²)`, so this runs
/// only where the nearest-line test has failed (a stack compressed past `δ_c`).
pub(super) fn face_on_face_ok(
    key: VeCandidate,
    colliders: &[Collider],
    delta_c: f64,
    cos_parallel: f64,
) -> bool {
    let ca = &colliders[key.vertex_collider as usize];
    let cb = &colliders[key.edge_collider as usize];
    let (v, e) = (key.vertex as usize, key.edge as usize);
    let n = cb.world_normals()[e];
    let faces = n.dot(ca.world_normals()[v]) < -cos_parallel
        || n.dot(ca.world_normals()[ca.local.prev(v)]) < -cos_parallel;
    faces && -cb.edge_distance(e, ca.world_vertices()[v]) <= sat_depth(ca, cb) + delta_c
}
