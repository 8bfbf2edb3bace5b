//! The impact solver's work budget (docs/MODELS.md §7.7, issues 35 and 42): a large island's
//! projected Gauss–Seidel phases stop after `impact_sweeps` sweeps, and what they leave cannot
//! create energy (the restitution is scaled where Poisson's would have).

use haptic2d::body::Body;
use haptic2d::contact::impact::{ImpactRow, ImpactSolver, DENSE_MAX_ROWS};
use haptic2d::geom::{Pose, Vec2};

/// `wedges` point masses (1 kg each, no lever arm) falling at 1 m/s into a V of two fixed walls
/// whose normals lean ±30° from the vertical, both rows colliding with restitution `e`. The two
/// normals are not orthogonal (`n_1·n_2 = 0.5`), so a row's update pushes the other row apart:
/// after one sweep the first row separates while it holds an impulse (worked by hand: velocity
/// (0.2165, 0.125) m/s, row 1 at +0.2165 m/s with λ_1 = 0.866 N·s), and Poisson's restitution on
/// that iterate would leave 0.875 J from 0.5 J per wedge at `e = 1`.
fn wedges(wedges: usize, e: f64) -> (Vec<Body>, Vec<ImpactRow>) {
    let mut bodies = vec![Body::fixed("walls", Pose::IDENTITY)];
    let mut rows = Vec::new();
    let (s, c) = (0.5, 0.75f64.sqrt());
    for k in 0..wedges {
        let mut b = Body::dynamic(format!("m{k}"), 1.0, 1.0, Pose::new(k as f64, 0.0, 0.0));
        b.vel = Vec2::new(0.0, -1.0);
        bodies.push(b);
        for n in [Vec2::new(s, c), Vec2::new(-s, c)] {
            rows.push(ImpactRow {
                body_a: k + 1,
                body_b: 0,
                n,
                r_a: Vec2::ZERO,
                r_b: Vec2::ZERO,
                restitution: e,
            });
        }
    }
    (bodies, rows)
}

fn kinetic(bodies: &[Body]) -> f64 {
    bodies.iter().map(Body::kinetic_energy).sum()
}

/// Every sweep budget from 1 to 200: the kinetic energy after the impact never exceeds the
/// energy before (I3), even where the budget cut the compression short; at small budgets the
/// fallback scales the restitution (at `e = 1` one sweep would give 0.875 J per 0.5 J, above).
#[test]
fn a_budget_cut_impact_never_creates_energy() {
    for e in [0.5, 1.0] {
        let mut scaled_at = Vec::new();
        for budget in 1..=200 {
            let (mut bodies, rows) = wedges(13, e);
            assert!(rows.len() > DENSE_MAX_ROWS, "the sparse path");
            let before = kinetic(&bodies);
            let mut solver = ImpactSolver::new();
            solver.set_sweep_budget(budget);
            solver.solve(&rows, &mut bodies);
            let after = kinetic(&bodies);
            assert!(
                after <= before * (1.0 + 1e-12),
                "e = {e}, budget {budget}: kinetic energy {before} J → {after} J"
            );
            if solver.budget_counters().restitution_scaled > 0 {
                scaled_at.push(budget);
            }
        }
        // At e = 0.5 Poisson's restitution on the one-sweep iterate loses energy anyway
        // (0.289 J of 0.5 J per wedge), so only e = 1 must fall back.
        if e == 1.0 {
            assert!(
                scaled_at.contains(&1),
                "e = 1: one sweep must need the passive fallback (scaled at {scaled_at:?})"
            );
        }
    }
}

/// The converged solve is untouched by the budget: with enough sweeps the wedges stop and leave
/// at `e` times their speed straight up (the exact solution: both rows active, `u⁺ = −e·u⁻`),
/// and nothing is counted as cut or scaled.
#[test]
fn a_converged_impact_is_not_changed_by_the_budget() {
    let (mut bodies, rows) = wedges(13, 0.5);
    let mut solver = ImpactSolver::new();
    solver.set_sweep_budget(200);
    solver.solve(&rows, &mut bodies);
    let c = solver.budget_counters();
    assert_eq!((c.phases_cut, c.restitution_scaled), (0, 0), "{c:?}");
    for b in &bodies[1..] {
        assert!(
            (b.vel - Vec2::new(0.0, 0.5)).length() < 1e-8,
            "wedge leaves at {:?}",
            b.vel
        );
    }
}

/// The work of one sparse solve is at most two phases of `budget` sweeps over its rows.
#[test]
fn the_budget_bounds_the_row_updates_of_an_impact() {
    for budget in [1, 4, 32] {
        let (mut bodies, rows) = wedges(20, 1.0);
        let mut solver = ImpactSolver::new();
        solver.set_sweep_budget(budget);
        solver.solve(&rows, &mut bodies);
        let c = solver.budget_counters();
        assert!(
            c.row_updates <= (2 * budget * rows.len()) as u64,
            "budget {budget}: {} row updates for {} rows",
            c.row_updates,
            rows.len()
        );
        assert_eq!(c.islands, 1);
    }
}

/// `[contact] impact_sweeps`: 1 to 200 is taken into the world's contact parameters, anything
/// else is an error naming the field; the default is `DEFAULT_IMPACT_SWEEPS`.
#[test]
fn impact_sweeps_scene_field_is_checked() {
    use haptic2d::contact::DEFAULT_IMPACT_SWEEPS;
    use haptic2d::scene::Scene;
    let wall = crate::shared::WALL_TOML;
    for bad in [0, 201] {
        let text = format!("[contact]\nimpact_sweeps = {bad}\n{wall}");
        let e = crate::shared::scene_errors(&text);
        assert!(
            e.errors
                .iter()
                .any(|x| x.field == "contact.impact_sweeps" && !x.fix.is_empty()),
            "{e:?}"
        );
    }
    let text = format!("[contact]\nimpact_sweeps = 8\n{wall}");
    let s = Scene::from_toml(&text, "t.toml", None).expect("impact_sweeps = 8");
    assert_eq!(s.world.params.contact.impact_sweeps, 8);
    let s = Scene::from_toml(wall, "t.toml", None).expect("default");
    assert_eq!(s.world.params.contact.impact_sweeps, DEFAULT_IMPACT_SWEEPS);
}

/// A landing pile (pile:100, whose columns join into islands of more than `DENSE_MAX_ROWS`
/// rows) with a budget of 2 sweeps, far below what its islands need: the budget cuts phases
/// (measured: 13 sparse islands, 26 phases cut in 1.5 s), and the world's ledger shows no
/// energy created (excess ≤ 0; measured −9.6e-3 J).
#[test]
fn a_landing_pile_with_a_tight_budget_creates_no_energy() {
    let (c, worst) = land_pile_100(|p| p.impact_sweeps = 2);
    eprintln!("pile:100, impact_sweeps = 2, 1.5 s: {c:?}; ledger excess at most {worst:e} J");
    assert!(c.islands > 0 && c.phases_cut > 0, "{c:?}");
    assert!(worst <= 1e-9, "ledger excess {worst} J");
}

/// The sample's row budget (§7.7, issue 42): a phase runs the sweeps that fit in what the sample
/// has left over its island, at least one, so a sample's sparse row updates are at most the
/// budget, or one sweep over the island for each phase that found it spent; the kinetic energy
/// never rises; and a budget that holds every sweep changes nothing, bit for bit.
#[test]
fn a_sample_row_budget_gives_each_phase_the_sweeps_that_fit() {
    let (bodies0, rows) = wedges(13, 1.0);
    let n = rows.len() as u64;
    let solve = |sample_rows: u64| {
        let mut bodies = bodies0.clone();
        let mut solver = ImpactSolver::new();
        solver.set_sweep_budget(8);
        solver.set_sample_rows(sample_rows);
        solver.solve(&rows, &mut bodies);
        (bodies, solver.budget_counters())
    };
    let (free, c_free) = solve(u64::MAX);
    assert_eq!(c_free.phases_capped, 0, "{c_free:?}");
    let before = kinetic(&bodies0);
    for sample_rows in 1..=(3 * 8 * n + 5) {
        let (bodies, c) = solve(sample_rows);
        // Phases run: compression, correction, and the fallback's second correction at most.
        assert!(
            c.row_updates <= sample_rows.max(n) + 2 * n,
            "budget {sample_rows}: {} row updates over {n} rows",
            c.row_updates
        );
        // The compression is capped below 8 sweeps over the island; above three phases of 8
        // sweeps nothing is.
        if sample_rows < 8 * n {
            assert!(c.phases_capped > 0, "budget {sample_rows}: {c:?}");
        }
        if sample_rows >= 3 * 8 * n {
            assert_eq!(c.phases_capped, 0, "budget {sample_rows}: {c:?}");
        }
        let after = kinetic(&bodies);
        assert!(
            after <= before * (1.0 + 1e-12),
            "budget {sample_rows}: kinetic energy {before} J → {after} J"
        );
        if sample_rows >= c_free.row_updates {
            for (a, b) in bodies.iter().zip(&free) {
                assert_eq!(
                    (a.vel.x.to_bits(), a.vel.y.to_bits(), a.omega.to_bits()),
                    (b.vel.x.to_bits(), b.vel.y.to_bits(), b.omega.to_bits()),
                    "budget {sample_rows} ≥ the unbounded solve's {} row updates",
                    c_free.row_updates
                );
            }
        }
    }
}

/// The sample's row budget is off by default; derived from the period it is 12 000 row updates
/// per millisecond (§7.7); `[contact] impact_budget` sets it, 0 leaving it unbounded.
#[test]
fn the_impact_row_budget_follows_the_sample_period() {
    use haptic2d::contact::{ContactParams, WorkBudget, IMPACT_ROW_UPDATES_PER_S};
    use haptic2d::scene::Scene;
    assert_eq!(ContactParams::default().impact_row_budget(1e-3), u64::MAX);
    let p = ContactParams {
        impact_budget: WorkBudget::FromPeriod,
        ..ContactParams::default()
    };
    assert_eq!(IMPACT_ROW_UPDATES_PER_S, 12.0e6);
    assert_eq!(p.impact_row_budget(1e-3), 12_000);
    assert_eq!(p.impact_row_budget(2e-3), 24_000);
    assert_eq!(p.impact_row_budget(1e-6), 12);
    assert_eq!(p.impact_row_budget(f64::NAN), 0);
    let off = ContactParams {
        impact_budget: WorkBudget::from_setting(0),
        ..p
    };
    assert_eq!(off.impact_row_budget(1e-3), u64::MAX);
    let wall = crate::shared::WALL_TOML;
    let text = format!("[contact]\nimpact_budget = 500\n{wall}");
    let s = Scene::from_toml(&text, "t.toml", None).expect("impact_budget = 500");
    assert_eq!(s.world.params.contact.impact_row_budget(1e-3), 500);
}

/// A landing pile with a row budget far below what its islands' sweeps need: phases get fewer
/// sweeps than `impact_sweeps` and the ledger shows no energy created.
#[test]
fn a_landing_pile_with_a_tight_row_budget_creates_no_energy() {
    let (c, worst) =
        land_pile_100(|p| p.impact_budget = haptic2d::contact::WorkBudget::RowUpdates(60));
    eprintln!("pile:100, impact_budget = 60, 1.5 s: {c:?}; ledger excess at most {worst:e} J");
    assert!(c.islands > 0 && c.phases_capped > 0, "{c:?}");
    assert!(worst <= 1e-9, "ledger excess {worst} J");
}

/// pile:100 landing for 1.5 s with its contact parameters changed by `set`: the impact budget's
/// counters and the largest excess of the world's energy ledger (J) over the run.
fn land_pile_100(
    set: impl FnOnce(&mut haptic2d::contact::ContactParams),
) -> (haptic2d::contact::impact::BudgetCounters, f64) {
    let mut w = haptic2d::scene::builtin("pile:100", None)
        .unwrap()
        .unwrap()
        .world;
    set(&mut w.params.contact);
    let mut worst = f64::NEG_INFINITY;
    for _ in 0..1500 {
        w.step();
        worst = worst.max(w.ledger().excess());
    }
    (w.contacts().impact_budget(), worst)
}
