//! Implicit damping of contact chains (issue 17): the damper that lets a stack come to rest.
//!
//! **Why.** Every contact is an explicit spring–damper (`Kc`, `Bc`, §5.9), so its damping is
//! proportional to its stiffness (`Bc/Kc = 0.4 ms` in the pile). For a chain of such interfaces
//! the modal damping is `ζ_i = (Bc/Kc)·ω_i/2`: the slow collective modes of a tall stack are
//! barely damped (pile:1000, 40 rows: `ω_1 ≈ 17 rad/s`, decay rate `≈ 0.16 s⁻¹` measured, the
//! pile "breathes" for tens of seconds; docs/PERFORMANCE.md). A larger `Bc` is not available:
//! the force pass is explicit and a body with `C` contacts sees `T·Bc·C·w ≈ 0.8` already, against
//! an explicit stability bound of about 1.
//!
//! **What.** For every contact of a *chain* — a Continuous, loaded (`f_n > 0`) record of which a
//! dynamic body touches at least two other bodies — an extra normal damper
//! `B_c = m_c/τ` (`m_c = 1/w` the contact's effective normal mass,
//! `w = 1/m_A + 1/m_B + (r_A×n)²/I_A + (r_B×n)²/I_B`, `τ` = `WorldParams::chain_tau`) acts on the
//! *end-of-sample* relative normal velocity (backward Euler): `F = −B_c·v⁺_n`, solved for all
//! chain contacts together by projected Gauss–Seidel (warm-started from the last sample's
//! impulses, rows in a greedy graph colouring, at most `chain_sweeps` sweeps, stopping once
//! converged; see [`ChainDamping::apply`]) with the bound `F ≥ −f_n` (the damper may cancel the
//! law's push but never pulls). Implicit, it is stable for any `τ > 0` and any number of contacts
//! per body, so a contact can be damped near or above critical and the collective modes decay.
//!
//! **Passive.** With `v*` the velocities the integrator would reach without this damper, impulses
//! `λ` change the kinetic energy by `λᵀv* + ½λᵀWλ = Φ(λ) − ½λᵀK⁻¹λ`, where
//! `Φ(λ) = ½λᵀ(W + K⁻¹)λ + λᵀv*` (`K = diag(T·B_c)`) is the convex function that projected
//! Gauss–Seidel decreases monotonically inside a box that contains 0, from any start with
//! `Φ ≤ Φ(0) = 0` (zero impulses, or the warm start scaled to the exact minimiser of `Φ` along
//! it). So `ΔKE ≤ −½λᵀK⁻¹λ ≤ 0` after every sweep, whatever the number of sweeps: the pass only
//! removes energy (returned by [`ChainDamping::apply`]). Positions then advance with the damped
//! velocity (semi-implicit Euler), as they do with any other held force.
//!
//! **Work budget** (issue 42 item 2; `WorldParams::chain_budget`, MODELS §6.7). A sample's sweeps
//! run at most a budget of row updates (one row update: one row's projected update; a sweep is
//! one per row of `sorted`, holes included): before each sweep after the first, they stop if
//! that whole sweep would take the sample past the budget. The first sweep always runs, so a
//! sample does at most `max(budget, one sweep)` row updates and at least a settled sample's one
//! sweep. Passive by the argument above, which holds after every sweep: stopping at the budget is
//! stopping after some number of sweeps, bit for bit the solve with that sweep limit (test
//! `a_budget_cut_is_exactly_a_smaller_sweep_limit`). What it costs: a cut sample has not
//! converged, so `F ≠ −B_c·v⁺` in that sample (it removes less energy than the converged solve;
//! its impulses warm-start the next sample). The default is derived from the sample period
//! (`WorkBudget::FromPeriod`).
//!
//! **Choice of τ and sweeps** (pile:1000 at 1 kHz, `haptic2d-bench --settle 6 --every 0.25 (or
//! 0.05) --set world.chain_tau=τ,world.chain_sweeps=S`; "at rest from" = the first check after
//! which no body moved ≥ 1 cm/s): off, 1000 bodies moving at 6 s; τ = 1 ms / 8 sweeps, 4.5 s
//! (0.0098 m/s at 5 s: no margin); 0.5 ms / 8, 3.75 s; 0.5 ms / 12 and / 16, blips of 1–2 cm/s
//! up to 3.2–5 s; 0.2 ms / 8, 2.25 s; 0.1 ms / 4, *never* (500 bodies at 0.1 m/s at 5 s);
//! **0.2 ms / 16, 2.15 s** (0.05 s checks; largest speed after 2.5 s 6.8 mm/s; the default).
//! Those are cold sweeps (from zero). Warm-started (session 7): at most 4 / 6 / 8 / 16 sweeps
//! gave rest from 2.35 / 2.05 / 2.65 / 2.15 s, and with the convergence stop (1e-5 m/s) at most
//! 16 gives 2.15 s while a settled pile runs 1–4 sweeps. A stop at 1e-4 m/s (issue 17, session
//! 9; the default until session 15) gives the same rest time and largest speed after 2.5 s
//! (2.15 s, 6.7 mm/s) with 1.2 sweeps per sample over 1–5 s instead of 3.7, and the 25 aligned
//! 10-box stacks of `tests/it/stack_corners.rs` at 8.3e-4 m/s after 2 s (6.4e-4 with 1e-5). A stop
//! at 2e-4 m/s (session 15; the default) halves the samples that need four sweeps or more, the slowest
//! samples of a settling pile (pile:1000 over 1–3 s: 38 of 2000 samples, then 19; pile:5000 over
//! 1–5 s: 23 of 4000, then 15), with the same rest times (pile:100 0.16 s, pile:1000 2.15 s,
//! pile:5000 1.62 s then 1.61 s, pyramid 0.19 s: `--rest-time 5`), the same settle table to four
//! digits, and the stacks at 7.6e-4 m/s after 2 s; 5e-4 and 1e-3 left the stacks at 1.2e-3 and
//! 4.2e-3 m/s. 4 or 6 fixed sweeps left the 10-box stacks of `tests/it/stack_corners.rs` with
//! contacts churning after 2 s (4: 3.9 cm/s, 6: 7.7 mm/s), 8 passed (4.3 mm/s), 16 with the stop
//! 0.64 mm/s.
//! The sweeps matter beyond the pile: with 8 sweeps at τ = 0.2 ms the 25 aligned 10-box stacks
//! of `tests/it/stack_corners.rs` kept rocking (2 cm/s, contacts churning after 2 s); with 16 they
//! pass (2e-3 m/s). A sweep that has not converged leaves `F ≠ −B_c·v⁺` (still passive, but the
//! impulses then shuffle energy between the stack's modes instead of removing it).
//!
//! **Scope.** Bodies that touch only one other body (a box on the floor, a probe against a wall:
//! the paper's one- and two-contact scenes) are not chains: their contacts keep the explicit law
//! alone, bit for bit. The pass runs in [`IntegrationMode::SemiImplicit`](crate::integrate::IntegrationMode)
//! only, after the drive of the sample is known (`World::finish_step`); the contact wrench of a
//! body includes it after `finish_step` (before, in `begin_step`, only the explicit laws).

//!
//! A projected Gauss–Seidel contact solver with graph colouring, so it lives with the contact
//! solvers: this file holds the solve ([`ChainDamping::apply`]: warm start, sweeps, forces) and
//! the rows it sweeps; `rows.rs` the row set (which contacts are chain contacts, their colours,
//! and building, patching or refreshing the rows from the last sample's).

#[cfg(test)]
mod budget_tests;
mod rows;
#[cfg(test)]
mod sweep_tests;
#[cfg(test)]
mod tests;

use crate::body::Body;
use crate::collide::VeCandidate;
use crate::contact::{Loaded, LoadedContact, Wrench2};
use crate::geom::{cross, select_max, Vec2};

/// No partner yet (per-body scratch).
const NONE: u32 = u32::MAX;

/// Colours of the row graph; rows that find none of them free go to one last, overflow colour.
const COLOURS: u32 = 64;

/// One chain contact in the solve: the normal, lever arms, masses and impulse its update needs
/// (72 bytes, so the sweeps stream through a few hundred kB at most for a 1000-body pile).
#[derive(Clone, Copy, Debug)]
struct Row {
    /// Solver-body indices of A and B.
    a: u32,
    b: u32,
    n: Vec2,
    /// `r_A × n`, `r_B × n` (m).
    rna: f64,
    rnb: f64,
    /// Inverse effective normal mass `w` (1/kg).
    w: f64,
    /// `−c`, with `c = r/((1 + r)·w)` and `r = T/τ` (kg): the sweep's factor, stored negated so
    /// that the sweep does not negate it every time (`(−c)·x` is `−(c·x)` exactly).
    neg_c: f64,
    /// Lower bound `−T·f_n` of the impulse (N·s).
    lo: f64,
    /// Accumulated impulse (N·s, along `+n` on A).
    lambda: f64,
}

/// A body's velocity and inverse mass, as the sweeps read and write them.
#[derive(Clone, Copy, Debug, Default)]
struct SolverBody {
    v: Vec2,
    omega: f64,
    inv_mass: f64,
    inv_inertia: f64,
}

/// A body as the rows are built: its velocity without the dampers and inverse masses
/// ([`SolverBody`]), and its position (m), in one record, so that building a row reads one
/// place per body.
#[derive(Clone, Copy, Debug, Default)]
struct StarBody {
    s: SolverBody,
    pos: Vec2,
}

impl Row {
    /// A placeholder, overwritten before any sweep reads it.
    const NONE: Row = Row {
        a: 0,
        b: 0,
        n: Vec2::ZERO,
        rna: 0.0,
        rnb: 0.0,
        w: 0.0,
        neg_c: 0.0,
        lo: 0.0,
        lambda: 0.0,
    };

    /// The row of chain contact `e` between solver bodies `a` and `b` (body positions,
    /// velocities and inverse masses `star`; `r = T/τ`, `dt = T` in s), warm-started from the
    /// impulse `prev` (N·s) within this sample's bound. Its effective mass may be not finite
    /// and positive: [`valid`](Self::valid) says.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn build(
        e: &LoadedContact,
        a: u32,
        b: u32,
        star: &[StarBody],
        r: f64,
        dt: f64,
        prev: f64,
    ) -> Row {
        let (xa, xb) = (&star[a as usize], &star[b as usize]);
        let (sa, sb) = (&xa.s, &xb.s);
        let rna = cross(e.point - xa.pos, e.n);
        let rnb = cross(e.point - xb.pos, e.n);
        let w = sa.inv_mass + sb.inv_mass + sa.inv_inertia * rna * rna + sb.inv_inertia * rnb * rnb;
        let lo = -dt * e.f_n;
        // `prev > lo ? prev : lo`: what `f64::max` gives for a bound that is never NaN (a loaded
        // contact has `f_n > 0`), a NaN `prev` included (both give `lo`), in one instruction.
        let warm = select_max(prev, lo);
        Row {
            a,
            b,
            n: e.n,
            rna,
            rnb,
            w,
            neg_c: -(r / ((1.0 + r) * w)),
            lo,
            lambda: if finite(warm) { warm } else { 0.0 },
        }
    }

    /// Whether the effective mass is finite and positive.
    #[inline(always)]
    fn valid(&self) -> bool {
        (self.w > 0.0) & finite(self.w)
    }

    /// Relative normal velocity of the row's points (m/s; positive separating) in the working
    /// velocities `s`.
    #[inline(always)]
    fn v_rel(&self, s: &[SolverBody]) -> f64 {
        self.v_rel_of(&s[self.a as usize], &s[self.b as usize])
    }

    /// Relative normal velocity of the row's points (m/s) in the velocities without the dampers.
    #[inline(always)]
    fn v_rel_star(&self, star: &[StarBody]) -> f64 {
        self.v_rel_of(&star[self.a as usize].s, &star[self.b as usize].s)
    }

    /// Relative normal velocity of the row's points (m/s) with A and B moving as `a` and `b`.
    #[inline(always)]
    fn v_rel_of(&self, a: &SolverBody, b: &SolverBody) -> f64 {
        (a.v - b.v).dot(self.n) + a.omega * self.rna - b.omega * self.rnb
    }

    /// Applies the impulse `d` (N·s along `+n` on A, `−n` on B) to the working velocities.
    #[inline(always)]
    fn apply(&self, d: f64, s: &mut [SolverBody]) {
        let a = &mut s[self.a as usize];
        a.v += self.n * (a.inv_mass * d);
        a.omega += a.inv_inertia * self.rna * d;
        let b = &mut s[self.b as usize];
        b.v -= self.n * (b.inv_mass * d);
        b.omega -= b.inv_inertia * self.rnb * d;
    }
}

/// The implicit chain damper of a world (its parameters and reused buffers).
#[derive(Clone, Debug)]
pub struct ChainDamping {
    partner: Vec<u32>,
    multi: Vec<bool>,
    /// The sweeps' working velocities (`v*` as step 1 leaves them, then with the impulses).
    solver: Vec<SolverBody>,
    /// The velocities without the dampers, `v*` (semi-implicit Euler), and the positions.
    star: Vec<StarBody>,
    /// Rows in colour order (each colour's rows in contact-key order) as built; a patch leaves
    /// holes (no-op rows) where rows died, fills them with new rows of their colour and appends
    /// the others (see [`patch_rows`](Self::patch_rows)).
    sorted: Vec<Row>,
    /// Index in the sample's loaded list of each row of `sorted` (`NONE`: a hole), its colour,
    /// and the next hole of the same colour (`NONE`: the last).
    src: Vec<u32>,
    colour_of: Vec<u32>,
    hole_next: Vec<u32>,
    /// The first hole of each colour (`NONE`: none), the holes, and the rows appended after the
    /// colour buckets, since the last build.
    hole_head: Vec<u32>,
    holes: usize,
    appended: usize,
    /// Whether a change in the loaded contacts may patch the rows instead of building them
    /// (tests turn it off to compare with a build).
    patching: bool,
    /// The generation and length of the loaded list the rows were built from ([`Loaded`]; 0 =
    /// none), and which bodies are dynamic (this sample's, once step 1 has run; the last sample's
    /// before): when all are unchanged and the last build dropped no chain contact, the rows are
    /// refreshed in place.
    generation: u64,
    loaded_len: usize,
    dynamic: Vec<bool>,
    /// The last build dropped a chain contact whose effective mass was not finite and positive.
    dropped: bool,
    /// Colour of each row (key order), rows per colour (then each colour's next position in
    /// `sorted`), and colours used per body.
    colour: Vec<u32>,
    per_colour: Vec<u32>,
    used: Vec<u64>,
    /// Keys of this sample's rows (key order) and the place of each in `sorted`; the last
    /// sample's keys and impulses, for the warm start of a build; and the new keys, places and
    /// rows of a patch (scratch).
    keys: Vec<VeCandidate>,
    place: Vec<u32>,
    prev_keys: Vec<VeCandidate>,
    prev_lambda: Vec<f64>,
    new_place: Vec<u32>,
    dead: Vec<u32>,
    born: Vec<(u32, u32)>,
    /// Chain contacts damped in the last sample.
    pub last_rows: usize,
    /// Whether the last sample refreshed the rows of the sample before in place (its loaded
    /// contacts were the same) instead of building them.
    pub last_refreshed: bool,
    /// Whether the last sample patched the rows of the sample before (a few of its loaded
    /// contacts changed: see [`apply`](Self::apply)) instead of building them.
    pub last_patched: bool,
    /// The rows that died and the rows that were born in the last sample's patch.
    pub last_patch_size: (usize, usize),
    /// Sweeps run in the last sample (at most the `sweeps` asked for; fewer once converged or
    /// when the work budget stopped them).
    pub last_sweeps: u32,
    /// Row updates run in the last sample: its sweeps × its rows (holes included: a sweep visits
    /// them too).
    pub last_row_updates: u64,
    /// Whether the work budget stopped the last sample's sweeps (another sweep was due: the
    /// last one had not converged and fewer than `sweeps` had run).
    pub last_cut: bool,
    /// Samples whose sweeps the work budget stopped, since the damper was made.
    pub budget_cuts: u64,
    /// Row updates run since the damper was made.
    pub row_updates: u64,
    /// The most row updates run in one sample since the damper was made.
    pub max_row_updates: u64,
    /// Scale `s ∈ [0, 1]` of the warm start in the last sample (1 = the last sample's impulses
    /// kept whole; see [`ChainDamping::apply`]).
    pub last_warm_scale: f64,
}

/// A sweep that changes no row's relative velocity by more than this (m/s) ends the solve:
/// the impulses have converged (to 2 % of the 1 cm/s rest criterion; 1e-5 m/s ran three times
/// the sweeps for the same settling, and 1e-4 twice the slow samples of four sweeps or more,
/// module docs). Any number of sweeps is passive, so stopping early is too.
const CONVERGED: f64 = 2e-4;

/// Default damping time `τ` (s) of the chain damper (`WorldParams::chain_tau`).
pub const DEFAULT_CHAIN_TAU: f64 = 2.0e-4;
/// Default number of the chain damper's Gauss–Seidel sweeps (`WorldParams::chain_sweeps`).
pub const DEFAULT_CHAIN_SWEEPS: u32 = 16;

impl Default for ChainDamping {
    fn default() -> Self {
        Self {
            partner: Vec::new(),
            multi: Vec::new(),
            solver: Vec::new(),
            star: Vec::new(),
            sorted: Vec::with_capacity(64),
            src: Vec::with_capacity(64),
            colour_of: Vec::with_capacity(64),
            hole_next: Vec::with_capacity(64),
            hole_head: vec![NONE; COLOURS as usize + 1],
            holes: 0,
            appended: 0,
            patching: true,
            generation: 0,
            loaded_len: 0,
            dynamic: Vec::new(),
            dropped: false,
            colour: Vec::with_capacity(64),
            per_colour: vec![0; COLOURS as usize + 1],
            used: Vec::new(),
            keys: Vec::with_capacity(64),
            place: Vec::with_capacity(64),
            prev_keys: Vec::with_capacity(64),
            prev_lambda: Vec::with_capacity(64),
            new_place: Vec::with_capacity(64),
            dead: Vec::with_capacity(64),
            born: Vec::with_capacity(64),
            last_rows: 0,
            last_refreshed: false,
            last_patched: false,
            last_patch_size: (0, 0),
            last_sweeps: 0,
            last_row_updates: 0,
            last_cut: false,
            budget_cuts: 0,
            row_updates: 0,
            max_row_updates: 0,
            last_warm_scale: 0.0,
        }
    }
}

impl ChainDamping {
    /// Adds the chain dampers' forces of this sample to `wrenches` and to the bodies' held
    /// `force`/`torque` (which must hold every other force of the sample), given the loaded
    /// contacts of this sample (`loaded`, from
    /// [`ContactSet::loaded`](crate::contact::ContactSet::loaded); its keys must be sorted) and
    /// the sample period `dt`
    /// (s), with damping time `tau` (s: a chain contact's damper is `B_c = m_c/τ`, N·s/m; `None`
    /// = off) and at most `sweeps` Gauss–Seidel sweeps (each one passive; they stop once a sweep
    /// changes no row's relative velocity by more than 2e-4 m/s), within `budget` row updates
    /// (`None` = unbounded). Returns the kinetic energy the dampers remove over the sample (J, ≥ 0
    /// up to rounding).
    ///
    /// **Budget.** Before each sweep after the first, the sweeps stop if that whole sweep would
    /// take the sample's row updates past `budget` (`last_cut`, counted in `budget_cuts`): a
    /// sample runs at most `max(budget, rows)` row updates. The first sweep always runs, so the
    /// sample does at least the work of a settled one. Passive wherever it stops (module docs);
    /// a cut sample leaves `F ≠ −B_c·v⁺` in that sample.
    ///
    /// **Warm start.** The sweeps start from the last sample's impulses of the same contacts
    /// (by key), clamped to this sample's bounds and scaled by the `s ∈ [0, 1]` that minimises
    /// `Φ(s·λ₀) = s·g + ½s²·h` (`g = λ₀ᵀv*`, `h = λ₀ᵀ(W + K⁻¹)λ₀`, both exact, summed as the
    /// rows are built and sorted), so `Φ(s·λ₀) ≤ Φ(0) = 0`: the passivity argument of the module docs holds
    /// from there, and the sweeps only lower `Φ` further. A pile at rest changes its impulses
    /// little from sample to sample, so a few sweeps reach what many cold ones did.
    ///
    /// **Order.** Rows are coloured greedily in key order (no two rows of a colour share a
    /// dynamic body) and swept colour by colour: the updates of a colour are independent, so the
    /// processor overlaps them instead of waiting on the body a row just wrote. Deterministic.
    ///
    /// **Refresh.** When the loaded contacts are those of the last sample (same generation of
    /// keys, same length, same dynamic bodies: most samples of a pile at rest), so are the chain
    /// contacts, their colours and their order; the rows are then refreshed in place from the new
    /// geometry instead of being matched by key, coloured and sorted again (`last_refreshed`).
    ///
    /// **Patch.** When some loaded contacts changed but the dynamic bodies did not, the rows are
    /// patched (`last_patched`): the rows of contacts that left
    /// become no-op holes, new chain contacts take a colour and a hole of it or a place after the
    /// colour buckets, and then every row is refreshed. The rows are those a build gives, in
    /// another order, so the sweeps reach another point within the same convergence tolerance:
    /// deterministic, but dependent on the history of the contacts, not only on this sample's
    /// list. Past an eighth of the rows (at least 16) in holes and appended rows since the last
    /// build, the rows are built from scratch again, in colour order.
    #[allow(clippy::too_many_arguments)]
    pub fn apply(
        &mut self,
        tau: Option<f64>,
        sweeps: u32,
        budget: Option<u64>,
        dt: f64,
        loaded: Loaded<'_>,
        bodies: &mut [Body],
        wrenches: &mut [Wrench2],
    ) -> f64 {
        self.clear_last();
        let tau = match tau {
            Some(t) if t > 0.0 && t.is_finite() && dt > 0.0 => t,
            _ => {
                self.forget();
                return 0.0;
            }
        };
        // Per-body buffers are sized at the first call, before any contact, so that the first
        // contacts do not allocate on the hot path.
        let n = bodies.len();
        if self.partner.len() != n {
            self.partner.resize(n, NONE);
            self.multi.resize(n, false);
            self.solver.resize(n, SolverBody::default());
            self.star.resize(n, StarBody::default());
            self.used.resize(n, 0);
            self.dynamic.resize(n, false);
            self.forget();
        }
        if loaded.contacts.is_empty() || loaded.keys.len() != loaded.contacts.len() {
            self.forget();
            return 0.0;
        }
        // 1. The velocities the integrator would reach without the dampers (semi-implicit
        //    Euler), with the inverse masses the impulses act through (none for fixed bodies);
        //    the sweeps' working velocities start there.
        let (ke_star, same_bodies) = self.start_velocities(dt, bodies);
        // 2–4. The rows: refreshed in place when the loaded contacts are those of the last
        //      sample (a pile at rest, most samples), patched when a few of them changed, built
        //      from scratch otherwise.
        let r = dt / tau;
        let kept = same_bodies && !self.dropped && !self.keys.is_empty();
        let same = kept
            && loaded.generation == self.generation
            && loaded.contacts.len() == self.loaded_len;
        let mut partners_found = false;
        let mut gh = None;
        if same {
            gh = self.refresh_rows(r, dt, loaded.contacts);
            self.last_refreshed = gh.is_some();
        } else if kept && self.patching {
            self.find_partners(loaded.contacts);
            partners_found = true;
            if self.patch_rows(loaded) {
                gh = self.refresh_rows(r, dt, loaded.contacts);
                self.last_patched = gh.is_some();
            }
        }
        let (g, h) = match gh {
            Some(gh) => gh,
            None => self.build_rows(r, dt, loaded, partners_found),
        };
        if self.keys.is_empty() {
            self.forget();
            return 0.0;
        }
        self.last_rows = self.keys.len();
        let s = self.scale_warm_start(g, h);
        self.last_warm_scale = s;
        // 5. Projected Gauss–Seidel on F = −B_c·v⁺_n, F ≥ −f_n, until converged. The rows still
        //    hold the whole warm impulses: the first sweep scales each by `s` as it reads it.
        //    The sweeps take the rows and velocities as slices: their lengths and addresses stay
        //    in registers (a `Vec` behind `&mut` is reloaded after every store to a row).
        let (rows, solver) = (&mut self.sorted[..], &mut self.solver[..]);
        let mut scale = s;
        let (limit, per_sweep) = (budget.unwrap_or(u64::MAX), rows.len() as u64);
        for _ in 0..sweeps {
            // The budget: whole sweeps, the first always (passive wherever the sweeps stop).
            if self.last_sweeps > 0 && self.last_row_updates + per_sweep > limit {
                self.last_cut = true;
                break;
            }
            // Largest change of a row's relative velocity in this sweep (m/s). After the first
            // sweep the scale is 1 and `sweep` is inlined without the multiplication (`λ·1 = λ`
            // exactly).
            let largest = if scale == 1.0 {
                sweep(rows, solver, 1.0)
            } else {
                sweep(rows, solver, scale)
            };
            scale = 1.0;
            self.last_sweeps += 1;
            self.last_row_updates += per_sweep;
            if largest <= CONVERGED {
                break;
            }
        }
        self.count_work();
        if scale != 1.0 {
            // No sweep ran: the scaled warm impulses are the result.
            for row in self.sorted.iter_mut() {
                row.lambda *= scale;
            }
        }
        // 6. The impulses as forces held over the sample (the rows keep them for the next warm
        //    start). A dynamic body's share is the momentum the sweeps gave it, `m·(v − v*)/T`
        //    and `I·(ω − ω*)/T`: one pass over the bodies instead of four writes per row, which
        //    also sums the kinetic energy the sweeps left. A fixed body's velocity does not
        //    change; its share (the reaction, which its wrench reports) is summed over the rows
        //    that touch it.
        let inv_dt = 1.0 / dt;
        let mut ke = 0.0;
        let per_body = (self.solver.iter().zip(&self.star)).zip(&self.dynamic);
        for ((b, w), ((s, v), &dynamic)) in bodies.iter_mut().zip(&mut wrenches[..n]).zip(per_body)
        {
            let v = &v.s;
            if b.is_dynamic() {
                ke += kinetic_of(b, s.v, s.omega);
            }
            if !dynamic {
                continue; // summed over its rows below
            }
            let f = if v.inv_mass > 0.0 {
                (s.v - v.v) * (b.mass * inv_dt)
            } else {
                Vec2::ZERO
            };
            let t = if v.inv_inertia > 0.0 {
                (s.omega - v.omega) * (b.inertia * inv_dt)
            } else {
                0.0
            };
            w.force += f;
            w.torque += t;
            b.force += f;
            b.torque += t;
        }
        self.add_fixed_reactions(inv_dt, bodies, wrenches);
        ke_star - ke
    }

    /// Step 6 for the bodies that are not dynamic: the reaction of each row's impulse (held
    /// over the sample, `1/T = inv_dt`) added to their wrench and held force, row by row.
    fn add_fixed_reactions(&self, inv_dt: f64, bodies: &mut [Body], wrenches: &mut [Wrench2]) {
        let dynamic = &self.dynamic;
        for row in &self.sorted {
            let (a, b) = (row.a as usize, row.b as usize);
            if dynamic[a] && dynamic[b] {
                continue;
            }
            let f = row.n * (row.lambda * inv_dt);
            if !dynamic[a] {
                let ta = row.rna * row.lambda * inv_dt;
                wrenches[a].force += f;
                wrenches[a].torque += ta;
                bodies[a].force += f;
                bodies[a].torque += ta;
            }
            if !dynamic[b] {
                let tb = row.rnb * row.lambda * inv_dt;
                wrenches[b].force -= f;
                wrenches[b].torque -= tb;
                bodies[b].force -= f;
                bodies[b].torque -= tb;
            }
        }
    }

    /// Clears what [`apply`](Self::apply) reports of the last sample, before it runs.
    fn clear_last(&mut self) {
        self.last_rows = 0;
        self.last_refreshed = false;
        self.last_patched = false;
        self.last_patch_size = (0, 0);
        self.last_sweeps = 0;
        self.last_row_updates = 0;
        self.last_cut = false;
        self.last_warm_scale = 0.0;
    }

    /// Adds the last sample's row updates and budget cut to the damper's totals.
    fn count_work(&mut self) {
        self.row_updates += self.last_row_updates;
        self.max_row_updates = self.max_row_updates.max(self.last_row_updates);
        self.budget_cuts += self.last_cut as u64;
    }

    /// Step 1 of [`apply`](Self::apply): `star` and the working velocities `solver` from the
    /// `bodies` (per-body buffers already sized to them), with `dynamic`. Returns the kinetic
    /// energy at `v*` (J) and whether every body is as dynamic as in the last sample. The
    /// buffers are zipped, not indexed: no index checks, no reloads of their addresses.
    fn start_velocities(&mut self, dt: f64, bodies: &[Body]) -> (f64, bool) {
        let mut ke_star = 0.0;
        let mut same_bodies = true;
        let per_body = (self.star.iter_mut().zip(&mut self.solver)).zip(&mut self.dynamic);
        for (b, ((star, solver), dynamic)) in bodies.iter().zip(per_body) {
            let s = if b.is_dynamic() {
                let f = b.force - b.vel * b.damping;
                let (v, omega) = (
                    b.vel + f * (dt * b.inv_mass),
                    b.omega + b.torque * dt * b.inv_inertia,
                );
                ke_star += kinetic_of(b, v, omega);
                SolverBody {
                    v,
                    omega,
                    inv_mass: b.inv_mass,
                    inv_inertia: b.inv_inertia,
                }
            } else {
                SolverBody {
                    v: b.vel,
                    omega: b.omega,
                    inv_mass: 0.0,
                    inv_inertia: 0.0,
                }
            };
            *star = StarBody { s, pos: b.pose.pos };
            *solver = s;
            let d = s.inv_mass > 0.0 || s.inv_inertia > 0.0;
            same_bodies &= *dynamic == d;
            *dynamic = d;
        }
        (ke_star, same_bodies)
    }

    /// Drops the rows of the last sample: the next sample starts cold.
    fn forget(&mut self) {
        self.sorted.clear();
        self.src.clear();
        self.colour_of.clear();
        self.hole_next.clear();
        self.hole_head.fill(NONE);
        self.holes = 0;
        self.appended = 0;
        self.keys.clear();
        self.place.clear();
        self.generation = 0;
        self.loaded_len = 0;
    }

    /// `h = λ₀ᵀ·(W + K⁻¹)·λ₀` of the warm impulses `λ₀` (already applied to `solver`), given
    /// `λ₀ᵀK⁻¹λ₀ = Σ λ₀ᵢ²·wᵢ/r` (`k_part`): `λ₀ᵀJWJᵀλ₀ = Σ_bodies Δpᵀ·M⁻¹·Δp` with `Δp = JᵀΛ₀` the
    /// momentum the warm impulses gave each body, i.e. `m·|Δv|² + I·Δω²` summed over the bodies
    /// (`Δv = v₀ − v*`) — one pass over the bodies instead of two velocity reads per row.
    fn curvature(&self, k_part: f64) -> f64 {
        let mut h = k_part;
        for (s, v) in self.solver.iter().zip(&self.star) {
            let v = &v.s;
            if v.inv_mass > 0.0 {
                h += (s.v - v.v).length_squared() / v.inv_mass;
            }
            if v.inv_inertia > 0.0 {
                let dw = s.omega - v.omega;
                h += dw * dw / v.inv_inertia;
            }
        }
        h
    }

    /// Scales the warm start `λ₀` (applied whole to `solver` as the rows were built; `g =
    /// λ₀ᵀ·J·v*`, `h = λ₀ᵀ·(W + K⁻¹)·λ₀`) by the `s ∈ [0, 1]` minimising `Φ(s·λ₀) = s·g +
    /// ½s²·h` in the working velocities, `v = v* + s·(v₀ − v*)` body by body (the momentum the
    /// warm impulses gave each body, scaled); returns `s`. The rows keep `λ₀`: the caller scales
    /// them (the first sweep, as it reads them).
    fn scale_warm_start(&mut self, g: f64, h: f64) -> f64 {
        let s = if h > 0.0 && g.is_finite() && h.is_finite() {
            (-g / h).clamp(0.0, 1.0)
        } else if h == 0.0 && g == 0.0 {
            1.0 // no warm impulse at all: nothing to scale
        } else {
            0.0
        };
        if s == 0.0 {
            self.reset_solver();
        } else if s < 1.0 {
            for (v, star) in self.solver.iter_mut().zip(&self.star) {
                let star = &star.s;
                v.v = star.v + (v.v - star.v) * s;
                v.omega = star.omega + (v.omega - star.omega) * s;
            }
        }
        s
    }

    /// The sweeps' working velocities back to `v*`.
    fn reset_solver(&mut self) {
        for (s, star) in self.solver.iter_mut().zip(&self.star) {
            *s = star.s;
        }
    }
}

/// One projected Gauss–Seidel sweep of `rows` (colour order) on the working velocities `solver`,
/// each row's impulse first scaled by `scale` (the warm start's, in the first sweep; 1 after):
/// `λ ← max(−c·(v_rel − w·λ), lo)` and the change applied to both bodies. Returns the largest
/// change of a row's relative velocity, `|Δλ·w|` (m/s).
#[inline(always)]
fn sweep(rows: &mut [Row], solver: &mut [SolverBody], scale: f64) -> f64 {
    let mut largest = 0.0f64;
    for row in rows.iter_mut() {
        let lambda = row.lambda * scale;
        let v_rel = row.v_rel(solver);
        let new = select_max(row.neg_c * (v_rel - row.w * lambda), row.lo);
        let d = new - lambda;
        row.lambda = new;
        row.apply(d, solver);
        largest = select_max((d * row.w).abs(), largest);
    }
    largest
}

/// Whether `x` is finite: `x − x` is `+0` exactly for a finite `x` and NaN for an infinite or
/// NaN one, so this is [`f64::is_finite`] — in two floating-point instructions, where the
/// compiler lowers `is_finite` (and `x > 0 && x.is_finite()`) to a dozen integer ones on the
/// bit pattern (`refresh_rows` asks twice per row). (`x − x` of the same `x` is the point, hence
/// the allowance.)
#[allow(clippy::eq_op)]
#[inline(always)]
fn finite(x: f64) -> bool {
    x - x == 0.0
}

/// Kinetic energy of body `b` at velocity `v` (m/s) and spin `omega` (rad/s) (J).
#[inline]
fn kinetic_of(b: &Body, v: Vec2, omega: f64) -> f64 {
    0.5 * (b.mass * v.dot(v) + b.inertia * omega * omega)
}
