//! A preallocated table of per-message values indexed by sequence number, written from any thread
//! (a receiver thread, zenoh's callback) without locks or allocation, read once the run is over.

use std::sync::atomic::{AtomicU64, Ordering};

/// Marks a slot nothing was recorded in.
const EMPTY: u64 = u64::MAX;

/// One value (ns) per sequence number `1..=n`.
pub struct Slots {
    v: Vec<AtomicU64>,
}

impl Slots {
    /// A table for sequence numbers `1..=n`, all empty.
    pub fn new(n: usize) -> Self {
        Self {
            v: (0..=n).map(|_| AtomicU64::new(EMPTY)).collect(),
        }
    }

    /// Records `value` (ns) for `seq`; a sequence number outside `1..=n` is ignored, and so is a
    /// second value for the same number (a duplicate keeps the first). Returns whether it was kept.
    #[inline]
    pub fn record(&self, seq: u32, value: u64) -> bool {
        match self.v.get(seq as usize) {
            Some(s) if seq > 0 => s
                .compare_exchange(EMPTY, value, Ordering::Relaxed, Ordering::Relaxed)
                .is_ok(),
            _ => false,
        }
    }

    /// The recorded values in sequence order, `(seq, value)`.
    pub fn recorded(&self) -> Vec<(u32, u64)> {
        self.v
            .iter()
            .enumerate()
            .skip(1)
            .filter_map(|(i, s)| {
                let x = s.load(Ordering::Relaxed);
                (x != EMPTY).then_some((i as u32, x))
            })
            .collect()
    }

    /// The recorded values alone, in sequence order.
    pub fn values(&self) -> Vec<u64> {
        self.recorded().into_iter().map(|(_, x)| x).collect()
    }
}

/// The intervals between the times of consecutive sequence numbers that were both recorded
/// (`t[k] − t[k−1]`, saturating at 0 for a reordered pair): the arrival spacing (ns).
pub fn intervals(times: &[(u32, u64)]) -> Vec<u64> {
    times
        .windows(2)
        .filter(|w| w[1].0 == w[0].0 + 1)
        .map(|w| w[1].1.saturating_sub(w[0].1))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slot_keeps_its_first_value_and_out_of_range_numbers_are_ignored() {
        let s = Slots::new(3);
        assert!(s.record(2, 20));
        assert!(!s.record(2, 21));
        assert!(!s.record(0, 1));
        assert!(!s.record(4, 1));
        assert!(s.record(3, 35));
        assert_eq!(s.recorded(), vec![(2, 20), (3, 35)]);
    }

    #[test]
    fn intervals_span_only_consecutive_numbers() {
        // 1 → 2: 1000; 2 → 4 is a gap (3 lost): skipped; 4 → 5: 900.
        let t = [(1, 5_000), (2, 6_000), (4, 8_100), (5, 9_000)];
        assert_eq!(intervals(&t), vec![1000, 900]);
    }
}
