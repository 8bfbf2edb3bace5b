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
