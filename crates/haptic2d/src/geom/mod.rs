//! Planar geometry: vectors, poses, convex polygons and their features, AABBs and mass properties.

mod aabb;
mod mass;
mod polygon;
mod pose;
mod trig;

pub use aabb::Aabb;
pub use mass::MassProperties;
pub use polygon::{ConvexPolygon, PolygonError};
pub use pose::{Pose, Rot};
pub use trig::sin_cos;

/// A 2-D vector of `f64` (glam's `DVec2`, as re-exported by parry2d-f64). Units depend on use (m, m/s, N).
pub type Vec2 = parry2d_f64::math::Vector;

/// Scalar cross product `a × b = a_x b_y − a_y b_x` (§0.3).
#[inline]
pub fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The larger of `x` and `y` as one compare-select (`maxsd`): `x` if `x > y`, else `y` (so `y`
/// when `x` is NaN). [`f64::max`] gives the same for a `y` that is not NaN, but adds a NaN fix-up
/// that, on a maximum carried from one loop iteration to the next, lengthens every iteration's
/// dependency chain (the chain damper's sweep and the impact sweeps).
#[inline(always)]
pub fn select_max(x: f64, y: f64) -> f64 {
    if x > y {
        x
    } else {
        y
    }
}

/// The smaller of `x` and `y` as one compare-select (`minsd`): `x` if `x < y`, else `y` (so `y`
/// when `x` is NaN): [`select_max`] mirrored. A running least `m` kept as `m = select_min(d, m)`
/// never becomes NaN once it is a number.
#[inline(always)]
pub fn select_min(x: f64, y: f64) -> f64 {
    if x < y {
        x
    } else {
        y
    }
}

/// `perp(a) = (−a_y, a_x)`: `a` rotated by +90° (§0.3).
#[inline]
pub fn perp(a: Vec2) -> Vec2 {
    Vec2::new(-a.y, a.x)
}

/// Wraps an angle to `(−π, π]` (rad). Used for display and for angle differences only.
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    let mut r = a % two_pi;
    if r <= -std::f64::consts::PI {
        r += two_pi;
    } else if r > std::f64::consts::PI {
        r -= two_pi;
    }
    r
}
