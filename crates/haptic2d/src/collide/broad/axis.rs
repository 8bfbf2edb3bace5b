//! The sweep axis (issue 42): each update sweeps along x or along y, whichever meets fewer boxes.
//!
//! A box of the sweep is tested against every box that starts before it ends along the sweep
//! axis (its run); the other axis then rejects most of them (`sweep.rs`). On pile:1000 (25
//! columns of 40 boxes, 1.4 m wide, about 2.3 m tall; inflated boxes 0.092 m wide, more than the
//! 0.056 m pitch) a sweep along x meets the rest of the box's column and all of the next one
//! (about 60 boxes), a sweep along y the rest of its row and the next row (about 37).
//!
//! # The choice
//!
//! With `n` boxes spread over an extent `E` along an axis, a box of length `w` along it meets
//! about `n·w/E` boxes that start within it, so the run summed over the boxes is about
//! `n·Σw/E`. [`sweep_axis`] takes the axis with the smaller `Σw/E` (y only when strictly
//! smaller: `Σh·E_x < Σw·E_y`, no division; x on a tie or a NaN), from the inflated boxes of the
//! update (one pass, in collider order).
//!
//! # Why the result does not depend on it
//!
//! The entries of a sweep along y are the boxes with their axes exchanged
//! ([`SweepEntry::along`]); the sweep reads only the entries, so it meets every pair of boxes that
//! overlap in both axes exactly once whichever axis it runs along (boxes overlap when their
//! intervals overlap on both axes, a symmetric test). Each pair's GJK distance depends only on
//! its two colliders' vertices and its own cache, and the result is published in pair order
//! (`publish.rs`), so the pairs, distances, caches and the set are the same, bit for bit. Only
//! the skip certificate (`skip.rs`) is made along the chosen axes: its gap is then the smallest
//! separation of unpaired boxes measured across the sweep within a run and along it beyond, which
//! bounds the boxes' motion by the same argument with the axes exchanged.

use super::*;

/// The axis a sweep runs along.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum Axis {
    /// Along x (the entries are the boxes as they are).
    #[default]
    X,
    /// Along y (the entries are the boxes with x and y exchanged).
    Y,
}

/// The axis along which a sweep of the boxes of `colliders` inflated by `half` (m) on every side
/// meets fewer boxes (see the module's doc): y when `Σh·E_x < Σw·E_y` (widths `w`, heights `h`
/// and extents `E` of the inflated boxes, m), x otherwise (also on a tie, with no colliders, or
/// with a NaN).
pub(super) fn sweep_axis(colliders: &[Collider], half: f64) -> Axis {
    let (mut lo, mut hi) = (Vec2::splat(f64::INFINITY), Vec2::splat(f64::NEG_INFINITY));
    let (mut widths, mut heights) = (0.0, 0.0);
    for c in colliders {
        let b = c.aabb.inflated(half);
        lo = Vec2::new(lo.x.min(b.min.x), lo.y.min(b.min.y));
        hi = Vec2::new(hi.x.max(b.max.x), hi.y.max(b.max.y));
        widths += b.max.x - b.min.x;
        heights += b.max.y - b.min.y;
    }
    let (extent_x, extent_y) = (hi.x - lo.x, hi.y - lo.y);
    if heights * extent_x < widths * extent_y {
        Axis::Y
    } else {
        Axis::X
    }
}

impl SweepEntry {
    /// The entry of collider `i`, `c`, with box `bx` (m) for a sweep along `axis`: `min_x`,
    /// `max_x` the box's interval along the axis, `min_y`, `max_y` across it.
    pub(super) fn along(i: usize, c: &Collider, bx: Aabb, axis: Axis) -> Self {
        match axis {
            Axis::X => SweepEntry::of(i, c, bx),
            Axis::Y => {
                let swapped = Aabb {
                    min: Vec2::new(bx.min.y, bx.min.x),
                    max: Vec2::new(bx.max.y, bx.max.x),
                };
                SweepEntry::of(i, c, swapped)
            }
        }
    }
}
