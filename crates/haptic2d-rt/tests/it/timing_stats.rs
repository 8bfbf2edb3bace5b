//! Percentiles of the timing statistics on synthetic data, against exact
//! nearest-rank values computed by sorting.

use haptic2d_rt::histogram::LogHistogram;
use haptic2d_rt::TimingStats;

/// Exact nearest-rank quantile of `sorted` (rank ⌈q·n⌉, at least 1).
fn exact_quantile(sorted: &[u64], q: f64) -> u64 {
    let n = sorted.len() as f64;
    let rank = ((q * n) - 1e-9).ceil().max(1.0) as usize;
    sorted[rank.min(sorted.len()) - 1]
}

/// The histogram's quantile is within its documented 0.4 % of the exact one.
fn assert_close(h: &LogHistogram, sorted: &[u64], q: f64) {
    let got = h.quantile(q).unwrap() as f64;
    let want = exact_quantile(sorted, q) as f64;
    let rel = (got - want).abs() / want.max(1.0);
    assert!(
        rel <= 1.0 / 256.0,
        "q = {q}: got {got}, exact {want}, rel {rel}"
    );
}

#[test]
fn uniform_ramp_percentiles_match_exact_nearest_rank() {
    // 1 µs … 100 ms in 1 µs steps, shuffled order does not matter.
    let values: Vec<u64> = (1..=100_000u64).map(|k| k * 1000).collect();
    let mut h = LogHistogram::new();
    for &v in values.iter().rev() {
        h.record(v);
    }
    for q in [0.0, 0.01, 0.5, 0.9, 0.99, 0.999, 0.9999] {
        assert_close(&h, &values, q);
    }
    assert_eq!(h.quantile(1.0), Some(100_000_000));
    assert_eq!(h.max(), Some(100_000_000));
    assert_eq!(h.min(), Some(1000));
    // Exact mean: 1000 · (n + 1) / 2.
    assert_eq!(h.mean(), Some(50_000_500.0));
}

#[test]
fn rare_outliers_show_in_p999_only_when_above_one_in_a_thousand() {
    let mut h = LogHistogram::new();
    for _ in 0..999 {
        h.record(10);
    }
    h.record(1_000_000);
    // Rank ⌈0.999·1000⌉ = 999: still a 10.
    assert_eq!(h.quantile(0.999), Some(10));
    assert_eq!(h.max(), Some(1_000_000));
    h.clear();
    for _ in 0..998 {
        h.record(10);
    }
    h.record(1_000_000);
    h.record(1_000_000);
    // Rank 999 now falls on an outlier (reported within 0.4 %).
    let p = h.quantile(0.999).unwrap() as f64;
    assert!((p - 1e6).abs() / 1e6 <= 1.0 / 256.0, "{p}");
    assert_eq!(h.quantile(0.99), Some(10));
}

#[test]
fn pseudo_random_lognormal_like_data_matches_sorted_quantiles() {
    // Deterministic xorshift; values spread over 6 decades like real latencies.
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    let mut values = Vec::with_capacity(50_000);
    let mut h = LogHistogram::new();
    for _ in 0..50_000 {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let u = (s >> 11) as f64 / (1u64 << 53) as f64;
        let v = (10f64.powf(1.0 + 6.0 * u * u)) as u64;
        values.push(v);
        h.record(v);
    }
    values.sort_unstable();
    for q in [0.5, 0.9, 0.99, 0.999] {
        assert_close(&h, &values, q);
    }
    assert_eq!(h.max(), values.last().copied());
}

#[test]
fn timing_stats_count_on_time_overruns_and_skips_per_definition() {
    // Period 1000 ns: on time ⇔ lateness ≤ 100 ns; overrun ⇔ lateness + compute > 1000 ns.
    let mut st = TimingStats::new(1e6, 1000);
    let mut deadline = 1_000_000u64;
    // (lateness, compute) per tick.
    let ticks = [(0, 200), (100, 850), (101, 10), (50, 1000), (2000, 5)];
    for (lat, comp) in ticks {
        st.record_tick(deadline, deadline + lat, deadline + lat + comp);
        deadline += 1000;
    }
    st.record_skipped(3);
    let s = st.summary(None);
    assert_eq!(s.ticks, 5);
    assert_eq!(s.skipped, 3);
    assert_eq!(s.deadlines, 8);
    assert_eq!(s.on_time, 3); // lateness 0, 100, 50
    assert!((s.on_time_fraction - 3.0 / 8.0).abs() < 1e-12);
    assert_eq!(s.overruns, 2); // 50 + 1000 and 2000 + 5
    assert!((s.lateness_us.max - 2.0).abs() < 1e-12);
    assert!((s.compute_us.max - 1.0).abs() < 1e-12);
    assert!((s.lateness_us.mean - 2251.0 / 5.0 * 1e-3).abs() < 1e-12);
    // Wakes at 1_000_000, 1_001_100, 1_002_101, 1_003_050, 1_006_000.
    let want_rate = 4.0 / (6000.0 * 1e-9);
    assert!((s.achieved_rate_hz - want_rate).abs() / want_rate < 1e-12);
    let text = s.to_string();
    for key in [
        "achieved", "lateness", "p50", "p99", "p99.9", "max", "compute", "overruns",
    ] {
        assert!(text.contains(key), "summary lacks `{key}`: {text}");
    }
}
