//! Encoder quantisation (§10.7): 4000 counts per motor revolution times the reduction `n_g`.

/// An incremental joint encoder referred to the joint: resolution `2π/(counts_per_rev·n_g)` rad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Encoder {
    /// Joint angle per count (rad).
    pub resolution: f64,
}

impl Encoder {
    /// An encoder with `counts_per_rev` counts per motor revolution (counts) behind reduction `n_g`.
    pub fn new(counts_per_rev: f64, n_g: f64) -> Self {
        Self {
            resolution: std::f64::consts::TAU / (counts_per_rev * n_g),
        }
    }

    /// The count for joint angle `q` (rad): rounded to the nearest count (the reading is the centre
    /// of its count cell, so quantisation error is at most half a count and unbiased).
    #[inline]
    pub fn count(&self, q: f64) -> i64 {
        (q / self.resolution).round() as i64
    }

    /// Joint angle (rad) of a count.
    #[inline]
    pub fn angle(&self, count: i64) -> f64 {
        count as f64 * self.resolution
    }

    /// The quantised reading of `q` (rad): `angle(count(q))`.
    #[inline]
    pub fn quantize(&self, q: f64) -> f64 {
        self.angle(self.count(q))
    }
}
