//! A convex collision shape attached to a body, with world-frame features cached once per tick.

use crate::geom::{Aabb, ConvexPolygon, Pose, Rot, Vec2};

/// A convex piece of a body. `local` is expressed in the body frame (origin at the centre of mass);
/// `world_*` are refreshed by [`Collider::update`] at the start of every tick.
#[derive(Clone, Debug)]
pub struct Collider {
    /// Index of the owning body in the world.
    pub body: usize,
    /// True if the owning body is dynamic (pairs of two fixed colliders are never tested).
    pub dynamic: bool,
    /// The polygon in the body frame (m).
    pub local: ConvexPolygon,
    /// World vertices `[0, n)` (m, counter-clockwise) and outward unit normals `[n, 2n)`, in one
    /// allocation ([`world_vertices`](Self::world_vertices), [`world_normals`](Self::world_normals)).
    world: Vec<Vec2>,
    /// World bounding box (m), not inflated.
    pub aabb: Aabb,
    /// Seam mask: bit `e` set when edge `e` is an internal edge of a body of several pieces,
    /// covered by another piece (`seam.rs`), and so never a contact normal. 0 for a lone piece;
    /// set by [`mark_seams`](super::mark_seams) (the world does it when it is built).
    pub seams: u128,
    /// Seams that face a *partly* covered edge of another piece (the wall slab's bottom on the
    /// floor slab's top, `seam.rs`): bit `e` set when the pieces across seam `e` reach
    /// [`reach`](Self::reach) beyond its line. A vertex across such a seam, within the reach and
    /// inside this piece's other lines, is in the covering piece *under this one*, and this
    /// piece's surface lines hold it there too (the concave corner's second face).
    pub across: u128,
    /// `(e, r)` for each seam `e` of [`across`](Self::across): how far (m) the covering pieces
    /// extend beyond the seam's line (the least, over them, of their extent behind it). Built
    /// with the world, only read in a step.
    pub reach: Vec<(u32, f64)>,
}

impl Collider {
    /// A collider for body `body` with shape `local` (body frame), placed at `pose`.
    pub fn new(body: usize, dynamic: bool, local: ConvexPolygon, pose: &Pose) -> Self {
        let n = local.len();
        let mut c = Self {
            body,
            dynamic,
            local,
            world: vec![Vec2::ZERO; 2 * n],
            aabb: Aabb::EMPTY,
            seams: 0,
            across: 0,
            reach: Vec::new(),
        };
        c.update(pose);
        c
    }

    /// Recomputes the world-frame features for the body pose `pose` (no allocation).
    pub fn update(&mut self, pose: &Pose) {
        self.update_with(pose, pose.rot());
    }

    /// [`Collider::update`] with the pose's rotation already computed (one `sin_cos` per body).
    pub fn update_with(&mut self, pose: &Pose, rot: Rot) {
        let mut aabb = Aabb::EMPTY;
        let local = (self.local.vertices(), self.local.normals());
        let (world_vertices, world_normals) = self.world.split_at_mut(local.0.len());
        let world = world_vertices.iter_mut().zip(world_normals.iter_mut());
        for ((v, n), (wv, wn)) in local.0.iter().zip(local.1).zip(world) {
            *wv = pose.pos + rot.apply(*v);
            *wn = rot.apply(*n);
            aabb.grow(*wv);
        }
        self.aabb = aabb;
    }

    /// Vertices in world coordinates (m), counter-clockwise.
    #[inline]
    pub fn world_vertices(&self) -> &[Vec2] {
        &self.world[..self.local.len()]
    }

    /// Outward unit edge normals in world coordinates.
    #[inline]
    pub fn world_normals(&self) -> &[Vec2] {
        &self.world[self.local.len()..]
    }

    /// The unit tangent of edge `e` in world coordinates, `(−n_y, n_x)` of its outward normal:
    /// exactly the rotated polygon tangent (normals are `(t_y, −t_x)`, and a rotation keeps that
    /// relation bit for bit; only the sign of an exact zero can differ).
    #[inline]
    pub fn world_tangent(&self, e: usize) -> Vec2 {
        let n = self.world_normals()[e];
        Vec2::new(-n.y, n.x)
    }

    /// Whether edge `e` is a seam (an internal edge of a multi-piece body, `seam.rs`).
    #[inline(always)]
    pub fn is_seam(&self, e: usize) -> bool {
        e < 128 && (self.seams >> e) & 1 == 1
    }

    /// How far (m) the covering pieces extend beyond seam `e` (0 unless `e` is in
    /// [`across`](Self::across)).
    #[inline]
    pub fn reach(&self, e: usize) -> f64 {
        if e >= 128 || (self.across >> e) & 1 == 0 {
            return 0.0;
        }
        self.reach
            .iter()
            .find(|&&(f, _)| f as usize == e)
            .map_or(0.0, |&(_, r)| r)
    }

    /// The largest [`reach`](Self::reach) of its seams (m; 0 without `across` seams).
    #[inline]
    pub fn max_reach(&self) -> f64 {
        self.reach.iter().fold(0.0f64, |m, &(_, r)| m.max(r))
    }

    /// Whether the box `aabb` (world) reaches beyond the line of one of the
    /// [`across`](Self::across) seams (a vertex inside it can be across that seam). False
    /// without such seams.
    pub fn beyond_across(&self, aabb: &Aabb) -> bool {
        self.across != 0
            && self.reach.iter().any(|&(e, _)| {
                let (n, v) = (
                    self.world_normals()[e as usize],
                    self.world_vertices()[e as usize],
                );
                // The box's support along the seam's outward normal.
                let far = Vec2::new(
                    if n.x >= 0.0 { aabb.max.x } else { aabb.min.x },
                    if n.y >= 0.0 { aabb.max.y } else { aabb.min.y },
                );
                n.dot(far - v) > 0.0
            })
    }

    /// The edge range of edge `e` (m, edge coordinates, before any `ε_s`): `[0, L]`, extended
    /// at an end where the edge meets an [`across`](Self::across) seam by that seam's reach
    /// (the face continues into the covering piece under this one).
    #[inline]
    pub fn edge_range(&self, e: usize) -> (f64, f64) {
        let len = self.local.lengths()[e];
        if self.across == 0 {
            return (0.0, len);
        }
        (
            -self.reach(self.local.prev(e)),
            len + self.reach(self.local.next(e)),
        )
    }

    /// Whether world point `p` is outside this piece only across [`across`](Self::across) seams,
    /// each within its reach (so inside the piece under it), and inside or on every other line:
    /// `Some(d)` with `d` the largest of the other lines' distances, `None` otherwise.
    pub fn across_seam(&self, p: Vec2) -> Option<f64> {
        if self.across == 0 {
            return None;
        }
        let (mut out, mut max_d) = (false, f64::NEG_INFINITY);
        for e in 0..self.len() {
            let d = self.edge_distance(e, p);
            if self.is_seam(e) {
                if d > 0.0 {
                    if d > self.reach(e) {
                        return None;
                    }
                    out = true;
                }
            } else {
                max_d = max_d.max(d);
            }
        }
        (out && max_d <= 0.0).then_some(max_d)
    }

    /// Number of vertices (= edges).
    #[inline]
    pub fn len(&self) -> usize {
        self.local.len()
    }

    /// Always false.
    #[inline]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Signed distance `d = n_e·(p − E0_e)` of world point `p` from the line of edge `e` (m), positive outside.
    #[inline]
    pub fn edge_distance(&self, e: usize, p: Vec2) -> f64 {
        self.world_normals()[e].dot(p - self.world_vertices()[e])
    }

    /// Edge coordinate `s = t_e·(p − E0_e)` of world point `p` along edge `e` (m).
    #[inline]
    pub fn edge_coordinate(&self, e: usize, p: Vec2) -> f64 {
        self.world_tangent(e).dot(p - self.world_vertices()[e])
    }
}
