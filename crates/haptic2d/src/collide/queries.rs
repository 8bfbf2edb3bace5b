//! Depth queries against a collider that respect its seams (`seam.rs`): the nearest surface line
//! of a point ([`nearest_line`]), the separating-axis depth of two pieces ([`sat_depth`],
//! [`sat_axis`]). Used by the local stage's candidate rules (`local.rs`), the clip contacts
//! (`clip.rs`) and the depth invariant of the contact records.

use super::Collider;
use crate::geom::Vec2;

/// The nearest edge line of `b` to the world point `p`: `(j*, d_{j*})` with `d_{j*} = max_j d_j`
/// over `b`'s edge lines that are not seams (m, positive outside; `(0, −∞)` if every edge is a
/// seam), or the seam line `p` is farthest outside of if it is outside `b` across a seam (then
/// `j*` is a seam, never a contact edge). For `p` inside `b`, `−d_{j*}` is its depth (distance
/// to the body's surface through `b`'s surface edges).
///
/// The invariant of every VE record `(V, e)` (issue 10): `d_e ≥ d_{j*} − δ_c`, so its stored
/// energy `½·K_c·d_e²` never exceeds that of the vertex's real depth by more than the corner
/// tolerance allows, or (issue 35) `−d_e ≤ sat_depth + δ_c`, the pair's overlap.
#[inline]
pub fn nearest_line(b: &Collider, p: Vec2) -> (usize, f64) {
    let mut best = (0usize, f64::NEG_INFINITY);
    let mut seam = (0usize, 0.0f64);
    for e in 0..b.len() {
        let d = b.edge_distance(e, p);
        if b.is_seam(e) {
            if d > seam.1 {
                seam = (e, d);
            }
        } else if d > best.1 {
            best = (e, d);
        }
    }
    // Outside `b` across a seam: the point is that far from `b` (in the next piece), unless it
    // is across seams that face a partly covered edge only, within their reach (in the piece
    // under `b`, whose surface lines hold it too, `Collider::across_seam`).
    if seam.1 > 0.0 && seam.1 > best.1 && !(best.1 <= 0.0 && b.across_seam(p).is_some()) {
        seam
    } else {
        best
    }
}

/// Penetration depth of two convex polygons by separating axes (m): the smallest overlap of their
/// projections over the edge normals of both, `0` if some axis separates them. No vertex of one
/// can be deeper in the other than this (translating by the minimum separating vector clears
/// every vertex). Costs `O((n_a + n_b)²)`: for checks and reports, not the hot path.
///
/// **Seams** (`seam.rs`): a piece of a multi-piece body is cleared through the body's surface,
/// never through a seam into the next piece. So a seam's normal is no axis, and neither is an
/// axis whose separating motion (of `a` relative to `b`) has a component through a seam of `b`
/// (or, reversed, of `a`): moving along it could clear the piece through the joint. Along an
/// admissible axis `u` every vertex leaves the piece through a surface edge `f` (`n_f·u > 0`)
/// after at least its depth `−d_f`, so the bound above still holds with depth measured to the
/// nearest surface line ([`nearest_line`]). A piece with no admissible axis gets the least
/// overlap over its surface normals.
pub fn sat_depth(a: &Collider, b: &Collider) -> f64 {
    sat_axis(a, b).0
}

/// [`sat_depth`] with its axis: `(depth, u)`, `u` the unit direction in which `a` moves
/// (relative to `b`) to separate by `depth`; `u = 0` when the pair is apart.
pub fn sat_axis(a: &Collider, b: &Collider) -> (f64, Vec2) {
    super::clip::sat_face(a, b).map_or((0.0, Vec2::ZERO), |f| (f.depth, f.axis))
}
