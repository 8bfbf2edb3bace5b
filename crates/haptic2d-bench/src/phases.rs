//! `--phases LANDING_END,SETTLED_FROM`: the step times of every engine split into a landing phase
//! (the timed steps before `LANDING_END`) and a settled phase (from `SETTLED_FROM` on), with the
//! figures issue 42 sets targets on: per phase and engine the median, the p99 and p99/median;
//! haptic2d's median ratio to each peer per phase; and the landing's worst 1 % of haptic2d's steps
//! against its own settled median. Time the landing from the start with `--warmup 0` (step `i` is
//! then sample `i`, 1 ms each).

use crate::timing::Samples;
use haptic2d::stage_time::{Stage, StageTimes};

/// The two phases, in timed-step indices: landing `[0, landing_end)`, settled `[settled_from, ..)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Phases {
    /// First timed step after the landing.
    pub landing_end: usize,
    /// First timed step of the settled phase.
    pub settled_from: usize,
}

impl std::str::FromStr for Phases {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let v: Vec<usize> = s
            .split(',')
            .map(|p| p.trim().parse::<usize>())
            .collect::<Result<_, _>>()
            .map_err(|e| {
                format!("--phases {s}: {e} (expected LANDING_END,SETTLED_FROM, e.g. 1000,2000)")
            })?;
        match v[..] {
            [l, s_] if l > 0 && s_ >= l => Ok(Self {
                landing_end: l,
                settled_from: s_,
            }),
            _ => Err(format!(
                "--phases {s}: expected LANDING_END,SETTLED_FROM with 0 < LANDING_END ≤ SETTLED_FROM (timed steps), e.g. 1000,2000"
            )),
        }
    }
}

impl Phases {
    /// Checks the phases against `steps` timed steps (the settled phase must not be empty).
    pub fn check(&self, steps: usize) -> Result<(), String> {
        if self.settled_from >= steps {
            return Err(format!(
                "--phases: the settled phase starts at step {} but only {steps} steps are timed (--steps)",
                self.settled_from
            ));
        }
        Ok(())
    }

    /// The landing's and the settled phase's steps of `t`.
    pub fn split(&self, t: &Samples) -> (Samples, Samples) {
        let end = self.landing_end.min(t.0.len());
        let from = self.settled_from.min(t.0.len());
        (Samples(t.0[..end].to_vec()), Samples(t.0[from..].to_vec()))
    }
}

/// The phase table of one case: `engines` are (key, timed steps), haptic2d first.
pub fn table(label: &str, phases: Phases, engines: &[(&str, &Samples)]) -> String {
    let mut out = format!(
        "{label}: phases — landing = timed steps 0..{}, settled = {}..\n",
        phases.landing_end, phases.settled_from
    );
    out.push_str("  engine            | landing median µs | p99 µs | p99/med | settled median µs | p99 µs | p99/med\n");
    let split: Vec<(&str, Samples, Samples)> = engines
        .iter()
        .map(|(k, t)| {
            let (l, s) = phases.split(t);
            (*k, l, s)
        })
        .collect();
    for (k, l, s) in &split {
        out.push_str(&format!(
            "  {k:<17} | {:>17.1} | {:>6.1} | {:>7.2} | {:>17.1} | {:>6.1} | {:>7.2}\n",
            l.median(),
            l.p99(),
            l.p99() / l.median(),
            s.median(),
            s.p99(),
            s.p99() / s.median()
        ));
    }
    if let Some((_, hl, hs)) = split.first() {
        for (k, l, s) in split.iter().skip(1) {
            out.push_str(&format!(
                "  haptic2d / {k}: landing median ratio {:.3}, settled median ratio {:.3}\n",
                hl.median() / l.median(),
                hs.median() / s.median()
            ));
        }
        out.push_str(&format!(
            "  haptic2d: landing p99 / settled median {:.2} (issue 42's target ≤ 2)\n",
            hl.p99() / hs.median()
        ));
    }
    out
}

/// haptic2d's stage profile per phase (a `stage-timing` build): the mean wall time of each stage
/// over the landing, over the landing's worst 1 % of steps (those at or above its p99) and over
/// the settled phase, so that the landing's tail names the stages that make it. `steps` are
/// haptic2d's timed steps (µs) and `stages` the stage times of the same steps, in order.
pub fn stage_table(label: &str, phases: Phases, steps: &Samples, stages: &[StageTimes]) -> String {
    let n = steps.0.len().min(stages.len());
    let (land, _) = phases.split(&Samples(steps.0[..n].to_vec()));
    let p99 = land.p99();
    let landing: Vec<usize> = (0..land.0.len()).collect();
    let tail: Vec<usize> = landing
        .iter()
        .copied()
        .filter(|&i| steps.0[i] >= p99)
        .collect();
    let settled_steps: Vec<usize> = (phases.settled_from.min(n)..n).collect();
    let sets = [
        ("landing", &landing),
        ("landing ≥ p99", &tail),
        ("settled", &settled_steps),
    ];
    let mut out = format!(
        "{label}: haptic2d's mean µs per stage (stage-timing build: the wall clock at each stage boundary, which counts preemption that --clock cpu does not) — {} landing steps ≥ p99 {:.1} µs\n",
        tail.len(),
        p99
    );
    out.push_str(&format!("  {:<14}", "stage"));
    for (name, _) in sets {
        out.push_str(&format!(" | {name:>14}"));
    }
    out.push('\n');
    let mean = |set: &[usize], f: &dyn Fn(&StageTimes) -> u64| {
        set.iter().map(|&i| f(&stages[i]) as f64).sum::<f64>() / set.len().max(1) as f64 * 1e-3
    };
    for s in Stage::ALL {
        out.push_str(&format!("  {:<14}", s.name()));
        for (_, set) in sets {
            out.push_str(&format!(" | {:>14.1}", mean(set, &|t| t.get(s))));
        }
        out.push('\n');
    }
    out.push_str(&format!("  {:<14}", "step"));
    for (_, set) in sets {
        out.push_str(&format!(" | {:>14.1}", mean(set, &|t| t.total())));
    }
    out.push('\n');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phases_parse_and_refuse_what_cannot_split() {
        let p: Phases = "1000,2000".parse().unwrap();
        assert_eq!(
            p,
            Phases {
                landing_end: 1000,
                settled_from: 2000
            }
        );
        assert!("0,10".parse::<Phases>().is_err());
        assert!("20,10".parse::<Phases>().is_err());
        assert!("10".parse::<Phases>().is_err());
        assert!("a,b".parse::<Phases>().is_err());
        assert!(p.check(2000).is_err() && p.check(2001).is_ok());
    }

    #[test]
    fn the_table_splits_the_steps_and_takes_ratios_per_phase() {
        // haptic2d: landing 10 µs, settled 2 µs; the peer: landing 20 µs, settled 8 µs.
        let h = Samples([vec![10.0; 100], vec![5.0; 50], vec![2.0; 100]].concat());
        let b = Samples([vec![20.0; 100], vec![5.0; 50], vec![8.0; 100]].concat());
        let t = table(
            "pile n=1",
            Phases {
                landing_end: 100,
                settled_from: 150,
            },
            &[("haptic2d", &h), ("box2d", &b)],
        );
        assert!(
            t.contains("landing median ratio 0.500, settled median ratio 0.250"),
            "{t}"
        );
        assert!(t.contains("landing p99 / settled median 5.00"), "{t}");
    }

    #[test]
    fn the_stage_table_averages_each_phase_and_the_landing_tail() {
        // 100 landing steps, the last two slow (the p99 of 100 steps is the 99th smallest); the
        // slow steps spent 900 ns each in the damper.
        let mut t = vec![10.0; 100];
        t[98] = 100.0;
        t[99] = 100.0;
        t.extend(vec![1.0; 50]);
        let mut st = vec![StageTimes::default(); 150];
        st[98].ns[Stage::ChainDamper as usize] = 900;
        st[99].ns[Stage::ChainDamper as usize] = 900;
        for x in &mut st[100..] {
            x.ns[Stage::ContactForces as usize] = 500;
        }
        let out = stage_table(
            "pile",
            Phases {
                landing_end: 100,
                settled_from: 100,
            },
            &Samples(t),
            &st,
        );
        // The damper: 0.018 µs over the landing, 0.9 µs over its tail, 0 settled.
        let damper = out
            .lines()
            .find(|l| l.trim_start().starts_with("damper"))
            .unwrap();
        assert!(
            damper.contains("0.0 |            0.9 |            0.0"),
            "{out}"
        );
        let forces = out
            .lines()
            .find(|l| l.trim_start().starts_with("forces"))
            .unwrap();
        assert!(forces.ends_with("0.5"), "{out}");
        assert!(out.contains("2 landing steps ≥ p99 100.0 µs"), "{out}");
    }
}
