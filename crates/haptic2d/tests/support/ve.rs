//! `ve(vc, v, ec, e)`: a VE candidate (vertex `v` of collider `vc` against edge `e` of collider
//! `ec`), for tests that compare the local stage's output. Include with
//! `#[path = "support/ve.rs"] mod ve_support;`.

use haptic2d::collide::VeCandidate;

/// The candidate of vertex `v` of collider `vc` against edge `e` of collider `ec`.
pub fn ve(vc: u32, v: u32, ec: u32, e: u32) -> VeCandidate {
    VeCandidate {
        vertex_collider: vc,
        vertex: v,
        edge_collider: ec,
        edge: e,
    }
}
