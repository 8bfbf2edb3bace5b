//! Axis-aligned bounding boxes.

use super::Vec2;

/// An axis-aligned bounding box (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner (m).
    pub min: Vec2,
    /// Upper corner (m).
    pub max: Vec2,
}

impl Aabb {
    /// An empty box that any `grow` replaces.
    pub const EMPTY: Aabb = Aabb {
        min: Vec2::new(f64::INFINITY, f64::INFINITY),
        max: Vec2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    };
    /// The box of a set of points.
    pub fn from_points(points: &[Vec2]) -> Self {
        let mut b = Self::EMPTY;
        for p in points {
            b.grow(*p);
        }
        b
    }
    /// Extends the box to contain `p`.
    #[inline]
    pub fn grow(&mut self, p: Vec2) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    /// The box enlarged by `margin` (m) on every side.
    #[inline]
    pub fn inflated(&self, margin: f64) -> Self {
        Self {
            min: self.min - Vec2::splat(margin),
            max: self.max + Vec2::splat(margin),
        }
    }
    /// True if the two (closed) boxes overlap.
    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        self.min.x <= o.max.x
            && o.min.x <= self.max.x
            && self.min.y <= o.max.y
            && o.min.y <= self.max.y
    }
}
