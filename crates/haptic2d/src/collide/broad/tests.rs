//! Tests of the global proximity stage: the sweep against all pairs, spread and whole updates,
//! reused distances, merges and patches, and the skip certificate.

use super::*;
use crate::geom::{ConvexPolygon, Pose};

fn square(body: usize, dynamic: bool, x: f64, y: f64) -> Collider {
    Collider::new(
        body,
        dynamic,
        ConvexPolygon::rectangle(0.04, 0.04).unwrap(),
        &Pose::new(x, y, 0.0),
    )
}

#[test]
fn margin_rule_gives_default() {
    assert!((required_delta_prox(1.0, 0.02, 0.002) - DEFAULT_DELTA_PROX).abs() < 1e-15);
    assert!(BroadPhase::new(0.0).is_err());
    assert!(BroadPhase::new(f64::NAN).is_err());
}

#[test]
fn filters_and_threshold() {
    let cols = vec![
        square(0, false, 0.0, 0.0),
        square(1, false, 0.06, 0.0),  // fixed–fixed with 0: skipped
        square(2, true, 0.0, 0.081),  // 0.041 from 0: proximate
        square(2, true, 0.0, 0.0805), // same body as 2: never paired with it
        square(3, true, 0.2, 0.0),    // far from everything
        square(4, true, 0.0, -0.083), // 0.043 from 0: not proximate
    ];
    let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let mut out = Vec::new();
    bp.update(&cols, &mut out);
    assert_eq!(out, vec![(0, 2), (0, 3)]);
}

/// A jittered grid of squares, some rotated, with a fixed floor: many AABB pairs, some proximate.
fn grid(shift: f64, pitch: f64) -> Vec<Collider> {
    let mut cols = vec![Collider::new(
        0,
        false,
        ConvexPolygon::rectangle(2.0, 0.1).unwrap(),
        &Pose::new(0.0, -0.05, 0.0),
    )];
    for k in 0..120usize {
        let (i, j) = ((k % 12) as f64, (k / 12) as f64);
        let jitter = ((k * 7919) % 13) as f64 * 1e-3;
        cols.push(Collider::new(
            k + 1,
            true,
            ConvexPolygon::rectangle(0.04, 0.04).unwrap(),
            &Pose::new(
                -0.3 + i * pitch + jitter + shift,
                0.021 + j * 0.0455,
                0.1 * jitter * k as f64,
            ),
        ));
    }
    cols
}

/// A seeded xorshift generator of uniform numbers in `[0, 1)`.
pub(super) fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut rng = seed;
    move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// One update of `bp` for `cols` with odometers `odo` (m), its sweep along `axis` whatever
/// [`sweep_axis`] would choose: `begin`'s sweep rebuilt along `axis`, then published.
pub(super) fn update_along(
    bp: &mut BroadPhase,
    cols: &[Collider],
    odo: &[f64],
    axis: Axis,
) -> Vec<(u32, u32)> {
    bp.begin_with_motion(cols, odo);
    let half = 0.5 * bp.delta_prox;
    bp.sweep.clear();
    for (i, c) in cols.iter().enumerate() {
        bp.sweep
            .push(SweepEntry::along(i, c, c.aabb.inflated(half), axis));
    }
    bp.sweep.sort_unstable_by(sweep_order);
    bp.axis = axis;
    let mut out = Vec::new();
    bp.publish(&mut out);
    out
}

/// The sweep pairs exactly the colliders whose inflated boxes overlap (closed), once each,
/// leaving out same-body and fixed–fixed pairs, against a test of every pair: random scenes
/// from 1 to 400 colliders, some stacked in narrow columns so that a box's x run is longer
/// than one or two of the sweep's 64-box blocks, some touching exactly, some sharing a body;
/// with the certificate's bookkeeping and without it, and along x whatever axis is chosen.
#[test]
fn the_sweep_pairs_every_overlapping_pair_once() {
    let mut next = uniform(0x2545_f491_4f6c_dd1du64);
    let half = 0.5 * DEFAULT_DELTA_PROX;
    let (mut longest_run, mut plain_updates) = (0, 0);
    for trial in 0..300 {
        let n = 1 + (400.0 * next() * next()) as usize;
        let columns = 1 + (6.0 * next()) as usize;
        let (mut cols, mut poses) = (Vec::new(), Vec::new());
        for i in 0..n {
            let body = if next() < 0.1 && i > 0 { i - 1 } else { i };
            let dynamic = next() < 0.8;
            let (w, h) = (0.01 + 0.05 * next(), 0.01 + 0.05 * next());
            let pose = if trial % 3 == 0 {
                Pose::new(next(), next(), 6.0 * next())
            } else {
                // A column: the same x up to a little jitter, rows 0.03 m apart, so that
                // neighbours overlap and boxes two rows apart do not; every 7th exactly on
                // the row above's edge.
                let c = (i % columns) as f64 * 0.2;
                let jitter = if i % 7 == 0 { 0.0 } else { 0.004 * next() };
                Pose::new(c + jitter, 0.03 * (i / columns) as f64, 0.0)
            };
            let shape = ConvexPolygon::rectangle(w, h).unwrap();
            cols.push(Collider::new(body, dynamic, shape, &pose));
            poses.push(pose);
        }
        let mut want = Vec::new();
        for a in 0..n {
            let run = (a + 1..n)
                .filter(|&b| {
                    let (p, q) = (cols[a].aabb.inflated(half), cols[b].aabb.inflated(half));
                    p.min.x <= q.max.x && q.min.x <= p.max.x
                })
                .count();
            longest_run = longest_run.max(run);
            for b in a + 1..n {
                let (ca, cb) = (&cols[a], &cols[b]);
                let overlap = ca.aabb.inflated(half).overlaps(&cb.aabb.inflated(half));
                let filtered = ca.body == cb.body || !(ca.dynamic || cb.dynamic);
                if overlap && !filtered {
                    want.push((a as u32, b as u32));
                }
            }
        }
        // The sweep with the certificate's bookkeeping (a first update), and without it
        // (an update after a failed skip check, which backs off from certifying).
        let mut certifying = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        certifying.update(&cols, &mut Vec::new());
        assert!(certifying.certificate.is_some());
        assert_eq!(
            certifying.tested_pairs().0,
            &want[..],
            "trial {trial}, {n} boxes"
        );
        // Swept along x whatever the layout (tall column worlds choose y), so that x runs
        // over several blocks are swept too.
        let mut along_x = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        update_along(&mut along_x, &cols, &[], Axis::X);
        assert_eq!(along_x.tested_pairs().0, &want[..], "trial {trial}, x");
        let mut plain = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        plain.update(&cols, &mut Vec::new());
        let moved: Vec<Collider> = cols
            .iter()
            .zip(&poses)
            .map(|(c, p)| {
                let mut c = c.clone();
                c.update(&Pose::new(p.pos.x + 0.3, p.pos.y, p.angle + 0.5));
                c
            })
            .collect();
        if !plain.skip_update(&moved) {
            plain.update(&cols, &mut Vec::new());
            plain_updates += usize::from(plain.certificate.is_none());
            assert_eq!(
                plain.tested_pairs().0,
                &want[..],
                "trial {trial}, {n} boxes"
            );
        }
    }
    assert!(longest_run > 128, "x runs over two blocks ({longest_run})");
    assert!(
        plain_updates > 200,
        "updates without the certificate: {plain_updates}"
    );
}

/// The spread update publishes exactly the set, distances, caches and counters of the whole
/// update at the poses of `begin`, whatever the poses of the colliders in between, and
/// whatever number of samples it is spread over.
#[test]
fn spread_update_equals_whole_update_at_begin() {
    let (a, b) = (grid(0.0, 0.05), grid(0.013, 0.09));
    for samples in [1usize, 2, 3, 10, 500] {
        let mut whole = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        let mut spread = whole.clone();
        let (mut out_w, mut out_s) = (Vec::new(), vec![(7, 7)]);
        // Warm both caches on `b` first, so the warm starts are exercised.
        whole.update(&b, &mut out_w);
        spread.update(&b, &mut out_s);
        whole.update(&a, &mut out_w);
        spread.begin(&a);
        for j in 0..samples {
            assert!(spread.in_progress());
            spread.advance(samples - j);
        }
        let before = out_s.clone();
        spread.publish(&mut out_s);
        assert_ne!(out_s, before, "the set of `a` differs from the set of `b`");
        assert!(!spread.in_progress());
        assert!(whole.stats().aabb_pairs > 200, "{:?}", whole.stats());
        assert_eq!(out_s, out_w, "{samples} samples");
        assert_eq!(spread.stats(), whole.stats(), "{samples} samples");
        let (pw, dw) = whole.tested_pairs();
        let (ps, ds) = spread.tested_pairs();
        assert_eq!(pw, ps);
        let bits = |d: &[f64]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(dw), bits(ds));
        // Publishing with no update in progress leaves the set alone.
        spread.publish(&mut out_s);
        assert_eq!(out_s, out_w);
    }
}

/// `advance(k)` splits the remaining boxes evenly over the first `N_g − 1` samples of the period
/// and sorts at the last one, so publish has nothing left to do but copy.
#[test]
fn advance_shares_cover_the_sweep() {
    let cols = grid(0.0, 0.05);
    let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    bp.begin(&cols);
    let mut swept = Vec::new();
    for j in 1..9 {
        bp.advance(10 - j);
        swept.push(bp.next.unwrap());
    }
    // Nine even shares of the boxes over the samples after `begin`; the last one sorts too.
    let share = cols.len().div_ceil(9);
    assert_eq!(swept[0], share);
    assert!(swept.windows(2).all(|w| w[1] - w[0] <= share));
    assert!(!bp.sorted);
    bp.advance(1);
    assert_eq!(bp.next, Some(cols.len()));
    assert!(cols.len() - swept[7] <= share);
    let pairs = bp.tested.len();
    assert!(bp.sorted && bp.order.len() == pairs && pairs > 0);
    assert!(bp.ready.pairs.windows(2).all(|w| w[0] < w[1]));
    assert_eq!(bp.ready.pairs.len(), pairs);
}

/// The warm-start lookup by first collider finds exactly the published pairs' caches.
#[test]
fn cache_lookup_finds_the_published_pairs() {
    let cols = grid(0.0, 0.05);
    let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let mut out = Vec::new();
    bp.update(&cols, &mut out);
    assert!(bp.cache_pairs.len() > 200);
    for (k, &(a, b)) in bp.cache_pairs.iter().enumerate() {
        let c = bp.cached(a, b).expect("a published pair has its cache");
        assert_eq!(c, k);
    }
    let n = cols.len() as u32;
    let tested: std::collections::BTreeSet<_> = bp.cache_pairs.iter().copied().collect();
    for a in 0..n + 2 {
        for b in a + 1..n + 2 {
            assert_eq!(
                bp.cached(a, b).is_some(),
                tested.contains(&(a, b)),
                "{a} {b}"
            );
        }
    }
}

/// GJK skipped on the pairs whose side of `δ_prox` the motion cannot have changed gives the
/// proximity set of running GJK on every pair, update after update, with bodies creeping
/// (reused) and jumping (re-tested) by turns.
#[test]
fn reused_distances_give_the_set_of_testing_every_pair() {
    let home = grid(0.0, 0.05);
    let mut cols = home.clone();
    let radius = 0.02 * 2f64.sqrt();
    let mut odometer = vec![0.0; cols.len()];
    let mut poses: Vec<Pose> = (0..cols.len()).map(|_| Pose::new(0.0, 0.0, 0.0)).collect();
    let mut fast = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let mut every: BroadPhase;
    let (mut out_fast, mut out_every) = (Vec::new(), Vec::new());
    let mut reused = 0;
    for k in 0..60u64 {
        // Every third update some bodies jump by up to 3 cm; otherwise all creep by 1 µm.
        for i in 1..cols.len() {
            let h = (i as u64 * 2654435761 + k * 40503) % 1000;
            let step = if k % 3 == 2 && h < 300 { 0.03 } else { 1e-6 };
            let u = h as f64 / 1000.0 - 0.5;
            let last = poses[i];
            let p = Pose::new(
                last.pos.x + step * u,
                last.pos.y - step * u.abs(),
                last.angle + step * u,
            );
            odometer[i] += (p.pos - last.pos).length() + (p.angle - last.angle).abs() * radius;
            poses[i] = p;
            let h0 = home[i].world_vertices()[0] - home[i].local.vertices()[0];
            cols[i].update(&Pose::new(h0.x + p.pos.x, h0.y + p.pos.y, p.angle));
        }
        fast.update_with_motion(&cols, &odometer, &mut out_fast);
        // A new stage each time: GJK on every pair and the full path.
        every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        every.update(&cols, &mut out_every);
        assert_eq!(out_fast, out_every, "update {k}");
        assert_eq!(fast.stats().aabb_pairs, every.stats().aabb_pairs);
        assert_eq!(every.stats().reused_distances, 0);
        reused += fast.stats().reused_distances;
    }
    assert!(reused > 1000, "reused {reused}");
}

/// An update whose pairs differ from the published ones merges the published pairs it met
/// again with the new ones: every pair keeps its own GJK result. Bodies jump between updates,
/// so pairs leave, join and stay; without odometers every pair runs GJK (warm-started from
/// its own cache), so each distance must be what a new stage computes for that pair now.
#[test]
fn a_merged_update_keeps_each_pair_with_its_own_distance() {
    let home = grid(0.0, 0.05);
    let mut cols = home.clone();
    let mut warm = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let (mut out_warm, mut out_cold) = (Vec::new(), Vec::new());
    let (mut left, mut joined) = (0, 0);
    let mut last: Vec<(u32, u32)> = Vec::new();
    for k in 0..40u64 {
        for i in 1..cols.len() {
            let h = (i as u64 * 2654435761 + k * 40503) % 1000;
            let u = h as f64 / 1000.0 - 0.5;
            let step = if h < 200 { 0.03 } else { 0.0 };
            let h0 = home[i].world_vertices()[0] - home[i].local.vertices()[0];
            let p = h0 + Vec2::new(step * u, -step * u.abs());
            cols[i].update(&Pose::new(p.x, p.y, step * u));
        }
        warm.update(&cols, &mut out_warm);
        let mut cold = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        cold.update(&cols, &mut out_cold);
        assert_eq!(out_warm, out_cold, "update {k}");
        let ((pw, dw), (pc, dc)) = (warm.tested_pairs(), cold.tested_pairs());
        assert_eq!(pw, pc, "update {k}");
        for ((p, a), b) in pw.iter().zip(dw).zip(dc) {
            assert!(
                (a - b).abs() <= 1e-12,
                "update {k}, pair {p:?}: {a} against {b}"
            );
        }
        left += last.iter().filter(|p| pw.binary_search(p).is_err()).count();
        joined += pw.iter().filter(|p| last.binary_search(p).is_err()).count();
        last = pw.to_vec();
    }
    assert!(left > 100 && joined > 100, "left {left}, joined {joined}");
}

/// An update that tests exactly the published pairs writes its few GJK results into the
/// published arrays in place (`BroadStats::in_place`) and publishes what a full sort would:
/// at rest (whole and spread), with a pair re-measured on the same side of `δ_prox` and one
/// that crosses it. A pair leaving the AABB test while every other is reused (a body drifting
/// away diagonally, farther than `δ_prox` throughout), or a new pair, takes the full path.
#[test]
fn an_update_testing_the_published_pairs_patches_them_in_place() {
    // Body 1 near body 2 (10 mm: proximate); body 3 diagonal to body 1, 38 mm gaps in x and
    // y: the boxes overlap (inflated by 21 mm each) but the squares are 53.7 mm apart.
    let mut cols = vec![
        square(0, false, 0.0, -1.0),
        square(1, true, 0.0, 0.0),
        square(2, true, -0.05, 0.0),
        square(3, true, 0.078, 0.078),
    ];
    let mut odometer = vec![0.0; 4];
    let mut fast = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    // The oracle: a new stage each time (no published pairs, so always the full path).
    let mut every: BroadPhase;
    let (mut out, mut out_every) = (Vec::new(), Vec::new());
    fast.update_with_motion(&cols, &odometer, &mut out);
    assert!(!fast.stats().in_place);
    let (pairs0, dist0) = (
        fast.tested_pairs().0.to_vec(),
        fast.tested_pairs().1.to_vec(),
    );
    assert_eq!(out, vec![(1, 2)]);
    assert_eq!(pairs0, vec![(1, 2), (1, 3)]);
    // At rest: in place with nothing to write, whole and spread.
    for spread in [false, true] {
        let mut o = vec![(7, 8)];
        if spread {
            fast.begin_with_motion(&cols, &odometer);
            fast.advance(3);
            fast.advance(2);
            fast.publish(&mut o);
        } else {
            fast.update_with_motion(&cols, &odometer, &mut o);
        }
        let st = fast.stats();
        assert!(st.in_place, "spread {spread}");
        assert_eq!(
            (st.aabb_pairs, st.proximate_pairs, st.gjk_iterations),
            (2, 1, 0)
        );
        assert_eq!(o, out);
        assert_eq!(fast.tested_pairs().0, pairs0.as_slice());
        assert_eq!(fast.tested_pairs().1, dist0.as_slice());
    }
    // Body 2 goes 20 mm away and 15 mm back (odometer +35 mm): its pair needs GJK and stays
    // proximate; body 3's keeps its distance.
    cols[2].update(&Pose::new(-0.055, 0.0, 0.0));
    odometer[2] += 0.035;
    fast.update_with_motion(&cols, &odometer, &mut out);
    every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    every.update(&cols, &mut out_every);
    assert!(fast.stats().in_place && fast.stats().gjk_iterations > 0);
    assert_eq!(out, out_every);
    assert_eq!(fast.tested_pairs().0, pairs0.as_slice());
    assert_eq!(fast.tested_pairs().1[0], every.tested_pairs().1[0]);
    assert_eq!(fast.tested_pairs().1[1], dist0[1]);
    // Body 3 comes 13 mm closer on both axes (35.4 mm apart): its pair crosses into the set.
    cols[3].update(&Pose::new(0.065, 0.065, 0.0));
    odometer[3] += 0.013 * 2f64.sqrt();
    fast.update_with_motion(&cols, &odometer, &mut out);
    every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    every.update(&cols, &mut out_every);
    assert!(fast.stats().in_place);
    assert_eq!(out, vec![(1, 2), (1, 3)]);
    assert_eq!(out, out_every);
    assert_eq!(fast.tested_pairs(), every.tested_pairs());
    // Body 3 drifts away diagonally in 1 mm steps until its box leaves body 1's: that update
    // must take the full path.
    let (mut left, mut patched) = (false, 0);
    for k in 1..=20 {
        let x = 0.065 + 0.001 * k as f64;
        cols[3].update(&Pose::new(x, x, 0.0));
        odometer[3] += 0.001 * 2f64.sqrt();
        fast.update_with_motion(&cols, &odometer, &mut out);
        every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        every.update(&cols, &mut out_every);
        assert_eq!(out, out_every, "step {k}");
        assert_eq!(fast.tested_pairs().0, every.tested_pairs().0, "step {k}");
        assert_eq!(fast.stats().proximate_pairs, out.len());
        let dropped = fast.stats().aabb_pairs < 2;
        if dropped && !left {
            assert!(!fast.stats().in_place, "step {k}: a pair left");
        }
        patched += fast.stats().in_place as usize;
        left |= dropped;
    }
    assert!(left, "body 3's box left body 1's");
    assert!(patched > 10, "{patched} updates in place");
    // A new pair (body 2 jumps 5 mm above body 3): the full path.
    cols[2].update(&Pose::new(0.085, 0.13, 0.0));
    odometer[2] += 0.2;
    fast.update_with_motion(&cols, &odometer, &mut out);
    every = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    every.update(&cols, &mut out_every);
    assert!(!fast.stats().in_place);
    assert_eq!(out, out_every);
    assert_eq!(fast.tested_pairs(), every.tested_pairs());
}

/// The sweep's insertion sort gives the order of a full sort, on nearly sorted input (the
/// last update's order) and on shuffled input (past its move budget), ties on `min.x` too.
#[test]
fn sweep_sort_matches_a_full_sort() {
    let mut seed = 12345u64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for (n, jitter) in [(0, 0.0), (1, 0.0), (50, 0.01), (1000, 0.002), (1000, 10.0)] {
        let mut sweep: Vec<SweepEntry> = (0..n)
            .map(|i| {
                let x = (i / 2) as f64 * 0.05 + jitter * next();
                SweepEntry {
                    min_x: if i % 7 == 0 { 0.5 } else { x },
                    max_x: x + 0.1,
                    min_y: 0.0,
                    max_y: 0.1,
                    index: i as u32,
                    body: (i as u32) << 1 | 1,
                }
            })
            .collect();
        let mut full = sweep.clone();
        full.sort_unstable_by(sweep_order);
        sort_sweep(&mut sweep);
        let order = |v: &[SweepEntry]| v.iter().map(|e| e.index).collect::<Vec<_>>();
        assert_eq!(order(&sweep), order(&full), "n {n}, jitter {jitter}");
    }
}

/// `still_exact` is sound: whenever it says the published set still holds, a new stage run
/// on the moved colliders computes that very set. Seeded random scenes: 24 rectangles of
/// 1–8 cm, a quarter of them fixed, some sharing a body, in a square of 0.3–3 m (dense scenes
/// are bound by the paired pairs' slack, sparse ones by the unpaired boxes' gap), published
/// once, then moved by up to a random scale from 1 µm to 3 cm and checked against a fresh
/// update. Half the trials move every body straight towards the middle by the whole scale
/// (pairs close at up to twice the scale, the bound's worst case); the others move them at
/// random, with a rotation.
#[test]
fn a_still_exact_set_is_what_an_update_now_computes() {
    let mut next = uniform(0x9e37_79b9_7f4a_7c15u64);
    let (mut held, mut changed, mut failed_same) = (0, 0, 0);
    let (mut gap_bound, mut tight) = (0, 0);
    for trial in 0..2000 {
        let (n, bodies) = (24, 20);
        let side = 0.3 * 10f64.powf(next());
        let mut poses = Vec::new();
        let mut cols = Vec::new();
        for i in 0..n {
            let body = if i < bodies { i } else { i - bodies };
            let dynamic = body % 4 != 0;
            let (w, h) = (0.01 + 0.07 * next(), 0.01 + 0.07 * next());
            let pose = Pose::new(side * next(), side * next(), 6.0 * next());
            let shape = ConvexPolygon::rectangle(w, h).unwrap();
            cols.push(Collider::new(body, dynamic, shape, &pose));
            poses.push(pose);
        }
        let odometer = vec![0.0; bodies];
        let mut stage = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
        let mut published = Vec::new();
        stage.update_with_motion(&cols, &odometer, &mut published);
        // (Unmoved it holds unless a pair sits within the guard of δ_prox.)
        let c = stage.certificate.expect("an update with a certificate");
        assert_eq!(
            stage.still_exact(&cols),
            c.gap > 0.0 && c.slack > 0.0,
            "{trial}"
        );
        gap_bound += (c.gap < c.slack) as usize;
        // One scale per trial, 1 µm to 3 cm (log-uniform).
        let scale = 1e-6 * (3e4f64).powf(next());
        let inward = trial % 2 == 0;
        let mut moves = Vec::new();
        for b in 0..bodies {
            let p = poses
                .iter()
                .zip(&cols)
                .find(|(_, c)| c.body == b)
                .unwrap()
                .0;
            moves.push(if inward {
                // Straight to the middle by the whole scale (a body off its origin only
                // translates, so every vertex moves by exactly `scale`).
                let to = Vec2::new(0.5 * side, 0.5 * side) - p.pos;
                let d = to * (scale / to.length().max(1e-12));
                (d.x, d.y, 0.0)
            } else {
                let u = |x: f64| scale * (2.0 * x - 1.0);
                (u(next()), u(next()), 20.0 * u(next()))
            });
        }
        for (c, p) in cols.iter_mut().zip(&poses) {
            let (dx, dy, da) = moves[c.body];
            c.update(&Pose::new(p.pos.x + dx, p.pos.y + dy, p.angle + da));
        }
        let mut fresh = Vec::new();
        BroadPhase::new(DEFAULT_DELTA_PROX)
            .unwrap()
            .update(&cols, &mut fresh);
        let exact = stage.still_exact(&cols);
        if exact {
            held += 1;
            tight += (4.0 * scale > c.gap.min(c.slack)) as usize;
            assert_eq!(
                fresh, published,
                "{trial}: still_exact, but the set changed"
            );
        } else if fresh == published {
            failed_same += 1;
        } else {
            changed += 1;
        }
    }
    assert!(
        held > 500 && changed > 200 && gap_bound > 100 && tight > 50,
        "held {held} ({tight} with the motion past half the bound), changed {changed}, \
         neither {failed_same}, bound by the gap {gap_bound}"
    );
}

/// The gap in y counts: a column of boxes 1 cm farther apart than `δ_prox` (their inflated
/// boxes overlap in x and are 1 cm apart in y, so the sweep tests them in y and pairs none).
/// Moving each box 4 mm towards the middle one keeps the set (empty) exact; 6 mm brings
/// neighbours within `δ_prox`, and the certificate must fail.
#[test]
fn the_gap_between_unpaired_boxes_in_y_bounds_the_motion() {
    let pitch = 0.04 + DEFAULT_DELTA_PROX + 0.01;
    let place = |shift: f64| -> Vec<Collider> {
        (0..5)
            .map(|i| {
                let y = pitch * i as f64;
                let toward = (2.0 * pitch - y).signum() * shift;
                square(i, true, 0.0, y + toward)
            })
            .collect()
    };
    let mut stage = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let mut set = Vec::new();
    stage.update_with_motion(&place(0.0), &[0.0; 5], &mut set);
    assert!(set.is_empty());
    assert!((stage.certificate.unwrap().gap - 0.01).abs() < 1e-12);
    assert!(stage.still_exact(&place(0.004)));
    let near = place(0.006);
    assert!(!stage.still_exact(&near));
    let mut fresh = Vec::new();
    BroadPhase::new(DEFAULT_DELTA_PROX)
        .unwrap()
        .update(&near, &mut fresh);
    assert!(!fresh.is_empty(), "the moved boxes are within δ_prox");
}

/// After a failed check the next updates compute no certificate (1, then 2, 4, … up to
/// `MAX_BACKOFF`), and a check that holds resets the backoff.
#[test]
fn a_failed_check_backs_off() {
    let home: Vec<Collider> = (0..3)
        .map(|i| square(i, true, 0.2 * i as f64, 0.0))
        .collect();
    let mut moved = home.clone();
    moved[1].update(&Pose::new(0.3, 0.0, 0.0)); // 10 cm: past the certificate (gaps 11.8 cm)
    let mut stage = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let mut set = Vec::new();
    let update = |stage: &mut BroadPhase, cols: &[Collider], set: &mut Vec<(u32, u32)>| {
        stage.update_with_motion(cols, &[0.0; 3], set);
    };
    update(&mut stage, &home, &mut set);
    assert!(stage.skip_update(&home), "unmoved");
    // Fail once: the next update has no certificate.
    assert!(!stage.skip_update(&moved));
    update(&mut stage, &home, &mut set);
    assert!(
        !stage.skip_update(&home),
        "no certificate while backing off"
    );
    // The one after has one again; failing now waits two updates.
    update(&mut stage, &home, &mut set);
    assert!(!stage.skip_update(&moved));
    for _ in 0..2 {
        update(&mut stage, &home, &mut set);
        assert!(!stage.skip_update(&home), "backing off");
    }
    update(&mut stage, &home, &mut set);
    assert!(stage.skip_update(&home), "certified again");
    assert_eq!((stage.backoff, stage.wait), (0, 0));
    // The backoff stops growing at MAX_BACKOFF.
    for _ in 0..20 {
        stage.backoff = MAX_BACKOFF;
        update(&mut stage, &home, &mut set);
        stage.wait = 0;
    }
    update(&mut stage, &home, &mut set);
    assert!(!stage.skip_update(&moved));
    assert_eq!(stage.wait, MAX_BACKOFF);
}

/// The partial update (`partial.rs`) decides the moved body's pairs again at the current poses:
/// a partner of body `B` joins when closer than `δ_prox + motion[B]` (`δ_prox` when `B` moved
/// too; a NaN motion keeps it), a stale pair of the moved body goes, and the other pairs stay,
/// in pair order. The squares are 0.04 m wide, so the face gaps follow from the centres.
#[test]
fn partial_update_decides_the_moved_bodys_pairs_with_the_partners_motion() {
    let cols = vec![
        square(0, true, 0.0, 0.0),  // the moved body
        square(1, true, 0.09, 0.0), // 0.05 from 0: beyond δ_prox, within δ_prox + 0.01
        square(2, true, 0.0, 0.07), // 0.03 from 0: within δ_prox
        square(3, true, 1.0, 0.0),  // far from 0: its stale pair goes
        square(4, true, 1.05, 0.0), // 0.01 from 3: a pair of two other bodies, kept
    ];
    let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let run = |bp: &mut BroadPhase, moved: [bool; 5], motion: [f64; 5]| {
        let mut set = vec![(0, 3), (3, 4)];
        bp.update_bodies(&cols, &moved, &motion, &mut set);
        set
    };
    let only_0 = [true, false, false, false, false];
    assert_eq!(run(&mut bp, only_0, [0.0; 5]), vec![(0, 2), (3, 4)]);
    let b_moved = [0.0, 0.01, 0.0, 0.0, 0.0];
    assert_eq!(run(&mut bp, only_0, b_moved), vec![(0, 1), (0, 2), (3, 4)]);
    let both = [true, true, false, false, false];
    assert_eq!(run(&mut bp, both, b_moved), vec![(0, 2), (3, 4)]);
    let unknown = [0.0, f64::NAN, 0.0, 0.0, 0.0];
    assert_eq!(run(&mut bp, only_0, unknown), vec![(0, 1), (0, 2), (3, 4)]);
}

/// The partial update's sorted dynamic boxes (`near`) are rebuilt when a collider's kind changed,
/// even with the number of dynamic colliders unchanged: a collider that became dynamic (not moved)
/// is still a partner of a moved body. Before, `near` was refreshed by index whenever the count
/// matched, so it kept the collider that became fixed and missed the one that became dynamic.
#[test]
fn partial_update_sees_a_collider_that_became_dynamic_with_the_count_unchanged() {
    let mut cols = vec![
        square(0, true, 1.0, 0.0),  // dynamic, becomes fixed
        square(1, false, 0.0, 0.0), // fixed, becomes dynamic
        square(2, true, 0.07, 0.0), // the moved body: 0.03 from 1, within δ_prox
    ];
    let mut bp = BroadPhase::new(DEFAULT_DELTA_PROX).unwrap();
    let moved = [false, false, true];
    let mut set = Vec::new();
    bp.update_bodies(&cols, &moved, &[0.0; 3], &mut set);
    assert_eq!(set, vec![(1, 2)], "a fixed partner is found");
    cols[0].dynamic = false;
    cols[1].dynamic = true;
    let mut set = Vec::new();
    bp.update_bodies(&cols, &moved, &[0.0; 3], &mut set);
    assert_eq!(
        set,
        vec![(1, 2)],
        "the partner that became dynamic is found too"
    );
}
