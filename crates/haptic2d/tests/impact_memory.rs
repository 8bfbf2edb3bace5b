//! Issue 10, item 5: the impact solver's memory is O(rows), never a dense `n × n` matrix beyond
//! `DENSE_MAX_ROWS` — r5 (an overlapping grid) and a 50 000-vertex polygon made it allocate 27 GB and
//! 6.6 GB. A counting allocator measures the peak bytes live during the test.

use haptic2d::body::Body;
use haptic2d::contact::impact::{ImpactRow, ImpactSolver, DENSE_MAX_ROWS};
use haptic2d::contact::lcp::{LcpError, LcpSolver, ENUMERATION_HARD_MAX_N};
use haptic2d::geom::{Pose, Vec2};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

struct Peak;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// The tests share the counters: one at a time.
static SERIAL: Mutex<()> = Mutex::new(());

unsafe impl GlobalAlloc for Peak {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let now = LIVE.fetch_add(l.size(), Ordering::SeqCst) + l.size();
            PEAK.fetch_max(now, Ordering::SeqCst);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        LIVE.fetch_sub(l.size(), Ordering::SeqCst);
    }
}

#[global_allocator]
static A: Peak = Peak;

/// Peak bytes allocated above the live total at the start, while `f` runs.
fn peak_during(f: impl FnOnce()) -> usize {
    let base = LIVE.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    f();
    PEAK.load(Ordering::SeqCst) - base
}

#[test]
fn impact_solver_for_100k_rows_allocates_linear_memory() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let rows = 100_000;
    // Dense would be rows² · 8 B = 80 GB; linear is ~ rows · (6 + 8) · 8 B ≈ 11 MB.
    let peak = peak_during(|| {
        let s = ImpactSolver::with_capacity(rows);
        assert_eq!(s.capacity(), rows);
    });
    assert!(peak < 32 << 20, "peak {peak} bytes for {rows} rows");
}

#[test]
fn a_large_impact_set_is_solved_on_the_sparse_path_in_linear_memory() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    // A row of 2 000 boxes landing side by side on a fixed floor at 0.1 m/s, two corner rows each:
    // 4 000 rows in one set (the floor couples them only through the fixed body, so PGS converges).
    let n = 2_000;
    let mut bodies = vec![Body::fixed("floor", Pose::new(0.0, -0.5, 0.0))];
    for k in 0..n {
        let mut b = Body::dynamic(
            format!("b{k}"),
            1.0,
            1e-3,
            Pose::new(0.06 * k as f64, 0.025, 0.0),
        );
        b.vel = Vec2::new(0.0, -0.1);
        bodies.push(b);
    }
    let rows: Vec<ImpactRow> = (0..2 * n)
        .map(|r| {
            let (k, side) = (r / 2, if r % 2 == 0 { -0.025 } else { 0.025 });
            ImpactRow {
                body_a: k + 1,
                body_b: 0,
                n: Vec2::new(0.0, 1.0),
                r_a: Vec2::new(side, -0.025),
                r_b: Vec2::new(0.06 * k as f64 + side, 0.5),
                restitution: 0.0,
            }
        })
        .collect();
    let n = rows.len();
    let mut solver = ImpactSolver::new();
    let peak = peak_during(|| {
        solver.solve(&rows, &mut bodies);
    });
    assert!(n > DENSE_MAX_ROWS);
    assert!(
        peak < 4 << 20,
        "peak {peak} bytes for {n} rows (dense: 32 MB)"
    );
    assert!(solver.delassus().is_empty(), "no matrix on the sparse path");
    // Plastic impacts (e = 0) of resting faces: every row ends at rest, every box stopped.
    let post = solver.post_velocities();
    assert!(
        post.iter().all(|v| v.abs() < 1e-6),
        "post velocities {post:?}"
    );
    assert!(bodies[1..]
        .iter()
        .all(|b| b.vel.length() < 1e-6 && b.omega.abs() < 1e-4));
}

#[test]
fn lcp_enumeration_beyond_its_cap_is_an_error_not_a_hang() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let n = ENUMERATION_HARD_MAX_N + 1;
    let mut a = vec![0.0; n * n];
    for i in 0..n {
        a[i * n + i] = 1.0;
    }
    let b = vec![-1.0; n];
    let mut lcp = LcpSolver::new();
    assert_eq!(
        lcp.solve_enumeration(&a, &b),
        Err(LcpError::TooLargeForEnumeration { n })
    );
    // The general solver takes PGS for it and solves it.
    let r = lcp.solve(&a, &b).unwrap();
    assert!(r.converged);
    assert!(lcp.lambda().iter().all(|l| (l - 1.0).abs() < 1e-9));
}
