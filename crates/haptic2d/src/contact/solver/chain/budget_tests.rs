//! Tests of the chain damper's work budget (issue 42 item 2, MODELS §6.7): the row updates of a
//! sample stay within it, a cut damper is still passive, a cut is exactly a smaller sweep limit,
//! and no budget changes nothing.

use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `boxes` boxes of random masses (0.2–5 kg) stacked on a fixed floor (body 0), two loaded
/// contacts per interface at the box's bottom corners (the column of
/// [`tall_column`](super::tests::tall_column)), normals tilted up to ±0.2 rad, random loads
/// (0.5–50 N), random velocities (±0.5 m/s, ±3 rad/s) and random held forces: a chain the
/// damper needs many sweeps for.
fn random_column(
    rng: &mut ChaCha8Rng,
    boxes: u32,
) -> (Vec<Body>, Vec<LoadedContact>, Vec<VeCandidate>) {
    let (mut bodies, column) = super::tests::tall_column(boxes);
    for b in bodies.iter_mut().skip(1) {
        let m = rng.random_range(0.2..5.0);
        *b = Body::dynamic("box", m, m / 600.0, b.pose);
        b.vel = Vec2::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5));
        b.omega = rng.random_range(-3.0..3.0);
        b.force = Vec2::new(rng.random_range(-20.0..20.0), rng.random_range(-20.0..20.0));
        b.torque = rng.random_range(-1.0..1.0);
    }
    let mut contacts = column.contacts;
    for c in contacts.iter_mut() {
        let tilt: f64 = rng.random_range(-0.2..0.2);
        c.n = Vec2::new(tilt.sin(), tilt.cos());
        c.f_n = rng.random_range(0.5..50.0);
    }
    (bodies, contacts, column.keys)
}

/// Kinetic energy of `bodies` after a semi-implicit Euler step of their held forces (J): the
/// velocities the integrator reaches, computed here independently of the damper.
fn kinetic_after_step(bodies: &[Body], dt: f64) -> f64 {
    bodies
        .iter()
        .filter(|b| b.is_dynamic())
        .map(|b| {
            let f = b.force - b.vel * b.damping;
            let v = b.vel + f * (dt * b.inv_mass);
            let omega = b.omega + b.torque * dt * b.inv_inertia;
            0.5 * (b.mass * v.dot(v) + b.inertia * omega * omega)
        })
        .sum()
}

/// One damper pass at `τ` = 0.2 ms, `T` = 1 ms, up to 16 sweeps within `budget`, over the
/// column's whole loaded list.
fn pass_within(
    d: &mut ChainDamping,
    budget: Option<u64>,
    sweeps: u32,
    bodies: &mut [Body],
    contacts: &[LoadedContact],
    keys: &[VeCandidate],
) -> f64 {
    let loaded = Loaded {
        contacts,
        keys,
        generation: 1,
    };
    let mut wrenches = vec![Wrench2::default(); bodies.len()];
    d.apply(
        Some(2e-4),
        sweeps,
        budget,
        1e-3,
        loaded,
        bodies,
        &mut wrenches,
    )
}

/// Over random columns and budgets, a sample's row updates are its sweeps × its rows and never
/// exceed `max(budget, one sweep)`; the budget stops the sweeps in some samples (the property is
/// not vacuous) and never where the unbudgeted solve needed no more than it allows.
#[test]
fn a_samples_row_updates_never_exceed_its_budget() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let mut cuts = 0;
    for case in 0..300 {
        let boxes = rng.random_range(2..40);
        let (bodies0, contacts, keys) = random_column(&mut rng, boxes);
        let budget = rng.random_range(0..(16 * 2 * boxes as u64 + 20));
        let mut free = bodies0.clone();
        let mut unbounded = ChainDamping::default();
        pass_within(&mut unbounded, None, 16, &mut free, &contacts, &keys);
        let (mut bodies, mut d) = (bodies0, ChainDamping::default());
        pass_within(&mut d, Some(budget), 16, &mut bodies, &contacts, &keys);
        let rows = d.sorted.len() as u64;
        assert!(rows > 0, "case {case}: no rows");
        assert_eq!(
            d.last_row_updates,
            d.last_sweeps as u64 * rows,
            "case {case}"
        );
        assert!(
            d.last_row_updates <= budget.max(rows),
            "case {case}: {} row updates, budget {budget}, {rows} rows",
            d.last_row_updates
        );
        assert!(
            d.last_sweeps >= 1,
            "case {case}: the first sweep always runs"
        );
        assert_eq!(
            d.last_cut,
            unbounded.last_row_updates > d.last_row_updates,
            "case {case}: cut exactly when the unbudgeted solve ran more"
        );
        assert_eq!(d.budget_cuts, d.last_cut as u64);
        cuts += d.last_cut as u32;
    }
    assert!(cuts > 50, "only {cuts} of 300 cases were cut");
}

/// Over random columns and budgets, the budgeted damper only removes energy: the energy it
/// reports removed is at least −rounding, and the kinetic energy after the step with its forces
/// (computed here from the bodies' held forces) is at most that without them, by what it reports.
#[test]
fn a_cut_damper_still_only_removes_energy() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let dt = 1e-3;
    let mut cut = 0;
    for case in 0..300 {
        let boxes = rng.random_range(2..40);
        let (mut bodies, contacts, keys) = random_column(&mut rng, boxes);
        let budget = rng.random_range(0..(16 * 2 * boxes as u64));
        let before = kinetic_after_step(&bodies, dt);
        let mut d = ChainDamping::default();
        let removed = pass_within(&mut d, Some(budget), 16, &mut bodies, &contacts, &keys);
        let after = kinetic_after_step(&bodies, dt);
        let tol = 1e-12 * before.max(1.0);
        assert!(removed >= -tol, "case {case}: removed {removed} J");
        assert!(after <= before + tol, "case {case}: {before} → {after} J");
        assert!(
            ((before - after) - removed).abs() <= 1e-9 * before.max(1.0),
            "case {case}: removed {removed} J, kinetic {before} → {after} J"
        );
        cut += d.last_cut as u32;
    }
    assert!(cut > 50, "only {cut} of 300 cases were cut");
}

/// A budget that stops the sweeps after `k` is bit for bit a limit of `k` sweeps without a
/// budget (forces, velocities and the energy removed), and no budget is bit for bit a budget
/// never reached: the budget only chooses where the unchanged sweeps stop.
#[test]
fn a_budget_cut_is_exactly_a_smaller_sweep_limit() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let bits = |bodies: &[Body]| -> Vec<[u64; 3]> {
        bodies
            .iter()
            .map(|b| [b.force.x.to_bits(), b.force.y.to_bits(), b.torque.to_bits()])
            .collect()
    };
    let mut cut = 0;
    for case in 0..100 {
        let boxes = rng.random_range(5..40);
        let (bodies0, contacts, keys) = random_column(&mut rng, boxes);
        let budget = rng.random_range(1..(8 * 2 * boxes as u64));
        let (mut a, mut da) = (bodies0.clone(), ChainDamping::default());
        let ea = pass_within(&mut da, Some(budget), 16, &mut a, &contacts, &keys);
        let k = da.last_sweeps;
        let (mut b, mut db) = (bodies0.clone(), ChainDamping::default());
        let eb = pass_within(&mut db, None, k, &mut b, &contacts, &keys);
        assert_eq!(bits(&a), bits(&b), "case {case}");
        assert_eq!(ea.to_bits(), eb.to_bits(), "case {case}");
        assert_eq!((db.last_sweeps, db.last_cut), (k, false), "case {case}");
        let (mut c, mut dc) = (bodies0.clone(), ChainDamping::default());
        let ec = pass_within(&mut dc, Some(u64::MAX), 16, &mut c, &contacts, &keys);
        let (mut n, mut dn) = (bodies0, ChainDamping::default());
        let en = pass_within(&mut dn, None, 16, &mut n, &contacts, &keys);
        assert_eq!(bits(&c), bits(&n), "case {case}");
        assert_eq!(ec.to_bits(), en.to_bits(), "case {case}");
        assert_eq!(
            (dc.last_sweeps, dc.last_cut),
            (dn.last_sweeps, false),
            "case {case}"
        );
        cut += da.last_cut as u32;
    }
    assert!(cut > 20, "only {cut} of 100 cases were cut");
}

/// The default budget is the documented share of the period at the documented cost of a row
/// update: at 1 kHz, 20 % of 1 ms = 200 µs at 7 ns a row update = 28 571.4, rounded 28 571; at
/// 500 Hz 57 142.9, rounded 57 143; 0 turns it off; a set number is taken as it is.
#[test]
fn the_default_budget_is_a_share_of_the_period() {
    use crate::contact::WorkBudget;
    use crate::world::{CHAIN_BUDGET_SHARE, CHAIN_ROW_UPDATES_PER_S, CHAIN_ROW_UPDATE_NS};
    assert_eq!((CHAIN_BUDGET_SHARE, CHAIN_ROW_UPDATE_NS), (0.2, 7.0));
    assert_eq!(WorkBudget::default(), WorkBudget::FromPeriod);
    assert_eq!(
        WorkBudget::FromPeriod.row_updates(1e-3, CHAIN_ROW_UPDATES_PER_S),
        Some(28_571)
    );
    assert_eq!(
        WorkBudget::FromPeriod.row_updates(2e-3, CHAIN_ROW_UPDATES_PER_S),
        Some(57_143)
    );
    assert_eq!(
        WorkBudget::FromPeriod.row_updates(f64::NAN, CHAIN_ROW_UPDATES_PER_S),
        Some(0)
    );
    assert_eq!(
        WorkBudget::from_setting(0).row_updates(1e-3, CHAIN_ROW_UPDATES_PER_S),
        None
    );
    assert_eq!(
        WorkBudget::from_setting(7).row_updates(1e-3, CHAIN_ROW_UPDATES_PER_S),
        Some(7)
    );
}

/// A landing pile (pile:100 thrown down at 1 m/s, then shoved sideways) under small budgets: no
/// sample's row updates exceed `max(budget, one sweep)`, every sample's damper removes energy
/// (the ledger's loss never decreases), the budget does cut, and the world's counters add up the
/// samples'.
#[test]
fn a_landing_pile_keeps_every_samples_row_updates_within_the_budget() {
    use crate::contact::test_pile::shove;
    use crate::contact::WorkBudget;
    for budget in [1u64, 500, 2000] {
        let mut w = crate::scene::builtin("pile:100", None)
            .unwrap()
            .unwrap()
            .world;
        w.params.chain_budget = WorkBudget::RowUpdates(budget);
        for b in w.bodies.iter_mut().filter(|b| b.inv_mass > 0.0) {
            b.vel.y -= 1.0;
        }
        let (mut total, mut cuts, mut loss) = (0u64, 0u64, 0.0);
        for k in 0..1500 {
            if k == 600 {
                shove(&mut w);
            }
            w.step();
            let d = w.chain_damper();
            let per_sweep = d.last_row_updates / (d.last_sweeps.max(1) as u64);
            assert!(
                d.last_row_updates <= budget.max(per_sweep),
                "budget {budget}, step {k}: {} row updates, {} sweeps",
                d.last_row_updates,
                d.last_sweeps
            );
            let now = w.ledger().chain_damping_loss;
            assert!(
                now >= loss - 1e-12,
                "budget {budget}, step {k}: loss {loss} → {now} J"
            );
            loss = now;
            total += d.last_row_updates;
            cuts += d.last_cut as u64;
        }
        let d = w.chain_damper();
        assert_eq!(
            (d.row_updates, d.budget_cuts),
            (total, cuts),
            "budget {budget}"
        );
        assert!(cuts > 0, "budget {budget}: never cut");
    }
}

/// `[world] chain_budget`: absent, the budget follows the scene's rate (28 571 row updates at
/// 1 kHz, 57 143 at 500 Hz, as the documented formula gives); `N` sets `N` row updates; 0 turns
/// it off; a negative value is refused.
#[test]
fn a_scene_sets_the_chain_budget_or_takes_it_from_its_rate() {
    use crate::contact::WorkBudget;
    use crate::scene::Scene;
    const WALL: &str = "[[body]]\nname = \"wall\"\nkind = \"fixed\"\npolygon = [[-0.1, -0.2], [0.0, -0.2], [0.0, 0.2], [-0.1, 0.2]]\n";
    let budget_of = |world: &str| {
        let p = Scene::from_toml(&format!("[world]\n{world}\n{WALL}"), "t.toml", None)
            .expect("a valid scene")
            .world
            .params;
        (p.chain_budget, p.chain_row_updates())
    };
    assert_eq!(
        budget_of("rate = 1000"),
        (WorkBudget::FromPeriod, Some(28_571))
    );
    assert_eq!(
        budget_of("rate = 500"),
        (WorkBudget::FromPeriod, Some(57_143))
    );
    assert_eq!(
        budget_of("rate = 1000\nchain_budget = 5000"),
        (WorkBudget::RowUpdates(5000), Some(5000))
    );
    assert_eq!(budget_of("chain_budget = 0"), (WorkBudget::Unbounded, None));
    let text = format!("[world]\nchain_budget = -1\n{WALL}");
    assert!(Scene::from_toml(&text, "t.toml", None).is_err());
}
