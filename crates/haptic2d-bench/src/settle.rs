//! `--settle SECONDS`: how a haptic2d scene comes to rest. Runs the selected cases for haptic2d only
//! (optionally with law parameters overridden, `--set normal.bc=200`) and prints the settle state
//! every `--every` seconds of simulated time: largest speed, bodies above 1 cm/s, mean height,
//! largest overlap. Used to find why the pile keeps moving (docs/PERFORMANCE.md, issue 17).

use haptic2d::contact::WorkBudget;
use haptic2d::stage_time::{self, Stage, StageTimes};
use haptic2d::world::World;

use crate::state;
use crate::timing::{now, Clock};

/// Applies `law.key=value` overrides (`normal.bc=200`, `friction.beta=40`) to the prototypes of the
/// world's laws (every contact created afterwards gets them), and the world options
/// `world.proximity_spread=0/1`, `world.proximity_skip=0/1`, `world.chain_tau=SECONDS` (0 = chain damper off) and
/// `world.chain_sweeps=N`, `world.chain_budget=N` (row updates per sample, 0 = unbounded;
/// docs/MODELS.md §6.7), and `contact.impact_sweeps=N` (the impact work budget, 1–200,
/// docs/MODELS.md §7.7; 200 is the limit before the budget).
pub fn apply(w: &mut World, sets: &[String]) -> Result<(), String> {
    for s in sets {
        let (k, v) = s
            .split_once('=')
            .ok_or_else(|| format!("--set {s}: expected law.key=value, e.g. normal.bc=200"))?;
        let v: f64 = v
            .trim()
            .parse()
            .map_err(|e| format!("--set {s}: value: {e}"))?;
        let r = match k.trim().split_once('.') {
            Some(("normal", key)) => w.normal.set_param(key, v),
            Some(("friction", key)) => w.friction.set_param(key, v),
            Some(("world", "proximity_skip")) => {
                w.params.proximity_skip = v != 0.0;
                Ok(())
            }
            Some(("world", "proximity_spread")) => {
                w.params.proximity_spread = v != 0.0;
                Ok(())
            }
            Some(("world", "chain_tau")) => {
                w.params.chain_tau = (v > 0.0).then_some(v);
                Ok(())
            }
            Some(("world", "chain_sweeps")) if v >= 0.0 && v.fract() == 0.0 => {
                w.params.chain_sweeps = v as u32;
                Ok(())
            }
            Some(("world", "chain_budget")) if v >= 0.0 && v.fract() == 0.0 => {
                w.params.chain_budget = WorkBudget::from_setting(v as u64);
                Ok(())
            }
            Some(("contact", "impact_sweeps"))
                if (1.0..=200.0).contains(&v) && v.fract() == 0.0 =>
            {
                w.params.contact.impact_sweeps = v as u32;
                Ok(())
            }
            Some(("contact", "impact_budget")) if v >= 0.0 && v.fract() == 0.0 => {
                w.params.contact.impact_budget = WorkBudget::from_setting(v as u64);
                Ok(())
            }
            _ => Err("expected normal.KEY, friction.KEY, world.{proximity_spread, proximity_skip, chain_tau, chain_sweeps, chain_budget} or contact.{impact_sweeps, impact_budget} (sweeps and budgets whole numbers, impact_sweeps 1 to 200, chain_budget and impact_budget 0 = unbounded)".into()),
        };
        r.map_err(|e| format!("--set {s}: {e}"))?;
    }
    Ok(())
}

/// One step through a function of its own, so a profiler can be limited to the steps after
/// `--profile-after` (`valgrind --tool=callgrind --toggle-collect='*profiled_step*'`).
#[inline(never)]
pub fn profiled_step(w: &mut World) {
    w.step();
}

/// One step right after a [`Cold`] pause, through a function of its own, so a profiler can be
/// limited to the cold steps (`valgrind --tool=callgrind --toggle-collect='*cold_step*'`).
#[inline(never)]
pub fn cold_step(w: &mut World) {
    w.step();
    // A body of its own, so the linker cannot fold it into `profiled_step`.
    std::hint::black_box(0xc01d_u32);
}

/// Bytes written by [`Pause::Evict`] when no size is given: four times the 2 MiB L2 of this
/// machine (docs/PERFORMANCE.md), so that a step after it finds its data in the L3.
pub const EVICT_BYTES: usize = 8 << 20;

/// Largest eviction buffer (MiB).
const MAX_EVICT_MIB: usize = 4096;

/// What runs before every other profiled step of `--settle --cold`: how a chunk start of the
/// interleaved bench finds the world's data and code.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cold {
    /// The pause itself.
    pub pause: Pause,
    /// After the pause, step a copy of the world once (untimed, made when profiling starts): the
    /// step's code, the branch predictors and the instruction TLB are warm again, while the
    /// world's own data stays as the pause left it. The difference to the same pause without it
    /// is the share of a cold step's cost that is code.
    pub warm_code: bool,
}

/// The pause of a [`Cold`] step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pause {
    /// Write this many bytes, one byte per 64-byte line: the default [`EVICT_BYTES`] evicts the
    /// world from the L1 and L2 caches; more than the 32 MiB L3 evicts it to memory.
    Evict(usize),
    /// Compute for this long (ms) without touching memory, as long as the other engines' chunks
    /// take: whatever the world loses from the caches meanwhile, the machine's other tenants took.
    Idle(f64),
}

impl std::str::FromStr for Cold {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let err = || {
            format!(
                "{s:?}: expected evict, evict=MIB (1–{MAX_EVICT_MIB}) or idle=MS (a positive time \
                 in ms), optionally followed by ,code (e.g. idle=100,code)"
            )
        };
        let t = s.trim();
        let (p, warm_code) = match t.strip_suffix(",code") {
            Some(p) => (p.trim(), true),
            None => (t, false),
        };
        let pause = match p {
            "evict" => Pause::Evict(EVICT_BYTES),
            x => {
                if let Some(v) = x.strip_prefix("evict=") {
                    match v.trim().parse::<usize>() {
                        Ok(mib) if (1..=MAX_EVICT_MIB).contains(&mib) => Pause::Evict(mib << 20),
                        _ => return Err(err()),
                    }
                } else if let Some(v) = x.strip_prefix("idle=") {
                    match v.trim().parse::<f64>() {
                        Ok(ms) if ms.is_finite() && ms > 0.0 => Pause::Idle(ms),
                        _ => return Err(err()),
                    }
                } else {
                    return Err(err());
                }
            }
        };
        Ok(Cold { pause, warm_code })
    }
}

impl Cold {
    /// Bytes of the eviction buffer the pause needs (0 for an idle pause).
    fn buffer_bytes(self) -> usize {
        match self.pause {
            Pause::Evict(b) => b,
            Pause::Idle(_) => 0,
        }
    }

    /// Runs the pause, with `buf` the eviction buffer ([`Cold::buffer_bytes`] long).
    #[inline(never)]
    fn pause(self, buf: &mut [u8]) {
        match self.pause {
            Pause::Evict(_) => {
                for line in buf.chunks_mut(64) {
                    line[0] = line[0].wrapping_add(1);
                }
                std::hint::black_box(buf);
            }
            Pause::Idle(ms) => {
                let t = std::time::Instant::now();
                let mut x = 1.0f64;
                while t.elapsed().as_secs_f64() < ms * 1e-3 {
                    for _ in 0..1000 {
                        x = (x * 1.000_000_1).sqrt() + 0.5;
                    }
                }
                std::hint::black_box(x);
            }
        }
    }

    fn describe(self) -> String {
        let p = match self.pause {
            Pause::Evict(b) => format!("evicting the caches ({} MiB written)", b >> 20),
            Pause::Idle(ms) => format!("{ms} ms of computing without touching memory"),
        };
        if self.warm_code {
            format!("{p} and one step of a copy of the world (code warm, data cold)")
        } else {
            p
        }
    }
}

/// Runs `w` for `seconds` of simulated time at `dt` (s), printing the state every `every` seconds;
/// steps after `profile_after` (s) go through [`profiled_step`]. With `cold`, the steps of every
/// other global period (`N_g` samples) run right after that pause instead, each through
/// [`cold_step`], and the summary compares the cold steps with the warm ones (the cost of a chunk
/// start in the bench).
pub fn run(
    label: &str,
    w: &mut World,
    dt: f64,
    seconds: f64,
    every: f64,
    profile_after: f64,
    cold: Option<Cold>,
) {
    let first_profiled = (profile_after / dt).round() as usize;
    let steps = (seconds / dt).round() as usize;
    let every = ((every / dt).round() as usize).max(1);
    println!(
        "{label}: t s | |v|max m/s | >1cm/s | mean y m | overlap mm | contacts | early | chain sweeps | cpu µs/step"
    );
    let origin = std::time::Instant::now();
    // CPU time of every step after `profile_after`, by sample phase of the global period.
    let n_g = w.params.proximity_every.max(1) as usize;
    let mut by_phase: Vec<Vec<f64>> = vec![Vec::new(); n_g];
    // Every warm profiled step.
    let mut each: Vec<ProfiledStep> = Vec::new();
    let (mut cpu, mut since) = (0.0, 0usize);
    // Global updates published during the profiled steps: (count, in place, GJK iterations,
    // periods whose update was skipped), and the world's count of skipped updates.
    let mut updates = (0usize, 0usize, 0u64, 0usize);
    let mut skips = w.skipped_global_updates();
    // With `cold`: the eviction buffer and the CPU time of every cold step (µs).
    let mut evict_buf = vec![0u8; cold.map_or(0, Cold::buffer_bytes)];
    let mut cold_times: Vec<f64> = Vec::new();
    // With `cold` and its `warm_code`: the copy of the world stepped after each pause.
    let mut twin: Option<World> = None;
    // Per-stage wall time summed over the warm and the cold profiled steps (ns), and their
    // counts (with the `stage-timing` feature).
    let mut stages = [(0usize, StageTimes::default()); 2];
    for k in 1..=steps {
        if k == first_profiled && cold.is_some_and(|c| c.warm_code) {
            twin = Some(w.clone());
        }
        // Cold and warm steps alternate by whole global periods, so both cover every phase.
        let is_cold = cold.is_some() && k > first_profiled && ((k - 1) / n_g) % 2 == 1;
        if let (true, Some(c)) = (is_cold, cold) {
            c.pause(&mut evict_buf);
            if let Some(t) = twin.as_mut() {
                t.step();
            }
        }
        let t0 = now(Clock::Cpu, origin);
        if is_cold {
            cold_step(w);
        } else if k > first_profiled {
            profiled_step(w);
        } else {
            w.step();
        }
        let dt_cpu = now(Clock::Cpu, origin) - t0;
        if k > first_profiled {
            let (count, sum) = &mut stages[is_cold as usize];
            *count += 1;
            for (s, x) in sum.ns.iter_mut().zip(w.stage_times().ns) {
                *s += x;
            }
        }
        cpu += dt_cpu;
        if is_cold {
            cold_times.push(dt_cpu * 1e6);
        } else if k > first_profiled {
            by_phase[(k - 1) % n_g].push(dt_cpu * 1e6);
            if (k - 1) % n_g == 0 {
                let b = w.broad_stats();
                let skipped = w.skipped_global_updates() > skips;
                skips = w.skipped_global_updates();
                if skipped {
                    updates.3 += 1;
                } else {
                    updates.0 += 1;
                    updates.1 += b.in_place as usize;
                    updates.2 += b.gjk_iterations;
                }
            }
            each.push(ProfiledStep::of(w, k, dt_cpu));
        }
        since += 1;
        if k % every == 0 || k == steps {
            let poses: Vec<_> = w
                .bodies
                .iter()
                .map(|b| (b.pose.pos, b.pose.angle, b.vel))
                .collect();
            let s = state::of(w, &poses);
            println!(
                "{label}: {:6.2} | {:10.4} | {:6} | {:8.4} | {:10.3} | {:8} | {:5} | {:12} | {:8.1}",
                k as f64 * dt,
                s.max_speed,
                s.moving,
                s.mean_height,
                s.max_overlap * 1e3,
                w.contacts().contact_count(),
                w.continuous_stats().1,
                w.chain_damper().last_sweeps,
                cpu * 1e6 / since as f64
            );
            (cpu, since) = (0.0, 0);
        }
    }
    if by_phase[0].is_empty() {
        return;
    }
    let b = w.broad_stats();
    println!(
        "{label}: work at the end: {} AABB pairs ({} of them with their last GJK distance reused) and {} proximate pairs in the global stage, {} of them skipped by the local stage and {} penetrating ones whose vertex scan it reused, {} tracked VE pairs, {} contacts, {} chain rows",
        b.aabb_pairs,
        b.reused_distances,
        b.proximate_pairs,
        w.local_stage().skipped(),
        w.local_stage().reused(),
        w.contacts().entries().len(),
        w.contacts().contact_count(),
        w.chain_damper().last_rows
    );
    println!(
        "{label}: global updates published after {profile_after} s: {}, {} of them in place (no sort), {:.1} GJK iterations per update; {} periods skipped their update (the set still exact)",
        updates.0,
        updates.1,
        updates.2 as f64 / updates.0.max(1) as f64,
        updates.3
    );
    let all_steps = crate::timing::Samples(by_phase.iter().flatten().copied().collect());
    if let Some(how) = cold {
        let c = crate::timing::Samples(cold_times);
        println!(
            "{label}: CPU µs per step after {profile_after} s, right after {} / warm: median {:.1} / {:.1} (cold / warm {:.2}), p99 {:.1} / {:.1}",
            how.describe(),
            c.median(),
            all_steps.median(),
            c.median() / all_steps.median(),
            c.p99(),
            all_steps.p99()
        );
    }
    if stage_time::ENABLED {
        print_stages(label, profile_after, &stages, cold);
    }
    print_merges(label, profile_after, &each);
    print_damper_kinds(label, profile_after, &each);
    print_row_updates(label, profile_after, &each);
    let (median, p99) = (all_steps.median(), all_steps.p99());
    println!(
        "{label}: CPU µs per step after {profile_after} s: median {median:.1}, p99 {p99:.1} (p99/median {:.2}), largest {:.1}",
        p99 / median,
        all_steps.quantile(1.0)
    );
    // How many chain-damper sweeps the profiled steps ran (the sweeps stop once converged).
    let mut sweeps = [0usize; 5];
    for e in &each {
        sweeps[match e.sweeps {
            0..=1 => 0,
            2..=3 => 1,
            4..=7 => 2,
            8..=15 => 3,
            _ => 4,
        }] += 1;
    }
    let mean = each.iter().map(|e| e.sweeps as f64).sum::<f64>() / each.len().max(1) as f64;
    println!(
        "{label}: chain damper sweeps per step after {profile_after} s: mean {mean:.1}; steps with 0–1 / 2–3 / 4–7 / 8–15 / 16+: {} / {} / {} / {} / {}",
        sweeps[0], sweeps[1], sweeps[2], sweeps[3], sweeps[4]
    );
    each.sort_by(|a, b| b.step_us.total_cmp(&a.step_us));
    println!(
        "{label}: slowest steps (µs @ step: phase mod {n_g}, chain sweeps, damped rows, contact events): {}",
        each.iter()
            .take(8)
            .map(|e| format!(
                "{:.0} @ {}: {}, {}, {}, {}",
                e.step_us,
                e.k,
                (e.k - 1) % n_g,
                e.sweeps,
                e.rows,
                e.events
            ))
            .collect::<Vec<_>>()
            .join("; ")
    );
    // The tail by phase as well: a phase whose work comes in bursts (a global update that is
    // not in place rebuilds its pairs on its last share) shows in its p95, not in its median.
    let p95: Vec<f64> = by_phase
        .iter()
        .map(|v| crate::timing::Samples(v.clone()).quantile(0.95))
        .collect();
    let med: Vec<f64> = by_phase
        .into_iter()
        .map(|v| crate::timing::Samples(v).median())
        .collect();
    let all = med.iter().sum::<f64>() / med.len() as f64;
    println!(
        "{label}: CPU µs per step by sample mod {n_g} after {profile_after} s (global stage {}): {} (worst / mean of phases {:.2})",
        if w.params.proximity_spread { "spread" } else { "whole at 0" },
        med.iter().map(|m| format!("{m:.1}")).collect::<Vec<_>>().join(" "),
        med.iter().fold(0.0f64, |a, &b| a.max(b)) / all
    );
    println!(
        "{label}: CPU µs per step by sample mod {n_g} after {profile_after} s, p95: {}",
        p95.iter()
            .map(|m| format!("{m:.1}"))
            .collect::<Vec<_>>()
            .join(" "),
    );
}

/// The mean wall time of each stage over the warm profiled steps, and over the cold ones with
/// `cold` (`stages[0]` warm, `stages[1]` cold: step counts and summed times).
fn print_stages(
    label: &str,
    profile_after: f64,
    stages: &[(usize, StageTimes); 2],
    cold: Option<Cold>,
) {
    let mean = |(n, t): &(usize, StageTimes), s: Stage| t.get(s) as f64 / (*n).max(1) as f64 / 1e3;
    let [warm, cold_sum] = stages;
    match cold {
        Some(c) => println!(
            "{label}: wall µs per stage after {profile_after} s (stage-timing build), warm ({} steps) / right after {} ({} steps) / difference:",
            warm.0,
            c.describe(),
            cold_sum.0
        ),
        None => println!(
            "{label}: wall µs per stage after {profile_after} s (stage-timing build, {} steps):",
            warm.0
        ),
    }
    let mut total = [0.0; 2];
    for s in Stage::ALL {
        let (w, c) = (mean(warm, s), mean(cold_sum, s));
        total[0] += w;
        total[1] += c;
        if cold.is_some() {
            println!("{label}:   {:<10} {w:8.1} {c:8.1} {:+8.1}", s.name(), c - w);
        } else {
            println!("{label}:   {:<10} {w:8.1}", s.name());
        }
    }
    if cold.is_some() {
        println!(
            "{label}:   {:<10} {:8.1} {:8.1} {:+8.1}",
            "step",
            total[0],
            total[1],
            total[1] - total[0]
        );
    } else {
        println!("{label}:   {:<10} {:8.1}", "step", total[0]);
    }
}

/// One warm profiled step of [`run`].
struct ProfiledStep {
    /// The step's CPU time (µs).
    step_us: f64,
    /// The step's number (from 1).
    k: usize,
    /// The chain damper's sweeps and rows, its row updates and whether its budget cut them.
    sweeps: u32,
    rows: usize,
    row_updates: u64,
    cut: bool,
    /// Contact events of the step.
    events: usize,
    /// How the chain damper made its rows.
    rows_by: RowsBy,
    /// The damper stage's wall time (µs; 0 without the `stage-timing` feature).
    damper_us: f64,
    /// Pairs the contact merge dropped or added.
    merge_changes: usize,
    /// The sync stage's wall time (merge and measure; µs; 0 without the `stage-timing` feature).
    sync_us: f64,
}

impl ProfiledStep {
    /// Step `k` of `w`, just run, which took `dt_cpu` s of CPU time.
    fn of(w: &World, k: usize, dt_cpu: f64) -> Self {
        let d = w.chain_damper();
        ProfiledStep {
            step_us: dt_cpu * 1e6,
            k,
            sweeps: d.last_sweeps,
            rows: d.last_rows,
            row_updates: d.last_row_updates,
            cut: d.last_cut,
            events: w.contacts().events().len(),
            rows_by: if d.last_refreshed {
                RowsBy::Refresh
            } else if d.last_patched {
                RowsBy::Patch
            } else {
                RowsBy::Build
            },
            damper_us: w.stage_times().get(Stage::ChainDamper) as f64 / 1e3,
            merge_changes: w.contacts().last_merge_changes(),
            sync_us: w.stage_times().get(Stage::ContactSync) as f64 / 1e3,
        }
    }
}

/// The warm steps whose contact merge changed the tracked set against the others: how many,
/// their median number of changes, their median step and, with the `stage-timing` feature, the
/// sync stage's median.
fn print_merges(label: &str, profile_after: f64, kinds: &[ProfiledStep]) {
    let median = |group: &[&ProfiledStep], f: fn(&ProfiledStep) -> f64| {
        crate::timing::Samples(group.iter().map(|k| f(k)).collect()).median()
    };
    let (merged, kept): (Vec<&ProfiledStep>, Vec<&ProfiledStep>) =
        kinds.iter().partition(|k| k.merge_changes > 0);
    if merged.is_empty() || kept.is_empty() {
        return;
    }
    let sync = |group: &[&ProfiledStep]| {
        if stage_time::ENABLED {
            format!(", sync stage {:.1} µs wall", median(group, |k| k.sync_us))
        } else {
            String::new()
        }
    };
    println!(
        "{label}: warm steps after {profile_after} s whose contact merge changed the set: {} ({:.1} %, median {} changes), median {:.1} CPU µs per step{}; the others {:.1}{}",
        merged.len(),
        100.0 * merged.len() as f64 / kinds.len() as f64,
        median(&merged, |k| k.merge_changes as f64),
        median(&merged, |k| k.step_us),
        sync(&merged),
        median(&kept, |k| k.step_us),
        sync(&kept),
    );
}

/// How the chain damper made a step's rows: refreshed in place (the loaded contacts were the
/// last step's), patched (a few changed) or built from scratch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum RowsBy {
    Refresh,
    Patch,
    Build,
}

/// The warm steps grouped by what the chain damper did (rows refreshed, patched or rebuilt; 1, 2, 3 or 4+
/// sweeps): how many, their median step, and with the `stage-timing` feature the damper's
/// median. The slowest 1 % of steps, the p99, is where these groups' shares and costs meet.
fn print_damper_kinds(label: &str, profile_after: f64, kinds: &[ProfiledStep]) {
    if kinds.is_empty() {
        return;
    }
    println!(
        "{label}: warm steps after {profile_after} s by the chain damper's work (rows, sweeps: steps, share, median CPU µs per step{}):",
        if stage_time::ENABLED { ", median damper wall µs" } else { "" }
    );
    for rows_by in [RowsBy::Refresh, RowsBy::Patch, RowsBy::Build] {
        for sweeps in 0..=4u32 {
            let group: Vec<&ProfiledStep> = kinds
                .iter()
                .filter(|k| k.rows_by == rows_by && k.sweeps.min(4) == sweeps)
                .collect();
            if group.is_empty() {
                continue;
            }
            let step = crate::timing::Samples(group.iter().map(|k| k.step_us).collect()).median();
            let damper = if stage_time::ENABLED {
                let d = crate::timing::Samples(group.iter().map(|k| k.damper_us).collect());
                format!(", {:8.1}", d.median())
            } else {
                String::new()
            };
            println!(
                "{label}:   {:<9}, sweeps {:>2}: {:5}, {:5.1} %, {:8.1}{damper}",
                match rows_by {
                    RowsBy::Refresh => "refreshed",
                    RowsBy::Patch => "patched",
                    RowsBy::Build => "rebuilt",
                },
                if sweeps == 4 {
                    "4+".to_string()
                } else {
                    sweeps.to_string()
                },
                group.len(),
                100.0 * group.len() as f64 / kinds.len() as f64,
                step
            );
        }
    }
}

/// The chain damper's row updates per warm step (median, p99, largest, steps its work budget cut)
/// and, with the `stage-timing` feature, the cost of a row update (ns; docs/MODELS.md §6.7).
fn print_row_updates(label: &str, profile_after: f64, kinds: &[ProfiledStep]) {
    let with_rows: Vec<&ProfiledStep> = kinds.iter().filter(|k| k.rows > 0).collect();
    if with_rows.is_empty() {
        return;
    }
    let updates = crate::timing::Samples(with_rows.iter().map(|k| k.row_updates as f64).collect());
    println!(
        "{label}: chain damper row updates per warm step after {profile_after} s ({} steps with rows): median {:.0}, p99 {:.0}, largest {:.0}; {} steps cut by the work budget",
        with_rows.len(),
        updates.median(),
        updates.quantile(0.99),
        updates.quantile(1.0),
        with_rows.iter().filter(|k| k.cut).count()
    );
    if !stage_time::ENABLED {
        return;
    }
    // The sweeps' cost: steps whose rows were refreshed in place (a pile at rest: the same rows,
    // the same refresh cost) grouped by their sweeps; the slope of the groups' median damper time
    // against their median row updates (least squares over groups of 5 steps or more) is the
    // cost of a row update, the preempted steps left out by the medians.
    let mut points = Vec::new();
    for sweeps in 1..=64u32 {
        let group: Vec<&&ProfiledStep> = with_rows
            .iter()
            .filter(|k| k.rows_by == RowsBy::Refresh && k.sweeps == sweeps)
            .collect();
        if group.len() >= 5 {
            let median = |f: fn(&ProfiledStep) -> f64| {
                crate::timing::Samples(group.iter().map(|k| f(k)).collect()).median()
            };
            points.push((
                median(|k| k.row_updates as f64),
                median(|k| k.damper_us),
                sweeps,
            ));
        }
    }
    if points.len() < 2 {
        return;
    }
    let n = points.len() as f64;
    let (mx, my) = (
        points.iter().map(|p| p.0).sum::<f64>() / n,
        points.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let groups: Vec<String> = points
        .iter()
        .map(|p| format!("{} sweeps: {:.0} updates, {:.1} µs", p.2, p.0, p.1))
        .collect();
    println!(
        "{label}: damper wall µs of refreshed steps by sweeps (medians; {}): {:.2} ns per row update (slope), {:.1} µs at none (intercept)",
        groups.join("; "),
        sxy / sxx * 1e3,
        my - sxy / sxx * mx
    );
}
