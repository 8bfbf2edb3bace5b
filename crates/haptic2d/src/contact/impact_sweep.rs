//! The sparse impact path's working set (§7.7, issue 42): one island's bodies gathered into
//! compact solver bodies and its rows into sweep rows, so that the projected Gauss–Seidel sweeps of
//! [`ImpactSolver`](super::impact::ImpactSolver)'s sparse path read and write two contiguous
//! arrays instead of the world's `Body` records (Box2D's `b2GatherBodies` / `b2ScatterBodies`;
//! the chain damper's `SolverBody` does the same).
//!
//! **Same bits.** Every operation is the one the sweeps on the bodies did, in the same order:
//! - a row's velocity `G_i·u` is `(j₀·v_x + j₁·v_y + j₂·ω)` of A plus the same of B, in that order;
//! - an impulse `p` adds `k·p` to each twist entry with `k = (1/m)·j` (or `(1/I)·j₂`) computed
//!   once per row: `v += (1/m)·j·p` evaluates as `((1/m)·j)·p`, so the hoisted product is the
//!   same number; A's block is applied before B's, so a row whose two bodies are one body sees the
//!   same sequence of additions;
//! - a row with `A_ii ≤ 0` (skipped by the sweeps on the bodies) has `1/A_ii = 0` here and is
//!   swept: its impulse starts at `+0`, `max(+0 − w·0, 0)` is `+0` for every `w` (NaN included,
//!   `select_max` returning its second argument), so its increment is `+0` and it applies nothing.
//!
//! Every fixed body shares slot 0, a twist of `+0` with zero inverse mass (its Jacobian block and
//! `k` are zero): the world keeps fixed bodies at rest (`+0` velocities, `tests/it/fixed_body_velocity.rs`),
//! so reading slot 0 gives the same `+0` products as reading the body, and `+0 + (+0·p)` stays `+0`
//! for every finite `p`. Slot 0 is never scattered back. (A caller of the public solver that gives a
//! fixed body a non-zero velocity sees it read as at rest, as [`ImpactRow::normal_velocity`] documents.)

use super::impact::ImpactRow;
use crate::body::Body;
use crate::geom::select_max;

/// The slot every fixed body reads: a twist at rest, never written back.
const FIXED_SLOT: u32 = 0;
/// `slot_of` entry of a body not in the island being solved.
const UNSEEN: u32 = u32::MAX;

/// One row as the sweeps read it: its bodies' slots, `1/A_ii`, the Jacobian `G_i` and `M⁻¹·G_iᵀ`.
#[derive(Clone, Copy, Debug, Default)]
struct SweepRow {
    /// Slot of body A (the vertex's).
    a: u32,
    /// Slot of body B (the edge's).
    b: u32,
    /// `1/A_ii` (kg; 0 where `A_ii ≤ 0`).
    inv_diag: f64,
    /// `G_i`, A's block `(n, r_A × n)` and B's `(−n, −(r_B × n))` (zero for a fixed body),
    /// interleaved entry by entry, `(A₀, B₀, A₁, B₁, A₂, B₂)`: the two blocks' products are then
    /// pairs in memory, and the compiler computes them two at a time without shuffling.
    j: [f64; 6],
    /// `M⁻¹·G_iᵀ` in block order, not interleaved: `(A₀/m_A, A₁/m_A, A₂/I_A, B₀/m_B, B₁/m_B, B₂/I_B)`
    /// ((m/s, rad/s) per N·s), each the product `(1/m)·G` the sweeps on the bodies formed first.
    k: [f64; 6],
}

impl SweepRow {
    /// The slots of A and B, as indices.
    #[inline(always)]
    fn slots(&self) -> (usize, usize) {
        (self.a as usize, self.b as usize)
    }

    /// `G_i·u` (m/s) from the twists `ta` of A and `tb` of B.
    #[inline(always)]
    fn velocity(&self, ta: &[f64; 3], tb: &[f64; 3]) -> f64 {
        let j = &self.j;
        (j[0] * ta[0] + j[2] * ta[1] + j[4] * ta[2]) + (j[1] * tb[0] + j[3] * tb[1] + j[5] * tb[2])
    }

    /// Adds `M⁻¹·G_iᵀ·p` to the twists `t` at A's slot `a` and B's slot `b`: A's block, then
    /// B's (re-read, as A may be B).
    #[inline(always)]
    fn apply(&self, t: &mut [[f64; 3]], (a, b): (usize, usize), p: f64) {
        let k = &self.k;
        let ta = &mut t[a];
        ta[0] += k[0] * p;
        ta[1] += k[1] * p;
        ta[2] += k[2] * p;
        let tb = &mut t[b];
        tb[0] += k[3] * p;
        tb[1] += k[4] * p;
        tb[2] += k[5] * p;
    }
}

/// One body of a row being gathered: its slot and inverse masses (1/kg, 1/(kg·m²)).
struct Side {
    slot: u32,
    inv_mass: f64,
    inv_inertia: f64,
}

/// The gathered island: sweep rows in the impact set's order and the solver bodies' twists.
///
/// Owns its buffers; they grow only with a larger island (or, for `slot_of`, a longer body slice)
/// than any before, so steady-state solves do not allocate.
#[derive(Clone, Debug, Default)]
pub(super) struct SparseIsland {
    /// One per row of the set, in its order.
    rows: Vec<SweepRow>,
    /// `(v_x, v_y, ω)` (m/s, rad/s) of each slot; slot 0 is the fixed bodies' rest.
    twists: Vec<[f64; 3]>,
    /// Body index of each slot from 1 on (where its twist is scattered back).
    body_of: Vec<u32>,
    /// Slot of each body of the island, [`UNSEEN`] for every other body (reset by `scatter`).
    slot_of: Vec<u32>,
}

impl SparseIsland {
    /// Room for `rows` rows (and their at most `2·rows` bodies) without allocating.
    pub(super) fn reserve(&mut self, rows: usize) {
        self.rows.reserve(rows.saturating_sub(self.rows.len()));
        let bodies = 2 * rows + 1;
        self.twists
            .reserve(bodies.saturating_sub(self.twists.len()));
        self.body_of
            .reserve(bodies.saturating_sub(self.body_of.len()));
    }

    /// Room for a body slice of `bodies` bodies (`slot_of`, which `gather` grows otherwise).
    pub(super) fn reserve_bodies(&mut self, bodies: usize) {
        if self.slot_of.len() < bodies {
            self.slot_of.resize(bodies, UNSEEN);
        }
    }

    /// Gathers `rows` and the twists of their dynamic bodies from `bodies` (which the sweeps then
    /// leave alone until [`scatter`](Self::scatter)). `1/A_ii` is computed as the sweeps on the
    /// bodies computed it.
    ///
    /// # Panics
    /// If a row's body is not an index into `bodies`.
    pub(super) fn gather(&mut self, rows: &[ImpactRow], bodies: &[Body]) {
        if self.slot_of.len() < bodies.len() {
            self.slot_of.resize(bodies.len(), UNSEEN);
        }
        self.rows.clear();
        self.twists.clear();
        self.body_of.clear();
        self.twists.push([0.0; 3]);
        self.body_of.push(UNSEEN);
        for row in rows {
            let (a, b) = (self.side(bodies, row.body_a), self.side(bodies, row.body_b));
            let j = row.jacobian_of(a.slot != FIXED_SLOT, b.slot != FIXED_SLOT);
            let (mut d, mut k) = (0.0, [0.0; 6]);
            for (off, s) in [(0usize, &a), (3, &b)] {
                d += s.inv_mass * (j[off] * j[off] + j[off + 1] * j[off + 1])
                    + s.inv_inertia * j[off + 2] * j[off + 2];
                k[off] = s.inv_mass * j[off];
                k[off + 1] = s.inv_mass * j[off + 1];
                k[off + 2] = s.inv_inertia * j[off + 2];
            }
            let (a, b) = (a.slot, b.slot);
            let inv_diag = if d > 0.0 { 1.0 / d } else { 0.0 };
            self.rows.push(SweepRow {
                a,
                b,
                inv_diag,
                j: [j[0], j[3], j[1], j[4], j[2], j[5]],
                k,
            });
        }
    }

    /// `bodies[i]` as a row sees it, read once: its slot (given one, with its twist, on first
    /// sight; [`FIXED_SLOT`] for a fixed body) and its inverse masses.
    #[inline]
    fn side(&mut self, bodies: &[Body], i: usize) -> Side {
        let body = &bodies[i];
        let slot = if !body.is_dynamic() {
            FIXED_SLOT
        } else if self.slot_of[i] == UNSEEN {
            let s = self.twists.len() as u32;
            self.slot_of[i] = s;
            self.twists.push([body.vel.x, body.vel.y, body.omega]);
            self.body_of.push(i as u32);
            s
        } else {
            self.slot_of[i]
        };
        Side {
            slot,
            inv_mass: body.inv_mass,
            inv_inertia: body.inv_inertia,
        }
    }

    /// Writes the island's twists back to its dynamic bodies and forgets their slots.
    pub(super) fn scatter(&mut self, bodies: &mut [Body]) {
        for (t, &bi) in self.twists.iter().zip(&self.body_of).skip(1) {
            let b = &mut bodies[bi as usize];
            (b.vel.x, b.vel.y, b.omega) = (t[0], t[1], t[2]);
            self.slot_of[bi as usize] = UNSEEN;
        }
    }

    /// `G u` (m/s) of every row for the current twists, into `out` (one per row).
    pub(super) fn normal_velocities(&self, out: &mut [f64]) {
        let t = &self.twists[..];
        for (r, o) in self.rows.iter().zip(out) {
            let (a, b) = r.slots();
            *o = r.velocity(&t[a], &t[b]);
        }
    }

    /// Applies `Δu = M⁻¹Gᵀp` for the impulses `p` (N·s, one per row; zero rows skipped).
    pub(super) fn apply_impulses(&mut self, p: &[f64]) {
        for (r, &p) in self.rows.iter().zip(p) {
            if p != 0.0 {
                r.apply(&mut self.twists, r.slots(), p);
            }
        }
    }

    /// One projected Gauss–Seidel sweep over the rows in order, `λ_i ← max(0, λ_i − (G_i·u)/A_ii)`
    /// with each increment applied to the twists at once; `acc` holds `λ` (N·s, one per row).
    /// Returns the sweep's largest `|Δλ_i|` (N·s).
    pub(super) fn sweep(&mut self, acc: &mut [f64]) -> f64 {
        let mut max_delta = 0.0f64;
        let t = &mut self.twists[..];
        for (r, acc) in self.rows.iter().zip(acc.iter_mut()) {
            let (a, b) = r.slots();
            let w = r.velocity(&t[a], &t[b]);
            let new = select_max(*acc - w * r.inv_diag, 0.0);
            let delta = new - *acc;
            *acc = new;
            if delta != 0.0 {
                max_delta = select_max(delta.abs(), max_delta);
                r.apply(t, (a, b), delta);
            }
        }
        max_delta
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Pose, Vec2};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The reference: the sweeps as they ran on the `Body` records before the island was
    /// gathered (issue 42, session 30), one function per operation.
    mod reference {
        use super::*;

        /// `J·(v_x, v_y, ω)` of one block.
        fn dot(j: &[f64], b: &Body) -> f64 {
            j[0] * b.vel.x + j[1] * b.vel.y + j[2] * b.omega
        }

        /// `G_i·u` (m/s).
        pub fn velocity(j: &[f64; 6], r: &ImpactRow, bodies: &[Body]) -> f64 {
            dot(&j[0..3], &bodies[r.body_a]) + dot(&j[3..6], &bodies[r.body_b])
        }

        /// `Δu = M⁻¹·G_iᵀ·p` on the dynamic bodies of row `r`.
        pub fn apply(j: &[f64; 6], r: &ImpactRow, bodies: &mut [Body], p: f64) {
            for (off, bi) in [(0usize, r.body_a), (3, r.body_b)] {
                let b = &mut bodies[bi];
                if b.is_dynamic() {
                    b.vel.x += b.inv_mass * j[off] * p;
                    b.vel.y += b.inv_mass * j[off + 1] * p;
                    b.omega += b.inv_inertia * j[off + 2] * p;
                }
            }
        }

        /// `1/A_ii`, 0 where `A_ii ≤ 0`.
        pub fn inv_diag(j: &[f64; 6], r: &ImpactRow, bodies: &[Body]) -> f64 {
            let mut d = 0.0;
            for (off, bi) in [(0usize, r.body_a), (3, r.body_b)] {
                let b = &bodies[bi];
                d += b.inv_mass * (j[off] * j[off] + j[off + 1] * j[off + 1])
                    + b.inv_inertia * j[off + 2] * j[off + 2];
            }
            if d > 0.0 {
                1.0 / d
            } else {
                0.0
            }
        }

        /// One sweep on the bodies, rows with `A_ii ≤ 0` skipped; the largest `|Δλ|`.
        pub fn sweep(rows: &[ImpactRow], bodies: &mut [Body], acc: &mut [f64]) -> f64 {
            let mut max_delta = 0.0f64;
            for (i, r) in rows.iter().enumerate() {
                let j = r.jacobian(bodies);
                let inv = inv_diag(&j, r, bodies);
                if inv <= 0.0 {
                    continue;
                }
                let w = velocity(&j, r, bodies);
                let new = select_max(acc[i] - w * inv, 0.0);
                let delta = new - acc[i];
                acc[i] = new;
                if delta != 0.0 {
                    max_delta = select_max(delta.abs(), max_delta);
                    apply(&j, r, bodies, delta);
                }
            }
            max_delta
        }
    }

    /// A seeded random pile-like island on `2 + boxes` bodies (a floor and a wall, fixed, first):
    /// each box on the one below (the floor under the first), two corner rows per interface,
    /// every third box against the one two below and against the wall, random masses, normals,
    /// lever arms and twists; plus a row whose two bodies are one box and a row between the two
    /// fixed bodies (`A_ii = 0`).
    fn random_island(seed: u64, boxes: usize) -> (Vec<Body>, Vec<ImpactRow>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut bodies = vec![
            Body::fixed("floor", Pose::IDENTITY),
            Body::fixed("wall", Pose::new(-1.0, 0.5, 0.0)),
        ];
        for k in 0..boxes {
            let m = rng.random_range(0.5..3.0);
            let mut b = Body::dynamic(
                format!("b{k}"),
                m,
                m * 4e-4,
                Pose::new(0.0, 0.05 * k as f64, 0.0),
            );
            b.vel = Vec2::new(rng.random_range(-0.3..0.3), rng.random_range(-2.0..0.2));
            b.omega = rng.random_range(-3.0..3.0);
            bodies.push(b);
        }
        let row = |rng: &mut ChaCha8Rng, a: usize, b: usize| {
            let t: f64 = rng.random_range(-0.3..0.3);
            let lever = |rng: &mut ChaCha8Rng| {
                Vec2::new(rng.random_range(-0.03..0.03), rng.random_range(-0.03..0.03))
            };
            ImpactRow {
                body_a: a,
                body_b: b,
                n: Vec2::new(t.sin(), t.cos()),
                r_a: lever(rng),
                r_b: lever(rng),
                restitution: 0.0,
            }
        };
        let mut rows = Vec::new();
        for k in 0..boxes {
            let upper = 2 + k;
            let lower = if k == 0 { 0 } else { upper - 1 };
            rows.push(row(&mut rng, upper, lower));
            rows.push(row(&mut rng, upper, lower));
            if k % 3 == 2 {
                rows.push(row(&mut rng, upper, upper - 2));
                rows.push(row(&mut rng, upper, 1));
            }
        }
        rows.insert(rows.len() / 2, row(&mut rng, 4, 4));
        rows.insert(rows.len() / 3, row(&mut rng, 0, 1));
        (bodies, rows)
    }

    fn bits(b: &Body) -> [u64; 3] {
        [b.vel.x.to_bits(), b.vel.y.to_bits(), b.omega.to_bits()]
    }

    /// The gathered island gives the reference's velocities, impulses, sweep increments and
    /// bodies' twists bit for bit, sweep after sweep, through impulses applied between sweeps and
    /// through a second island on the same body slice.
    #[test]
    fn the_gathered_island_sweeps_bit_for_bit_as_the_bodies_did() {
        for seed in 0..8 {
            let (start, rows) = random_island(seed, 40);
            let n = rows.len();
            let (mut expect, mut got) = (start.clone(), start.clone());
            let mut island = SparseIsland::default();
            // Two islands in turn: the first half of the rows, then all of them.
            for set in [&rows[..n / 2], &rows[..]] {
                let m = set.len();
                island.gather(set, &got);
                let jac: Vec<[f64; 6]> = set.iter().map(|r| r.jacobian(&expect)).collect();
                let mut out = vec![0.0; m];
                island.normal_velocities(&mut out);
                for i in 0..m {
                    let v = reference::velocity(&jac[i], &set[i], &expect);
                    assert_eq!(out[i].to_bits(), v.to_bits(), "seed {seed} row {i}");
                }
                let (mut acc_ref, mut acc) = (vec![0.0; m], vec![0.0; m]);
                let mut rng = ChaCha8Rng::seed_from_u64(100 + seed);
                for sweep in 0..12 {
                    let dr = reference::sweep(set, &mut expect, &mut acc_ref);
                    let dg = island.sweep(&mut acc);
                    assert_eq!(dg.to_bits(), dr.to_bits(), "seed {seed} sweep {sweep}");
                    for i in 0..m {
                        assert_eq!(
                            acc[i].to_bits(),
                            acc_ref[i].to_bits(),
                            "seed {seed} row {i}"
                        );
                    }
                    // Impulses between sweeps (restitution, a correction), some of them zero.
                    let p: Vec<f64> = (0..m)
                        .map(|_| {
                            if rng.random_bool(0.3) {
                                0.0
                            } else {
                                rng.random_range(-0.1..0.2)
                            }
                        })
                        .collect();
                    island.apply_impulses(&p);
                    for i in 0..m {
                        if p[i] != 0.0 {
                            reference::apply(&jac[i], &set[i], &mut expect, p[i]);
                        }
                    }
                }
                island.scatter(&mut got);
                for (x, y) in expect.iter().zip(&got) {
                    assert_eq!(bits(x), bits(y), "seed {seed}: {}", x.name);
                }
            }
            // The sweeps changed the boxes, and never a fixed body.
            assert!(got[2..]
                .iter()
                .zip(&start[2..])
                .any(|(x, y)| bits(x) != bits(y)));
            assert_eq!(
                (got[0].vel, got[0].omega, got[1].vel, got[1].omega),
                (Vec2::ZERO, 0.0, Vec2::ZERO, 0.0)
            );
        }
    }

    /// Bodies outside the island are left alone: `scatter` writes only the island's bodies, and
    /// forgets their slots for the next island.
    #[test]
    fn scatter_writes_the_island_bodies_only_and_forgets_their_slots() {
        let (start, rows) = random_island(7, 12);
        let mut bodies = start.clone();
        let mut island = SparseIsland::default();
        // Rows of the lowest three boxes only (bodies 2..=4 and the floor).
        let low: Vec<ImpactRow> = rows
            .iter()
            .copied()
            .filter(|r| r.body_a <= 4 && r.body_b <= 4 && r.body_a != r.body_b)
            .collect();
        island.gather(&low, &bodies);
        let mut acc = vec![0.0; low.len()];
        for _ in 0..4 {
            island.sweep(&mut acc);
        }
        island.scatter(&mut bodies);
        assert!(island.slot_of.iter().all(|&s| s == UNSEEN));
        assert!((2..=4).any(|i| bits(&bodies[i]) != bits(&start[i])));
        for i in (0..2).chain(5..bodies.len()) {
            assert_eq!(bits(&bodies[i]), bits(&start[i]), "{}", start[i].name);
        }
    }
}
