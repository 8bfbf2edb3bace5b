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
//! 10-box stacks of `tests/stack_corners.rs` at 8.3e-4 m/s after 2 s (6.4e-4 with 1e-5). A stop
//! at 2e-4 m/s (session 15; the default) halves the samples that need four sweeps or more, the slowest
//! samples of a settling pile (pile:1000 over 1–3 s: 38 of 2000 samples, then 19; pile:5000 over
//! 1–5 s: 23 of 4000, then 15), with the same rest times (pile:100 0.16 s, pile:1000 2.15 s,
//! pile:5000 1.62 s then 1.61 s, pyramid 0.19 s: `--rest-time 5`), the same settle table to four
//! digits, and the stacks at 7.6e-4 m/s after 2 s; 5e-4 and 1e-3 left the stacks at 1.2e-3 and
//! 4.2e-3 m/s. 4 or 6 fixed sweeps left the 10-box stacks of `tests/stack_corners.rs` with
//! contacts churning after 2 s (4: 3.9 cm/s, 6: 7.7 mm/s), 8 passed (4.3 mm/s), 16 with the stop
//! 0.64 mm/s.
//! The sweeps matter beyond the pile: with 8 sweeps at τ = 0.2 ms the 25 aligned 10-box stacks
//! of `tests/stack_corners.rs` kept rocking (2 cm/s, contacts churning after 2 s); with 16 they
//! pass (2e-3 m/s). A sweep that has not converged leaves `F ≠ −B_c·v⁺` (still passive, but the
//! impulses then shuffle energy between the stack's modes instead of removing it).
//!
//! **Scope.** Bodies that touch only one other body (a box on the floor, a probe against a wall:
//! the paper's one- and two-contact scenes) are not chains: their contacts keep the explicit law
//! alone, bit for bit. The pass runs in [`IntegrationMode::SemiImplicit`](super::IntegrationMode)
//! only, after the drive of the sample is known (`World::finish_step`); the contact wrench of a
//! body includes it after `finish_step` (before, in `begin_step`, only the explicit laws).

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
    /// `c = r/((1 + r)·w)` with `r = T/τ` (kg).
    c: f64,
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
        c: 0.0,
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
            c: r / ((1.0 + r) * w),
            lo,
            lambda: if warm.is_finite() { warm } else { 0.0 },
        }
    }

    /// Whether the effective mass is finite and positive.
    #[inline(always)]
    fn valid(&self) -> bool {
        self.w > 0.0 && self.w.is_finite()
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
    /// Sweeps run in the last sample (at most the `sweeps` asked for; fewer once converged).
    pub last_sweeps: u32,
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
    /// changes no row's relative velocity by more than 2e-4 m/s). Returns the kinetic energy the
    /// dampers remove over the sample (J, ≥ 0 up to rounding).
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
    pub fn apply(
        &mut self,
        tau: Option<f64>,
        sweeps: u32,
        dt: f64,
        loaded: Loaded<'_>,
        bodies: &mut [Body],
        wrenches: &mut [Wrench2],
    ) -> f64 {
        self.last_rows = 0;
        self.last_refreshed = false;
        self.last_patched = false;
        self.last_patch_size = (0, 0);
        self.last_sweeps = 0;
        self.last_warm_scale = 0.0;
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
        let mut ke_star = 0.0;
        let mut same_bodies = true;
        for (i, b) in bodies.iter().enumerate() {
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
            self.star[i] = StarBody { s, pos: b.pose.pos };
            self.solver[i] = s;
            let d = s.inv_mass > 0.0 || s.inv_inertia > 0.0;
            same_bodies &= self.dynamic[i] == d;
            self.dynamic[i] = d;
        }
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
        let solver = &mut self.solver;
        let mut scale = s;
        for _ in 0..sweeps {
            // Largest change of a row's relative velocity in this sweep (m/s).
            let mut largest = 0.0f64;
            for row in self.sorted.iter_mut() {
                let lambda = row.lambda * scale;
                let v_rel = row.v_rel(solver);
                let new = select_max(-row.c * (v_rel - row.w * lambda), row.lo);
                let d = new - lambda;
                row.lambda = new;
                row.apply(d, solver);
                largest = select_max((d * row.w).abs(), largest);
            }
            scale = 1.0;
            self.last_sweeps += 1;
            if largest <= CONVERGED {
                break;
            }
        }
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
        for (i, b) in bodies.iter_mut().enumerate() {
            let (s, v) = (&self.solver[i], &self.star[i].s);
            if b.is_dynamic() {
                ke += kinetic_of(b, s.v, s.omega);
            }
            if !self.dynamic[i] {
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
            wrenches[i].force += f;
            wrenches[i].torque += t;
            b.force += f;
            b.torque += t;
        }
        let removed = ke_star - ke;
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
        removed
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

    /// Steps 2–4 from scratch: the chain contacts of `loaded` (`keys` in key order, `place` the
    /// place of each in `sorted`), each with its colour, as rows in colour order (`sorted`, with
    /// `src` the loaded-list index of each), each warm-started from the last sample's impulse of
    /// the same key within this sample's bound, applied to `solver`. `partners_found`: step 2
    /// ([`find_partners`](Self::find_partners)) already ran for `loaded`. Returns `(g, h)` of
    /// [`scale_warm_start`](Self::scale_warm_start): `g = λ₀ᵀ·J·v*` and `h = λ₀ᵀ·(W + K⁻¹)·λ₀`
    /// (see [`curvature`](Self::curvature); `r = T/τ`).
    ///
    /// Two passes over the contacts, the colours first, so that each row is written once, to its
    /// place in colour order; the sums and the warm impulses go in key order.
    fn build_rows(
        &mut self,
        r: f64,
        dt: f64,
        loaded: Loaded<'_>,
        partners_found: bool,
    ) -> (f64, f64) {
        // The last sample's impulses by key.
        std::mem::swap(&mut self.prev_keys, &mut self.keys);
        self.prev_lambda.clear();
        let sorted = &self.sorted;
        self.prev_lambda
            .extend(self.place.iter().map(|&p| sorted[p as usize].lambda));
        if !partners_found {
            self.find_partners(loaded.contacts);
        }
        self.generation = loaded.generation;
        self.loaded_len = loaded.contacts.len();
        // 3–4. The colours, then the rows in their places. The colouring first takes every
        //      chain contact's effective mass as finite and positive, as it nearly always is; if
        //      placing the rows meets one that is not, both run again with the check, so that
        //      such a contact takes no colour.
        self.colour_rows(r, dt, loaded.contacts, false);
        let (g, k) = match self.place_rows(r, dt, loaded, true) {
            Some(gk) => gk,
            None => {
                self.colour_rows(r, dt, loaded.contacts, true);
                let gk = self.place_rows(r, dt, loaded, false);
                debug_assert!(gk.is_some(), "a checked colouring places every row");
                gk.unwrap_or_default()
            }
        };
        (g, self.curvature(k / r))
    }

    /// Step 2: which dynamic bodies touch two or more other bodies through the contacts of
    /// `loaded` (`multi`; `partner` is scratch).
    fn find_partners(&mut self, loaded: &[LoadedContact]) {
        let dynamic = &self.dynamic;
        self.partner.fill(NONE);
        self.multi.fill(false);
        for e in loaded {
            for (x, y) in [(e.body_a, e.body_b), (e.body_b, e.body_a)] {
                if !dynamic[x as usize] {
                    continue;
                }
                let p = &mut self.partner[x as usize];
                if *p == NONE {
                    *p = y;
                } else if *p != y {
                    self.multi[x as usize] = true;
                }
            }
        }
    }

    /// Step 3 of [`build_rows`](Self::build_rows): the colour of each chain contact of `loaded`
    /// in key order (`colour`, and `per_colour` the rows of each), greedy: the lowest colour
    /// neither body has yet (fixed bodies take any number). With `check`, a contact whose
    /// effective mass is not finite and positive is no row: it takes no colour and sets
    /// `dropped`.
    fn colour_rows(&mut self, r: f64, dt: f64, loaded: &[LoadedContact], check: bool) {
        self.colour.clear();
        self.per_colour.fill(0);
        self.used.fill(0);
        self.dropped = false;
        let (dynamic, multi, used) = (&self.dynamic, &self.multi, &mut self.used);
        for e in loaded {
            let (a, b) = (e.body_a as usize, e.body_b as usize);
            if !is_chain(multi, a, b) {
                continue;
            }
            if check && !Row::build(e, a as u32, b as u32, &self.star, r, dt, 0.0).valid() {
                self.dropped = true;
                continue;
            }
            let c = take_colour(dynamic, used, a, b);
            self.colour.push(c);
            self.per_colour[c as usize] += 1;
        }
    }

    /// Step 4 of [`build_rows`](Self::build_rows): the rows, in key order, written straight to
    /// their places in colour order (`per_colour` becomes each colour's next position: a stable
    /// counting sort), each warm-started from the last sample's impulse of the same key (a merge
    /// of two key-sorted lists) within this sample's bound, and that impulse applied to
    /// `solver`. Returns `g = λ₀ᵀ·J·v*` and `Σ λ₀ᵢ²·wᵢ`; `None` if `abort_on_invalid` and a
    /// chain contact's effective mass is not finite and positive (the colours did not leave it
    /// out), else such a contact is skipped.
    fn place_rows(
        &mut self,
        r: f64,
        dt: f64,
        loaded: Loaded<'_>,
        abort_on_invalid: bool,
    ) -> Option<(f64, f64)> {
        let mut at = 0u32;
        for k in self.per_colour.iter_mut() {
            let count = *k;
            *k = at;
            at += count;
        }
        let n = self.colour.len();
        self.sorted.clear();
        self.sorted.resize(n, Row::NONE);
        self.src.clear();
        self.src.resize(n, 0);
        self.colour_of.clear();
        self.colour_of.resize(n, 0);
        self.hole_next.clear();
        self.hole_next.resize(n, NONE);
        self.hole_head.fill(NONE);
        (self.holes, self.appended) = (0, 0);
        self.keys.clear();
        self.place.clear();
        // Room for the rows the patches may append before the next build (`patch_rows`' budget:
        // at most an eighth of the rows, at least 16), so that a patch allocates nothing.
        let room = n / 7 + 20;
        self.sorted.reserve(room);
        self.src.reserve(room);
        self.colour_of.reserve(room);
        self.hole_next.reserve(room);
        for keys in [&mut self.keys, &mut self.prev_keys] {
            keys.reserve(n + room);
        }
        self.place.reserve(n + room);
        self.new_place.reserve(n + room);
        self.dead.clear();
        self.dead.reserve(room);
        self.born.clear();
        self.born.reserve(room);
        // A refresh that gave up may have applied impulses: start again from `v*`.
        self.reset_solver();
        let (star, multi) = (&self.star, &self.multi);
        let (mut g, mut k) = (0.0, 0.0);
        let mut j = 0;
        for (i, (e, &key)) in loaded.contacts.iter().zip(loaded.keys).enumerate() {
            let (a, b) = (e.body_a as usize, e.body_b as usize);
            if !is_chain(multi, a, b) {
                continue;
            }
            while j < self.prev_keys.len() && self.prev_keys[j] < key {
                j += 1;
            }
            let prev = if j < self.prev_keys.len() && self.prev_keys[j] == key {
                self.prev_lambda[j]
            } else {
                0.0
            };
            let row = Row::build(e, a as u32, b as u32, star, r, dt, prev);
            if !row.valid() {
                if abort_on_invalid {
                    return None;
                }
                continue;
            }
            // g = λ₀ᵀ·J·v* (see `scale_warm_start`), and the warm impulse applied.
            if row.lambda != 0.0 {
                g += row.lambda * row.v_rel_star(star);
                row.apply(row.lambda, &mut self.solver);
            }
            k += row.lambda * row.lambda * row.w;
            let index = self.keys.len();
            let colour = self.colour[index];
            let p = &mut self.per_colour[colour as usize];
            self.sorted[*p as usize] = row;
            self.src[*p as usize] = i as u32;
            self.colour_of[*p as usize] = colour;
            self.place.push(*p);
            *p += 1;
            self.keys.push(key);
        }
        Some((g, k))
    }

    /// Steps 3–4 when a few loaded contacts changed (after step 2,
    /// [`find_partners`](Self::find_partners), for `loaded`): a merge of the last sample's keys
    /// with the new ones. A row whose contact is still a chain contact keeps its place and its
    /// colour (its loaded index is updated). A row whose contact is gone, or no longer a chain
    /// contact, becomes a hole: a no-op row (zero normal, lever arms, mass and bound, so a sweep
    /// leaves every velocity as it was) that gives back its colour. A new chain contact takes
    /// the lowest colour neither body has, and a hole of that colour or else a new place after
    /// the colour buckets. The caller then refreshes the rows
    /// ([`refresh_rows`](Self::refresh_rows)): the new ones start from a zero impulse, as a
    /// build would start them, and every other row from its own last impulse, so the rows are a
    /// build's, in another order.
    ///
    /// Returns `false`, having changed nothing a build reads, when the holes and appended rows
    /// since the last build could exceed an eighth of the rows (at least 16): the sweeps would
    /// then lose the colour order that lets the processor overlap their updates, so the caller
    /// builds the rows from scratch.
    fn patch_rows(&mut self, loaded: Loaded<'_>) -> bool {
        self.new_place.clear();
        self.dead.clear();
        self.born.clear();
        // The new keys go to `prev_keys`, which a build overwrites.
        self.prev_keys.clear();
        let (old_keys, old_place) = (&self.keys[..], &self.place[..]);
        let (new_keys, new_place) = (&mut self.prev_keys, &mut self.new_place);
        let (src, dead, born, multi) = (&mut self.src, &mut self.dead, &mut self.born, &self.multi);
        // The budget below cannot exceed this one (the new rows are at most the loaded
        // contacts), so the merge gives up as soon as the changes pass it.
        let (spent, limit) = (
            self.holes + self.appended,
            (loaded.contacts.len() / 8).max(16),
        );
        let mut j = 0;
        for (i, (e, &key)) in loaded.contacts.iter().zip(loaded.keys).enumerate() {
            // Most keys are the next old one; otherwise old keys before this one died.
            let mut old = NONE;
            if old_keys.get(j) == Some(&key) {
                old = old_place[j];
                j += 1;
            } else {
                while j < old_keys.len() && old_keys[j] < key {
                    dead.push(old_place[j]);
                    j += 1;
                }
                if spent + dead.len() + born.len() > limit {
                    return false;
                }
                if old_keys.get(j) == Some(&key) {
                    old = old_place[j];
                    j += 1;
                }
            }
            if is_chain(multi, e.body_a as usize, e.body_b as usize) {
                if old == NONE {
                    born.push((i as u32, new_place.len() as u32));
                } else {
                    // A build rewrites every `src`, so this write is safe if the patch gives up.
                    src[old as usize] = i as u32;
                }
                new_place.push(old);
                new_keys.push(key);
            } else if old != NONE {
                dead.push(old);
            }
        }
        dead.extend_from_slice(&old_place[j..]);
        let dynamic = &self.dynamic;
        let budget = (self.new_place.len() / 8).max(16);
        if self.holes + self.appended + self.dead.len() + self.born.len() > budget {
            return false;
        }
        let used = &mut self.used;
        for &p in &self.dead {
            let p = p as usize;
            let (row, c) = (self.sorted[p], self.colour_of[p]);
            if c < COLOURS {
                for x in [row.a as usize, row.b as usize] {
                    if dynamic[x] {
                        used[x] &= !(1u64 << c);
                    }
                }
            }
            self.sorted[p] = Row::NONE;
            self.src[p] = NONE;
            self.hole_next[p] = self.hole_head[c as usize];
            self.hole_head[c as usize] = p as u32;
            self.holes += 1;
        }
        for &(i, k) in &self.born {
            let e = &loaded.contacts[i as usize];
            let (a, b) = (e.body_a as usize, e.body_b as usize);
            let c = take_colour(dynamic, used, a, b);
            let head = self.hole_head[c as usize];
            let p = if head != NONE {
                self.hole_head[c as usize] = self.hole_next[head as usize];
                self.hole_next[head as usize] = NONE;
                self.holes -= 1;
                head as usize
            } else {
                self.sorted.push(Row::NONE);
                self.src.push(NONE);
                self.colour_of.push(c);
                self.hole_next.push(NONE);
                self.appended += 1;
                self.sorted.len() - 1
            };
            // The refresh builds the row from the contact, from a zero impulse.
            self.sorted[p] = Row {
                a: a as u32,
                b: b as u32,
                ..Row::NONE
            };
            self.src[p] = i;
            self.colour_of[p] = c;
            self.new_place[k as usize] = p as u32;
        }
        self.last_patch_size = (self.dead.len(), self.born.len());
        std::mem::swap(&mut self.keys, &mut self.prev_keys);
        std::mem::swap(&mut self.place, &mut self.new_place);
        self.generation = loaded.generation;
        self.loaded_len = loaded.contacts.len();
        true
    }

    /// Steps 2–4 when `loaded` holds the same contacts as the last sample (same keys in the same
    /// order, same dynamic bodies): the chain contacts, their colours and order are then those of
    /// the last sample, so its rows (colour order) are refreshed in place from the new
    /// geometry, each warm-started from its own last impulse within this sample's bound — what
    /// [`build_rows`](Self::build_rows) would build, without the key merge and the colouring.
    /// Returns `(g, h)` of [`scale_warm_start`](Self::scale_warm_start), or `None` (the caller
    /// builds from scratch) if a row's effective mass is no longer finite.
    fn refresh_rows(&mut self, r: f64, dt: f64, loaded: &[LoadedContact]) -> Option<(f64, f64)> {
        // `solver` holds `v*` (step 1): nothing has applied an impulse to it yet.
        let star = &self.star;
        let (mut g, mut k) = (0.0, 0.0);
        // Checked once at the end (no branch per row): if a row failed, the caller rebuilds from
        // scratch, from `star` and the rows' impulses; every row keeps `max(λ, lo)` or 0 here,
        // which `build_rows` maps the same way.
        let mut valid = true;
        for (row, &i) in self.sorted.iter_mut().zip(&self.src) {
            if i == NONE {
                continue; // a hole left by a patch: a no-op row
            }
            *row = Row::build(&loaded[i as usize], row.a, row.b, star, r, dt, row.lambda);
            valid &= row.valid();
            if row.lambda != 0.0 {
                g += row.lambda * row.v_rel_star(star);
                k += row.lambda * row.lambda * row.w;
                row.apply(row.lambda, &mut self.solver);
            }
        }
        valid.then(|| (g, self.curvature(k / r)))
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

/// Whether the contact between bodies `a` and `b` is a chain contact: one of them is dynamic and
/// touches two or more other bodies (`multi`, which
/// [`find_partners`](ChainDamping::find_partners) sets for dynamic bodies only). The colouring,
/// the placing of the rows and a patch must agree on it contact by contact, so all ask here.
#[inline(always)]
fn is_chain(multi: &[bool], a: usize, b: usize) -> bool {
    multi[a] || multi[b]
}

/// The greedy colour of a row between bodies `a` and `b`: the lowest colour neither dynamic body
/// has yet (`used`, one bit per colour; fixed bodies take any number), now taken by both; or the
/// overflow colour [`COLOURS`] when none is free.
#[inline(always)]
fn take_colour(dynamic: &[bool], used: &mut [u64], a: usize, b: usize) -> u32 {
    let (dyn_a, dyn_b) = (dynamic[a], dynamic[b]);
    let taken = if dyn_a { used[a] } else { 0 } | if dyn_b { used[b] } else { 0 };
    let c = (!taken).trailing_zeros().min(COLOURS);
    if c < COLOURS {
        used[a] |= (dyn_a as u64) << c;
        used[b] |= (dyn_b as u64) << c;
    }
    c
}

/// Kinetic energy of body `b` at velocity `v` (m/s) and spin `omega` (rad/s) (J).
#[inline]
fn kinetic_of(b: &Body, v: Vec2, omega: f64) -> f64 {
    0.5 * (b.mass * v.dot(v) + b.inertia * omega * omega)
}

#[cfg(test)]
mod tests {
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
    struct Column {
        contacts: Vec<LoadedContact>,
        keys: Vec<VeCandidate>,
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
        let dt = 1e-3;
        // Sample 1: every box falls faster than the one below: the dampers push the boxes apart
        // (λ > 0 on every row).
        for (i, b) in bodies.iter_mut().enumerate().skip(1) {
            b.vel = Vec2::new(0.0, -0.1 * i as f64);
        }
        let before = kinetic_of(&bodies);
        let removed = chain.apply(
            Some(2e-4),
            16,
            dt,
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
        let removed = chain.apply(
            Some(2e-4),
            0,
            dt,
            loaded.view(3, 1),
            &mut bodies,
            &mut wrenches,
        );
        assert!(
            chain.last_warm_scale < 1.0,
            "scale {}",
            chain.last_warm_scale
        );
        assert!(removed >= 0.0, "removed {removed} J");
        // And with sweeps the dampers pull nothing (F ≥ −f_n) and still only remove energy.
        let removed = chain.apply(
            Some(2e-4),
            16,
            dt,
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
        chain.apply(
            Some(2e-4),
            64,
            1e-3,
            loaded.view(3, 1),
            &mut bodies,
            &mut wrenches,
        );
        let cold = chain.last_sweeps;
        set(&mut bodies);
        let removed = chain.apply(
            Some(2e-4),
            64,
            1e-3,
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
            let r_plain = plain.apply(
                Some(2e-4),
                3,
                1e-3,
                loaded.view(3, 100 + k),
                &mut b_plain,
                &mut wrenches,
            );
            let r_with = with.apply(
                Some(2e-4),
                3,
                1e-3,
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
        let dt = 1e-3;
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
            let r_fast = fast.apply(
                Some(2e-4),
                3,
                dt,
                loaded.view(3, 1),
                &mut b_fast,
                &mut wrenches,
            );
            let r_full = full.apply(
                Some(2e-4),
                3,
                dt,
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
        fast.apply(Some(2e-4), 3, dt, loaded.view(2, 2), &mut b, &mut wrenches);
        assert_eq!((fast.last_rows, fast.last_refreshed), (2, false));
        // A body that became fixed: rebuilt too (box 1 fixed: the floor–box 1 contact joins two
        // fixed bodies and is no row; box 2 still touches boxes 1 and 3).
        fast.apply(
            Some(2e-4),
            3,
            dt,
            loaded.view(3, 3),
            &mut b_fast.clone(),
            &mut wrenches,
        );
        assert_eq!((fast.last_rows, fast.last_refreshed), (3, false));
        let mut b = b_fast.clone();
        b[1] = Body::fixed("now fixed", b[1].pose);
        // (The same generation of keys: only the bodies changed.)
        fast.apply(Some(2e-4), 3, dt, loaded.view(3, 3), &mut b, &mut wrenches);
        assert_eq!((fast.last_rows, fast.last_refreshed), (2, false));
    }

    /// A tall column of boxes on a fixed floor, two contacts (the bottom corners) at each
    /// interface: the whole loaded list, in key order.
    fn tall_column(boxes: u32) -> (Vec<Body>, Column) {
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
        let dt = 1e-3;
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
                let r_p = patched.apply(
                    Some(2e-4),
                    sweeps,
                    dt,
                    list.view(n, k + 1),
                    &mut b_p,
                    &mut wrenches,
                );
                let r_b = built.apply(
                    Some(2e-4),
                    sweeps,
                    dt,
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
                        assert_eq!((row.w, row.c, row.lo, row.lambda), (0.0, 0.0, 0.0, 0.0));
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
                        (p.c, b.c),
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
            d.apply(
                Some(2e-4),
                2,
                1e-3,
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
        chain.apply(
            Some(2e-4),
            16,
            dt,
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
}
