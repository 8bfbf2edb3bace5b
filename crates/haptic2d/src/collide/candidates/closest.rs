//! A separated pair within `δ_c`: candidates from its closest features (§9.5), the near-parallel
//! faces first.

use super::{incident_edges, Ctx, Side};
use crate::collide::tracker::{ClosestFeatures, Feature};
use crate::collide::{Collider, VeCandidate};
use crate::geom::Vec2;

impl Ctx {
    /// Separated pair with distance ≤ δ_c: candidates from the closest features (§9.5).
    pub(super) fn closest_feature_candidates(
        &self,
        a: Side,
        b: Side,
        f: &ClosestFeatures,
        out: &mut Vec<VeCandidate>,
    ) {
        // Near-parallel faces: one edge pair whose overlap ends are both within δ_c.
        for ea in incident_edges(a.c, f.feature_a).into_iter().flatten() {
            for eb in incident_edges(b.c, f.feature_b).into_iter().flatten() {
                if self.edge_edge(a, ea, b, eb, true, out) {
                    return;
                }
            }
        }
        match (f.feature_a, f.feature_b) {
            (Feature::Vertex(i), Feature::Edge(j)) => {
                self.push_if_valid(a, i as usize, b, j as usize, out);
            }
            (Feature::Edge(i), Feature::Vertex(j)) => {
                self.push_if_valid(b, j as usize, a, i as usize, out);
            }
            (Feature::Vertex(i), Feature::Vertex(j)) => {
                let (i, j) = (i as usize, j as usize);
                let eb = most_aligned_edge(b.c, j, a.c.world_vertices()[i]);
                self.push_if_valid(a, i, b, eb, out);
                let ea = most_aligned_edge(a.c, i, b.c.world_vertices()[j]);
                self.push_if_valid(b, j, a, ea, out);
            }
            (Feature::Edge(i), Feature::Edge(j)) => {
                self.edge_edge(a, i as usize, b, j as usize, false, out);
            }
        }
    }
}

/// Of the two edges of `c` incident to vertex `v`, the one whose outward normal is most aligned
/// with `p − V` (largest `n·(p − V)`; the outgoing edge on a tie).
fn most_aligned_edge(c: &Collider, v: usize, p: Vec2) -> usize {
    let r = p - c.world_vertices()[v];
    let e_out = v;
    let e_in = c.local.prev(v);
    if c.world_normals()[e_in].dot(r) > c.world_normals()[e_out].dot(r) {
        e_in
    } else {
        e_out
    }
}
