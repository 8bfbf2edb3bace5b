//! A log-linear histogram of `u64` samples (nanoseconds), allocation-free
//! after construction.
//!
//! Layout (as in HdrHistogram): values below `2^SUB_BITS = 128` have one
//! bucket each (exact). Above, each power of two `[2^m, 2^(m+1))` is split into
//! 128 equal buckets of width `2^(m−7)`. A bucket's width is therefore at most
//! 1/128 (0.78 %) of its lower bound, and reporting its midpoint errs by at most
//! 1/256 (0.39 %) relative. The whole `u64` range takes `128·58 = 7424`
//! counters (58 KiB). Recording is an index computation (`leading_zeros`) and
//! an increment.

/// log2 of the number of buckets per power of two.
pub const SUB_BITS: u32 = 7;
/// Buckets per power of two (and size of the exact range).
const SUB: u64 = 1 << SUB_BITS;
/// Total number of buckets covering `0..=u64::MAX`.
const BUCKETS: usize = (SUB as usize) * (64 - SUB_BITS as usize + 1);

/// Histogram of non-negative integer samples with ≤ 0.4 % relative error on
/// reported quantiles; exact count, sum, min and max.
#[derive(Debug, Clone)]
pub struct LogHistogram {
    counts: Box<[u64]>,
    count: u64,
    sum: u128,
    min: u64,
    max: u64,
}

impl Default for LogHistogram {
    fn default() -> Self {
        Self::new()
    }
}

impl LogHistogram {
    /// An empty histogram (allocates its 7424 counters once).
    pub fn new() -> Self {
        Self {
            counts: vec![0; BUCKETS].into_boxed_slice(),
            count: 0,
            sum: 0,
            min: u64::MAX,
            max: 0,
        }
    }

    /// Bucket index of `v`.
    #[inline]
    pub fn bucket_index(v: u64) -> usize {
        if v < SUB {
            v as usize
        } else {
            let msb = 63 - v.leading_zeros();
            let shift = msb - SUB_BITS;
            (SUB as usize) * (shift as usize + 1) + ((v >> shift) - SUB) as usize
        }
    }

    /// Inclusive value range `(lo, hi)` of bucket `index`.
    pub fn bucket_bounds(index: usize) -> (u64, u64) {
        let sub = SUB as usize;
        if index < sub {
            (index as u64, index as u64)
        } else {
            let shift = (index / sub - 1) as u32;
            let lo = (SUB + (index % sub) as u64) << shift;
            (lo, lo + ((1u64 << shift) - 1))
        }
    }

    /// Records one sample. Never allocates.
    #[inline]
    pub fn record(&mut self, v: u64) {
        self.counts[Self::bucket_index(v)] += 1;
        self.count += 1;
        self.sum += v as u128;
        self.min = self.min.min(v);
        self.max = self.max.max(v);
    }

    /// Forgets all samples (keeps the storage).
    pub fn clear(&mut self) {
        self.counts.fill(0);
        self.count = 0;
        self.sum = 0;
        self.min = u64::MAX;
        self.max = 0;
    }

    /// Number of samples.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Smallest sample (exact), `None` when empty.
    pub fn min(&self) -> Option<u64> {
        (self.count > 0).then_some(self.min)
    }

    /// Largest sample (exact), `None` when empty.
    pub fn max(&self) -> Option<u64> {
        (self.count > 0).then_some(self.max)
    }

    /// Mean of the samples (exact sum divided by count), `None` when empty.
    pub fn mean(&self) -> Option<f64> {
        (self.count > 0).then(|| self.sum as f64 / self.count as f64)
    }

    /// The `q`-quantile (`q` in [0, 1], e.g. 0.999 for p99.9) by the
    /// nearest-rank rule: the smallest sample `v` such that at least
    /// `⌈q·n⌉` samples are ≤ `v`. Reported as the midpoint of `v`'s bucket,
    /// clamped to the exact [min, max]; `q ≥ 1` gives the exact max.
    /// `q` is rounded to parts per million so that `0.999·1000` is exactly
    /// rank 999. `None` when empty.
    pub fn quantile(&self, q: f64) -> Option<u64> {
        if self.count == 0 {
            return None;
        }
        let ppm = (q.clamp(0.0, 1.0) * 1e6).round() as u128;
        if ppm >= 1_000_000 {
            return Some(self.max);
        }
        // rank = ceil(ppm·n / 1e6), at least 1 (integer arithmetic, exact).
        let rank = ((ppm * self.count as u128).div_ceil(1_000_000) as u64).max(1);
        let mut seen = 0u64;
        for (i, &c) in self.counts.iter().enumerate() {
            seen += c;
            if seen >= rank {
                let (lo, hi) = Self::bucket_bounds(i);
                let mid = lo + (hi - lo) / 2;
                return Some(mid.clamp(self.min, self.max));
            }
        }
        Some(self.max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buckets_tile_the_range_with_bounded_width() {
        let mut prev_hi: Option<u64> = None;
        for i in 0..BUCKETS {
            let (lo, hi) = LogHistogram::bucket_bounds(i);
            if let Some(p) = prev_hi {
                assert_eq!(lo, p + 1, "bucket {i} does not follow the previous one");
            }
            assert!(
                (hi - lo) as f64 <= lo as f64 / SUB as f64,
                "bucket {i} too wide"
            );
            assert_eq!(LogHistogram::bucket_index(lo), i);
            assert_eq!(LogHistogram::bucket_index(hi), i);
            prev_hi = Some(hi);
        }
        assert_eq!(prev_hi, Some(u64::MAX));
    }

    #[test]
    fn empty_histogram_reports_none() {
        let h = LogHistogram::new();
        assert_eq!(h.quantile(0.5), None);
        assert_eq!(h.max(), None);
        assert_eq!(h.mean(), None);
    }
}
