//! Order statistics of a run's samples (nanoseconds): count, min, the nearest-rank percentiles
//! p50, p90, p99, p99.9, and max.
//!
//! Nearest rank: the q-quantile of n sorted samples is the sample of rank ⌈q·n⌉ (1-based, at least
//! 1), so every reported value is one that was measured. q is given in tenths of a percent
//! (p99.9 = 999) and the rank computed in integers, so no rounding of a float decides a rank.

/// The summary of one series of samples (all times in nanoseconds).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Summary {
    /// Number of samples.
    pub count: usize,
    /// Smallest sample (ns).
    pub min: u64,
    /// Median, nearest rank (ns).
    pub p50: u64,
    /// 90th percentile, nearest rank (ns).
    pub p90: u64,
    /// 99th percentile, nearest rank (ns).
    pub p99: u64,
    /// 99.9th percentile, nearest rank (ns).
    pub p999: u64,
    /// Largest sample (ns).
    pub max: u64,
}

/// The 1-based nearest rank of the quantile `tenths_of_percent / 1000` among `n` samples:
/// ⌈tenths·n / 1000⌉, at least 1 (`n` > 0).
pub fn nearest_rank(tenths_of_percent: u64, n: usize) -> usize {
    let r = (tenths_of_percent as u128 * n as u128).div_ceil(1000) as usize;
    r.max(1)
}

/// Sorts `samples` in place and summarises them; `None` for an empty series.
pub fn summarize(samples: &mut [u64]) -> Option<Summary> {
    if samples.is_empty() {
        return None;
    }
    samples.sort_unstable();
    let n = samples.len();
    let at = |q| samples[nearest_rank(q, n) - 1];
    Some(Summary {
        count: n,
        min: samples[0],
        p50: at(500),
        p90: at(900),
        p99: at(990),
        p999: at(999),
        max: samples[n - 1],
    })
}

/// The header of [`row`]'s table (values in microseconds).
pub const HEADER: &str =
    "                                count     min     p50     p90     p99   p99.9     max   (µs)";

/// One table row: `label`, then the summary in microseconds with one decimal (or "no samples").
pub fn row(label: &str, s: Option<Summary>) -> String {
    let us = |ns: u64| ns as f64 / 1e3;
    match s {
        None => format!("  {label:<28} no samples"),
        Some(s) => format!(
            "  {label:<28} {:>5} {:>7.1} {:>7.1} {:>7.1} {:>7.1} {:>7.1} {:>7.1}",
            s.count,
            us(s.min),
            us(s.p50),
            us(s.p90),
            us(s.p99),
            us(s.p999),
            us(s.max)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_percentiles_of_one_to_a_thousand_are_the_ranks_themselves() {
        // 1..=1000 in a scrambled order (multiplying by 7 mod 1009 permutes 1..=1008; keep ≤ 1000).
        let mut v: Vec<u64> = (1..=1008u64)
            .map(|i| i * 7 % 1009)
            .filter(|&x| x <= 1000)
            .collect();
        assert_eq!(v.len(), 1000);
        // Nearest rank of q among 1000: ⌈q·1000⌉ = 500, 900, 990, 999; the sample of rank r is r.
        let s = summarize(&mut v).unwrap();
        assert_eq!(
            s,
            Summary {
                count: 1000,
                min: 1,
                p50: 500,
                p90: 900,
                p99: 990,
                p999: 999,
                max: 1000
            }
        );
    }

    #[test]
    fn the_percentiles_of_ten_samples_round_the_rank_up() {
        // Sorted: 10 20 30 40 50 60 70 80 90 1000. Ranks: p50 ⌈5⌉ = 5 → 50; p90 ⌈9⌉ = 9 → 90;
        // p99 ⌈9.9⌉ = 10 → 1000; p99.9 ⌈9.99⌉ = 10 → 1000.
        let mut v = vec![1000, 30, 10, 90, 20, 80, 40, 70, 50, 60];
        let s = summarize(&mut v).unwrap();
        assert_eq!(
            s,
            Summary {
                count: 10,
                min: 10,
                p50: 50,
                p90: 90,
                p99: 1000,
                p999: 1000,
                max: 1000
            }
        );
    }

    #[test]
    fn one_sample_is_every_percentile_and_none_is_no_summary() {
        let s = summarize(&mut [42]).unwrap();
        assert_eq!((s.min, s.p50, s.p999, s.max, s.count), (42, 42, 42, 42, 1));
        assert_eq!(summarize(&mut []), None);
    }

    #[test]
    fn the_nearest_rank_of_ten_thousand_samples() {
        // 10 000 samples (the default run): p50 → 5000, p90 → 9000, p99 → 9900, p99.9 → 9990.
        assert_eq!(nearest_rank(500, 10_000), 5000);
        assert_eq!(nearest_rank(900, 10_000), 9000);
        assert_eq!(nearest_rank(990, 10_000), 9900);
        assert_eq!(nearest_rank(999, 10_000), 9990);
        // 9 999 samples: ⌈0.999 · 9999⌉ = ⌈9989.001⌉ = 9990.
        assert_eq!(nearest_rank(999, 9_999), 9990);
        assert_eq!(nearest_rank(0, 5), 1);
    }

    #[test]
    fn a_row_prints_microseconds() {
        let s = Summary {
            count: 3,
            min: 1500,
            p50: 2000,
            p90: 2500,
            p99: 2500,
            p999: 2500,
            max: 10_240,
        };
        let r = row("round trip", Some(s));
        assert!(
            r.contains("    3     1.5     2.0     2.5     2.5     2.5    10.2"),
            "{r}"
        );
        assert!(row("x", None).contains("no samples"));
    }
}
