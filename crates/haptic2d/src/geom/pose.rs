//! Rigid poses `(c, θ)` and rotations.

use super::Vec2;

/// A planar rotation stored as `(cos θ, sin θ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rot {
    /// cos θ.
    pub c: f64,
    /// sin θ.
    pub s: f64,
}

impl Rot {
    /// The rotation by `angle` (rad), from [`sin_cos`](super::sin_cos) (the same bits on every
    /// platform for `|angle| < 2¹⁹·π/2`, about 8·10⁵ rad).
    #[inline]
    pub fn new(angle: f64) -> Self {
        let (s, c) = super::sin_cos(angle);
        Self { c, s }
    }
    /// The identity rotation.
    pub const IDENTITY: Rot = Rot { c: 1.0, s: 0.0 };
    /// `R(θ)·v`.
    #[inline]
    pub fn apply(self, v: Vec2) -> Vec2 {
        Vec2::new(self.c * v.x - self.s * v.y, self.s * v.x + self.c * v.y)
    }
    /// `R(θ)ᵀ·v`.
    #[inline]
    pub fn apply_inv(self, v: Vec2) -> Vec2 {
        Vec2::new(self.c * v.x + self.s * v.y, -self.s * v.x + self.c * v.y)
    }
}

/// The pose of a body frame in the world: origin `pos` (m) and orientation `angle` (rad, unwrapped).
///
/// For a body the origin is its centre of mass. A body-frame point `ρ` is at `pos + R(angle)·ρ` (§0.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Origin of the frame in world coordinates (m).
    pub pos: Vec2,
    /// Orientation (rad), unwrapped: it may exceed ±π.
    pub angle: f64,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// The identity pose.
    pub const IDENTITY: Pose = Pose {
        pos: Vec2::ZERO,
        angle: 0.0,
    };
    /// A pose at `(x, y)` m with orientation `angle` rad.
    pub fn new(x: f64, y: f64, angle: f64) -> Self {
        Self {
            pos: Vec2::new(x, y),
            angle,
        }
    }
    /// The rotation part.
    #[inline]
    pub fn rot(&self) -> Rot {
        Rot::new(self.angle)
    }
    /// Maps a frame-local point to world coordinates.
    #[inline]
    pub fn transform_point(&self, p: Vec2) -> Vec2 {
        self.pos + self.rot().apply(p)
    }
    /// Maps a world point to frame-local coordinates.
    #[inline]
    pub fn inverse_transform_point(&self, p: Vec2) -> Vec2 {
        self.rot().apply_inv(p - self.pos)
    }
    /// The equivalent parry pose (for queries and oracles).
    pub fn to_parry(&self) -> parry2d_f64::math::Pose {
        parry2d_f64::math::Pose::new(self.pos, self.angle)
    }
}
