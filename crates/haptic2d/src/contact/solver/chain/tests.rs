//! Tests of the chain damper: warm start, colouring, rows patched and refreshed as a build's,
//! and the forces as the sums of the rows' impulses.

use super::*;
use crate::geom::Pose;

/// A fixed floor (body 0) and `boxes` 1 kg boxes of 0.1 m stacked on it (bodies 1, 2, …).
fn column_bodies(boxes: u32) -> Vec<Body> {
    let mut bodies = vec![Body::fixed("floor", Pose::new(0.0, -0.05, 0.0))];
    for i in 0..boxes {
        let y = 0.05 + 0.1 * i as f64;
        bodies.push(Body::dynamic(
            "box",
            1.0,
            1.0 / 600.0,
            Pose::new(0.0, y, 0.0),
        ));
    }
    bodies
}

/// A column of three 1 kg boxes (0.1 m) on a fixed floor: contacts floor–1, 1–2, 2–3 at the
/// boxes' bottom faces, each pushing with 10 N.
fn column() -> (Vec<Body>, Column) {
    let bodies = column_bodies(3);
    let keys = (0..3u32)
        .map(|i| VeCandidate {
            vertex_collider: i + 1,
            vertex: 0,
            edge_collider: i,
            edge: 2,
        })
        .collect();
    let contacts = (0..3u32)
        .map(|i| LoadedContact {
            body_a: i + 1,
            body_b: i,
            point: Vec2::new(0.0, 0.1 * i as f64),
            n: Vec2::new(0.0, 1.0),
            f_n: 10.0,
        })
        .collect();
    (bodies, Column { contacts, keys })
}

/// A loaded list of the column's contacts, and its keys.
pub(super) struct Column {
    pub(super) contacts: Vec<LoadedContact>,
    pub(super) keys: Vec<VeCandidate>,
}

impl Column {
    /// The first `n` contacts as the contact set lists them, with keys of generation `g`.
    fn view(&self, n: usize, g: u64) -> Loaded<'_> {
        Loaded {
            contacts: &self.contacts[..n],
            keys: &self.keys[..n],
            generation: g,
        }
    }
}

/// One pass of damper `d` with `τ` = 0.2 ms at `T` = 1 ms, up to `sweeps` sweeps, over `loaded`;
/// the energy it removed (J).
fn pass(
    d: &mut ChainDamping,
    sweeps: u32,
    loaded: Loaded<'_>,
    bodies: &mut [Body],
    wrenches: &mut [Wrench2],
) -> f64 {
    d.apply(Some(2e-4), sweeps, None, 1e-3, loaded, bodies, wrenches)
}

fn kinetic_of(bodies: &[Body]) -> f64 {
    bodies.iter().map(|b| b.kinetic_energy()).sum()
}

/// A warm start from impulses that would now add energy (the column compressing, then
/// springing apart) is scaled down, and the damper still only removes energy.
#[test]
fn warm_start_that_would_add_energy_is_scaled_down() {
    let (mut bodies, loaded) = column();
    let mut wrenches = vec![Wrench2::default(); bodies.len()];
    let mut chain = ChainDamping::default();
    // Sample 1: every box falls faster than the one below: the dampers push the boxes apart
    // (λ > 0 on every row).
    for (i, b) in bodies.iter_mut().enumerate().skip(1) {
        b.vel = Vec2::new(0.0, -0.1 * i as f64);
    }
    let before = kinetic_of(&bodies);
    let removed = pass(
        &mut chain,
        16,
        loaded.view(3, 1),
        &mut bodies,
        &mut wrenches,
    );
    assert!(
        removed > 0.0 && removed <= before,
        "removed {removed} of {before} J"
    );
    let impulses: Vec<f64> = chain.sorted.iter().map(|r| r.lambda).collect();
    assert!(
        impulses.len() == 3 && impulses.iter().all(|&l| l > 0.0),
        "{impulses:?}"
    );
    // Sample 2: the column springs apart instead; the last impulses (pushing apart) would add
    // energy, so the warm start is scaled down, and the pass still removes energy.
    for (i, b) in bodies.iter_mut().enumerate().skip(1) {
        b.vel = Vec2::new(0.0, 0.1 * i as f64);
        b.force = Vec2::ZERO;
        b.torque = 0.0;
    }
    let removed = pass(&mut chain, 0, loaded.view(3, 1), &mut bodies, &mut wrenches);
    assert!(
        chain.last_warm_scale < 1.0,
        "scale {}",
        chain.last_warm_scale
    );
    assert!(removed >= 0.0, "removed {removed} J");
    // And with sweeps the dampers pull nothing (F ≥ −f_n) and still only remove energy.
    let removed = pass(
        &mut chain,
        16,
        loaded.view(3, 1),
        &mut bodies,
        &mut wrenches,
    );
    assert!(removed >= 0.0, "removed {removed} J");
}

/// A warm start that still fits (the same compression again) is kept whole, and fewer sweeps
/// are needed than from zero.
#[test]
fn warm_start_that_fits_is_kept_and_saves_sweeps() {
    let (mut bodies, loaded) = column();
    let mut wrenches = vec![Wrench2::default(); bodies.len()];
    let mut chain = ChainDamping::default();
    let set = |bodies: &mut Vec<Body>| {
        for (i, b) in bodies.iter_mut().enumerate().skip(1) {
            b.vel = Vec2::new(0.0, -0.1 * i as f64);
            b.force = Vec2::ZERO;
            b.torque = 0.0;
        }
    };
    set(&mut bodies);
    pass(
        &mut chain,
        64,
        loaded.view(3, 1),
        &mut bodies,
        &mut wrenches,
    );
    let cold = chain.last_sweeps;
    set(&mut bodies);
    let removed = pass(
        &mut chain,
        64,
        loaded.view(3, 1),
        &mut bodies,
        &mut wrenches,
    );
    assert_eq!(chain.last_warm_scale, 1.0);
    assert!(
        chain.last_sweeps < cold,
        "{} sweeps warm, {cold} cold",
        chain.last_sweeps
    );
    assert!(removed > 0.0);
}

/// A chain contact whose effective mass is not finite (here a NaN point, between two bodies
/// that already touch) is no row and takes no colour: the rows, their order and the
/// result are those of the list without it, bit for bit, and the next sample rebuilds. (The
/// colouring first assumes every mass valid; placing the rows meets the NaN and runs both
/// again with the check.)
#[test]
fn a_degenerate_chain_contact_takes_no_colour() {
    let (bodies0, loaded) = column();
    let mut degenerate = Column {
        contacts: loaded.contacts.clone(),
        keys: loaded.keys.clone(),
    };
    // Between box 1 and box 2 (as contact 1), keyed between contacts 1 and 2.
    let mut key = loaded.keys[1];
    key.vertex = 1;
    degenerate.keys.insert(2, key);
    degenerate.contacts.insert(
        2,
        LoadedContact {
            point: Vec2::new(f64::NAN, 0.1),
            ..loaded.contacts[1]
        },
    );
    let (mut plain, mut with) = (ChainDamping::default(), ChainDamping::default());
    plain.patching = false;
    let (mut b_plain, mut b_with) = (bodies0.clone(), bodies0.clone());
    let mut wrenches = vec![Wrench2::default(); bodies0.len()];
    for k in 0..4u64 {
        for bodies in [&mut b_plain, &mut b_with] {
            for (i, b) in bodies.iter_mut().enumerate().skip(1) {
                b.vel = Vec2::new(0.02 * k as f64, -0.1 * i as f64);
                b.omega = 0.1 * (k as f64 - i as f64);
                b.force = Vec2::new(0.0, -9.81);
                b.torque = 0.0;
            }
        }
        // The plain list comes with a new generation every sample, so it is rebuilt (it may
        // not patch its rows); the one
        // with the degenerate contact keeps its generation, and is rebuilt because a
        // contact was dropped (else it would be refreshed, which rounds differently).
        let r_plain = pass(
            &mut plain,
            3,
            loaded.view(3, 100 + k),
            &mut b_plain,
            &mut wrenches,
        );
        let r_with = pass(
            &mut with,
            3,
            degenerate.view(4, 1),
            &mut b_with,
            &mut wrenches,
        );
        assert_eq!((plain.last_rows, with.last_rows), (3, 3), "sample {k}");
        assert!(!with.last_refreshed && !plain.last_refreshed, "sample {k}");
        assert_eq!(r_plain.to_bits(), r_with.to_bits(), "sample {k}");
        for (a, b) in b_plain.iter().zip(&b_with) {
            assert_eq!(a.force, b.force, "sample {k}");
            assert_eq!(a.torque.to_bits(), b.torque.to_bits(), "sample {k}");
        }
    }
}

/// A sample whose loaded contacts are those of the last one refreshes the rows in place; it
/// gives what building them from scratch gives (up to the order of the sums' rounding), and a
/// changed list of contacts or of dynamic bodies rebuilds them.
#[test]
fn rows_refreshed_in_place_match_rows_rebuilt() {
    let (bodies0, loaded) = column();
    let (mut fast, mut full) = (ChainDamping::default(), ChainDamping::default());
    (fast.patching, full.patching) = (false, false);
    let (mut b_fast, mut b_full) = (bodies0.clone(), bodies0.clone());
    let mut wrenches = vec![Wrench2::default(); bodies0.len()];
    for k in 0..6 {
        for bodies in [&mut b_fast, &mut b_full] {
            for (i, b) in bodies.iter_mut().enumerate().skip(1) {
                b.vel = Vec2::new(0.01 * k as f64, -0.1 * i as f64 + 0.03 * k as f64);
                b.omega = 0.2 * (k as f64 - i as f64);
                b.force = Vec2::new(0.0, -9.81);
                b.torque = 0.0;
            }
        }
        // A new generation of the same keys (the impulses are kept by key) forces a rebuild
        // every sample.
        let r_fast = pass(&mut fast, 3, loaded.view(3, 1), &mut b_fast, &mut wrenches);
        let r_full = pass(
            &mut full,
            3,
            loaded.view(3, 100 + k),
            &mut b_full,
            &mut wrenches,
        );
        assert!(
            (r_fast - r_full).abs() <= 1e-12 * r_full.abs().max(1e-9),
            "{k}: {r_fast} {r_full}"
        );
        for (a, b) in b_fast.iter().zip(&b_full) {
            assert!(
                (a.force - b.force).length() <= 1e-9,
                "{k}: {:?} {:?}",
                a.force,
                b.force
            );
            assert!((a.torque - b.torque).abs() <= 1e-9);
        }
        assert_eq!(fast.last_rows, 3);
        assert_eq!((fast.last_refreshed, full.last_refreshed), (k > 0, false));
        assert!((fast.last_warm_scale - full.last_warm_scale).abs() <= 1e-12);
    }
    // One fewer contact: rebuilt (the top box is no longer a chain's end, two rows remain).
    let mut b = b_fast.clone();
    pass(&mut fast, 3, loaded.view(2, 2), &mut b, &mut wrenches);
    assert_eq!((fast.last_rows, fast.last_refreshed), (2, false));
    // A body that became fixed: rebuilt too (box 1 fixed: the floor–box 1 contact joins two
    // fixed bodies and is no row; box 2 still touches boxes 1 and 3).
    pass(
        &mut fast,
        3,
        loaded.view(3, 3),
        &mut b_fast.clone(),
        &mut wrenches,
    );
    assert_eq!((fast.last_rows, fast.last_refreshed), (3, false));
    let mut b = b_fast.clone();
    b[1] = Body::fixed("now fixed", b[1].pose);
    // (The same generation of keys: only the bodies changed.)
    pass(&mut fast, 3, loaded.view(3, 3), &mut b, &mut wrenches);
    assert_eq!((fast.last_rows, fast.last_refreshed), (2, false));
}

/// A tall column of boxes on a fixed floor, two contacts (the bottom corners) at each
/// interface: the whole loaded list, in key order.
pub(super) fn tall_column(boxes: u32) -> (Vec<Body>, Column) {
    let bodies = column_bodies(boxes);
    let (mut contacts, mut keys) = (Vec::new(), Vec::new());
    for i in 0..boxes {
        for corner in 0..2u32 {
            keys.push(VeCandidate {
                vertex_collider: i + 1,
                vertex: corner,
                edge_collider: i,
                edge: 2,
            });
            contacts.push(LoadedContact {
                body_a: i + 1,
                body_b: i,
                point: Vec2::new(0.1 * corner as f64 - 0.05, 0.1 * i as f64),
                n: Vec2::new(0.0, 1.0),
                f_n: 5.0 + i as f64 + corner as f64,
            });
        }
    }
    (bodies, Column { contacts, keys })
}

/// The live rows of a damper by key: (key, row), in key order.
fn rows_by_key(d: &ChainDamping) -> Vec<(VeCandidate, Row)> {
    d.keys
        .iter()
        .zip(&d.place)
        .map(|(&k, &p)| (k, d.sorted[p as usize]))
        .collect()
}

/// When a few loaded contacts change, the rows are patched: rows of contacts that left
/// become exact no-op holes, new ones take a hole of their colour or a new place, and the
/// live rows are bit for bit those a build from scratch gives, key by key (the warm
/// impulses differ by the rounding of the warm start's scale only). With sweeps, the result
/// stays passive. Too many changes since the last build rebuild the rows.
#[test]
fn rows_patched_are_the_rows_a_build_gives() {
    let (bodies0, all) = tall_column(30);
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    for sweeps in [0, 4] {
        let (mut patched, mut built) = (ChainDamping::default(), ChainDamping::default());
        built.patching = false;
        let (mut b_p, mut b_b) = (bodies0.clone(), bodies0.clone());
        let mut wrenches = vec![Wrench2::default(); bodies0.len()];
        let mut present = vec![true; all.keys.len()];
        let (mut patches, mut builds, mut holes_filled) = (0, 0, 0);
        for k in 0..200u64 {
            // Most samples toggle one or two contacts; every 50th toggles a fifth of them.
            let toggles = if k % 50 == 49 {
                12
            } else {
                1 + (next() % 2) as usize
            };
            if k > 0 {
                for _ in 0..toggles {
                    let i = (next() % present.len() as u64) as usize;
                    present[i] = !present[i];
                }
            }
            let list = Column {
                contacts: (0..present.len())
                    .filter(|&i| present[i])
                    .map(|i| all.contacts[i])
                    .collect(),
                keys: (0..present.len())
                    .filter(|&i| present[i])
                    .map(|i| all.keys[i])
                    .collect(),
            };
            for bodies in [&mut b_p, &mut b_b] {
                for (i, b) in bodies.iter_mut().enumerate().skip(1) {
                    let phase = 0.1 * k as f64 + i as f64;
                    b.vel = Vec2::new(0.01 * phase.sin(), -0.05 * phase.cos());
                    b.omega = 0.2 * (phase * 0.7).sin();
                    b.force = Vec2::new(0.0, -9.81);
                    b.torque = 0.0;
                }
            }
            let holes_before = patched.holes;
            let n = list.keys.len();
            let r_p = pass(
                &mut patched,
                sweeps,
                list.view(n, k + 1),
                &mut b_p,
                &mut wrenches,
            );
            let r_b = pass(
                &mut built,
                sweeps,
                list.view(n, k + 1),
                &mut b_b,
                &mut wrenches,
            );
            assert!(!built.last_patched, "{k}");
            assert!(r_p >= -1e-12 && r_b >= -1e-12, "{k}: passive: {r_p} {r_b}");
            assert_eq!(patched.last_rows, built.last_rows, "{k}");
            if patched.last_patched {
                patches += 1;
                let (died, born) = patched.last_patch_size;
                holes_filled += (holes_before + died)
                    .saturating_sub(patched.holes)
                    .min(born);
            } else if !patched.last_refreshed {
                builds += 1;
            }
            // Every place that is no row is an exact no-op hole.
            let live: std::collections::BTreeSet<u32> = patched.place.iter().copied().collect();
            assert_eq!(live.len(), patched.keys.len());
            for (p, row) in patched.sorted.iter().enumerate() {
                if !live.contains(&(p as u32)) {
                    assert_eq!(patched.src[p], NONE, "{k}: hole {p}");
                    assert_eq!((row.w, row.neg_c, row.lo, row.lambda), (0.0, 0.0, 0.0, 0.0));
                    assert_eq!((row.n, row.rna, row.rnb), (Vec2::ZERO, 0.0, 0.0));
                }
            }
            assert_eq!(
                patched.sorted.len() - patched.keys.len(),
                patched.holes,
                "{k}"
            );
            if sweeps > 0 {
                continue;
            }
            // Without sweeps the rows are the warm start: the same rows key by key.
            let (rp, rb) = (rows_by_key(&patched), rows_by_key(&built));
            assert_eq!(rp.len(), rb.len(), "{k}");
            for ((kp, p), (kb, b)) in rp.iter().zip(&rb) {
                assert_eq!(kp, kb, "{k}");
                assert_eq!((p.a, p.b, p.n), (b.a, b.b, b.n), "{k}: {kp:?}");
                for (x, y) in [
                    (p.rna, b.rna),
                    (p.rnb, b.rnb),
                    (p.w, b.w),
                    (p.neg_c, b.neg_c),
                    (p.lo, b.lo),
                ] {
                    assert_eq!(x.to_bits(), y.to_bits(), "{k}: {kp:?}");
                }
                assert!(
                    (p.lambda - b.lambda).abs() <= 1e-12 * b.lambda.abs().max(1e-12),
                    "{k}: {kp:?}: {} {}",
                    p.lambda,
                    b.lambda
                );
            }
            for (a, b) in b_p.iter().zip(&b_b) {
                assert!((a.force - b.force).length() <= 1e-9, "{k}");
                assert!((a.torque - b.torque).abs() <= 1e-9, "{k}");
            }
        }
        assert!(patches > 150, "sweeps {sweeps}: {patches} patches");
        assert!(builds >= 4, "sweeps {sweeps}: {builds} builds");
        assert!(
            holes_filled > 10,
            "sweeps {sweeps}: {holes_filled} holes filled"
        );
    }
}

/// The capacities of a damper's row buffers (a change means a reallocation).
fn capacities(d: &ChainDamping) -> [usize; 8] {
    [
        d.sorted.capacity(),
        d.src.capacity(),
        d.colour_of.capacity(),
        d.hole_next.capacity(),
        d.keys.capacity(),
        d.prev_keys.capacity(),
        d.place.capacity(),
        d.new_place.capacity(),
    ]
}

/// A build leaves room for every row the patches may append before the next build, so a
/// patch never reallocates in the tick: 60 rows built, then one new contact per sample,
/// each appended (no holes to fill) until the budget (16) forces a build.
#[test]
fn a_patch_appends_within_the_room_a_build_left() {
    let (bodies0, all) = tall_column(40);
    let mut d = ChainDamping::default();
    let mut bodies = bodies0.clone();
    let mut wrenches = vec![Wrench2::default(); bodies0.len()];
    let mut built = None;
    for k in 0..18usize {
        let n = 60 + k;
        pass(
            &mut d,
            2,
            all.view(n, k as u64 + 1),
            &mut bodies,
            &mut wrenches,
        );
        assert_eq!(d.last_rows, n);
        if k == 0 {
            assert!(!d.last_patched && !d.last_refreshed);
            built = Some(capacities(&d));
        } else if k <= 16 {
            assert!(d.last_patched, "sample {k}");
            assert_eq!(d.last_patch_size, (0, 1), "sample {k}");
            assert_eq!(Some(capacities(&d)), built, "sample {k}: reallocated");
        } else {
            // The 17th append would pass the budget.
            assert!(!d.last_patched, "sample {k}: past the budget, built again");
        }
    }
}

/// The forces the damper adds are its rows' impulses over the sample: a dynamic body's, taken
/// from the momentum the sweeps gave it, equals the sum over its rows to round-off, as does the
/// fixed floor's, summed over its rows; and the forces and the torques about
/// the origin of all bodies sum to zero (each row pushes its two bodies equally and oppositely).
#[test]
fn the_dampers_forces_are_the_sums_of_their_rows_impulses() {
    let (mut bodies, loaded) = tall_column(12);
    for (i, b) in bodies.iter_mut().enumerate().skip(1) {
        let k = i as f64;
        b.vel = Vec2::new(0.01 * k * (-1.0f64).powi(i as i32), -0.1 * k);
        b.omega = 0.3 * (-1.0f64).powi(i as i32);
    }
    let mut wrenches = vec![Wrench2::default(); bodies.len()];
    let mut chain = ChainDamping::default();
    let dt = 1e-3;
    pass(
        &mut chain,
        16,
        loaded.view(loaded.contacts.len(), 1),
        &mut bodies,
        &mut wrenches,
    );
    assert_eq!(chain.last_rows, 24);
    // The forces row by row, as the impulses define them.
    let mut by_rows = vec![Wrench2::default(); bodies.len()];
    for row in &chain.sorted {
        let (a, b) = (row.a as usize, row.b as usize);
        let f = row.n * (row.lambda / dt);
        by_rows[a].force += f;
        by_rows[a].torque += row.rna * row.lambda / dt;
        by_rows[b].force -= f;
        by_rows[b].torque -= row.rnb * row.lambda / dt;
    }
    let scale = by_rows
        .iter()
        .map(|w| w.force.length().max(w.torque.abs()))
        .fold(0.0, f64::max);
    assert!(scale > 1.0, "the dampers push: largest {scale} N");
    for (i, (w, r)) in wrenches.iter().zip(&by_rows).enumerate() {
        assert!(
            (w.force - r.force).length() <= 1e-12 * scale
                && (w.torque - r.torque).abs() <= 1e-12 * scale,
            "body {i}: {w:?} against the rows' {r:?}"
        );
        assert_eq!(w.force, bodies[i].force, "body {i}: wrench and held force");
        assert_eq!(
            w.torque, bodies[i].torque,
            "body {i}: wrench and held torque"
        );
    }
    assert!(wrenches[0].force.y < -1.0, "the floor is pushed down");
    let mut net_force = Vec2::ZERO;
    let mut net_torque = 0.0;
    for (w, b) in wrenches.iter().zip(&bodies) {
        net_force += w.force;
        net_torque += w.torque + cross(b.pose.pos, w.force);
    }
    assert!(
        net_force.length() <= 1e-12 * scale && net_torque.abs() <= 1e-12 * scale,
        "net force {net_force:?}, net torque {net_torque}"
    );
}
