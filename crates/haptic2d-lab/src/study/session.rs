//! Running one session: the directory `OUT/sub-<ID>/ses-<N>/` holds `trials.tsv` (one row per
//! answered trial, written and synced as each trial ends), `study.toml` (the study file, verbatim)
//! and `session.json` (pseudonymous participant ID, session, seeds, software version, observer).
//!
//! A session whose directory already exists resumes: its rows are read (a line cut short by a crash
//! is dropped), the schedule is replayed from the recorded answers (each replayed trial must match
//! its row, or the study or seed changed and the run stops), and the remaining trials follow. No
//! trial is lost or repeated.

use super::file::{Study, Task};
use super::observer::{Answer, Observer};
use super::order::block_order;
use super::rng::{hash_text, mix};
use super::schedule::{Schedule, TrialSpec};
use super::trials::{self, TrialRow, HEADER};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The software version written beside the data.
pub const VERSION: &str = concat!("haptic2d ", env!("CARGO_PKG_VERSION"));

/// Checks a participant ID: 1–32 letters, digits or `-` (a pseudonymous code, never a name).
pub fn check_participant(id: &str) -> Result<(), String> {
    if !id.is_empty() && id.len() <= 32 && id.chars().all(|c| c.is_ascii_alphanumeric() || c == '-')
    {
        Ok(())
    } else {
        Err(format!(
            "participant ID `{id}` is not 1–32 letters, digits or '-'\n    fix: use a pseudonymous code such as P07 (never a name)"
        ))
    }
}

/// The directory of a session.
pub fn session_dir(out: &Path, participant: &str, session: u32) -> PathBuf {
    out.join(format!("sub-{participant}"))
        .join(format!("ses-{session}"))
}

/// The seed of a session: the study's recorded seed mixed with the participant ID and session, so
/// every participant and session gets its own (reproducible) order.
pub fn session_seed(study_seed: u64, participant: &str, session: u32) -> u64 {
    mix(mix(study_seed, hash_text(participant)), u64::from(session))
}

/// What a run did.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSummary {
    /// The session directory.
    pub dir: PathBuf,
    /// Trials found in the directory and replayed.
    pub resumed: u32,
    /// Trials run now.
    pub ran: u32,
    /// The session is complete.
    pub complete: bool,
    /// QUEST's or QUEST+'s estimate per condition (name, threshold, 95 % credible interval), for
    /// QUEST and QUEST+ studies.
    pub quest: Vec<(String, f64, (f64, f64))>,
    /// QUEST+'s slope estimate per condition (name, posterior mean of β), for QUEST+ studies.
    pub slopes: Vec<(String, f64)>,
}

impl RunSummary {
    /// What a session run reports at its end (the simulated and the browser paths alike): each
    /// condition's QUEST or QUEST+ estimate, then where the trials went and whether the session is
    /// complete (`resume_hint` says how to go on when it is not).
    pub fn report(&self, resume_hint: &str) -> String {
        let s = self;
        let mut out = String::new();
        let quest = if s.slopes.is_empty() {
            "QUEST"
        } else {
            "QUEST+"
        };
        for (c, est, (lo, hi)) in &s.quest {
            out += &format!("{quest} {c}: threshold {est:.4} [{lo:.4}, {hi:.4}] (posterior mean, 95 % credible interval)\n");
        }
        for (c, b) in &s.slopes {
            out += &format!("QUEST+ {c}: Weibull slope {b:.2} (posterior mean)\n");
        }
        let resumed = if s.resumed > 0 {
            format!(" after {} resumed from trials.tsv", s.resumed)
        } else {
            String::new()
        };
        let state = if s.complete {
            format!(
                "session complete\nnext: haptic2d study analyse {}",
                s.dir.display()
            )
        } else {
            format!("session not complete: {resume_hint}")
        };
        out += &format!(
            "{}: {} trial(s) run{resumed}; {state}\n",
            s.dir.display(),
            s.ran
        );
        out
    }
}

/// The answer names the comparison (or, same–different: says "different", 1, exactly when the
/// comparison was presented).
pub fn answer_correct(study: &Study, spec: &TrialSpec, response: u8) -> bool {
    if study.task == Task::SameDifferent {
        (response == 1) == (spec.comparison_interval != 0)
    } else {
        response == spec.comparison_interval
    }
}

/// Row of `spec` answered `response` at `rt` s.
fn row(study: &Study, sched: &Schedule, spec: &TrialSpec, a: &Answer) -> TrialRow {
    let (response, rt) = (a.response, a.rt);
    let c = &study.conditions[spec.condition];
    let stair = spec.track.and_then(|t| sched.tracks[t].tracker.stair());
    TrialRow {
        trial: spec.trial,
        block: spec.block,
        practice: spec.practice,
        condition: c.name.clone(),
        track: spec.track,
        vary: c.vary.to_string(),
        reference_value: c.reference_value,
        comparison_value: c.base_value + spec.delta,
        delta: spec.delta,
        comparison_interval: spec.comparison_interval,
        response,
        correct: (!c.pse && study.task != Task::Magnitude)
            .then_some(answer_correct(study, spec, response)),
        rt,
        reversals: stair.map(|s| s.reversals),
        run: stair.map(|s| s.run),
        magnitude: a.magnitude,
    }
}

/// Runs (or resumes) session `session` of `participant` in `out`, answering with `observer`;
/// `study_text` is the study file's text (stored verbatim). `progress(done, planned)` is called
/// after every trial. `stop_after` ends the run after that many new trials (an interruption, for
/// tests and pilots).
#[allow(clippy::too_many_arguments)]
pub fn run(
    study: &Study,
    study_text: &str,
    out: &Path,
    participant: &str,
    session: u32,
    observer: &mut dyn Observer,
    progress: &mut dyn FnMut(u32, u32),
    stop_after: Option<u32>,
) -> Result<RunSummary, String> {
    check_participant(participant)?;
    let dir = session_dir(out, participant, session);
    let tsv = dir.join("trials.tsv");
    let seed = session_seed(study.seed, participant, session);
    let order = block_order(study.counterbalance, study.blocks.len(), participant)?;
    let mut sched = Schedule::ordered(study, seed, order.clone());
    let resumed = if tsv.exists() {
        resume(study, study_text, &dir, &mut sched)?
    } else {
        let meta = serde_json::json!({
            "study": study.name,
            "study_file": study.source,
            "scene": study.scene_source,
            "participant": participant,
            "session": session,
            "seed": study.seed,
            "session_seed": seed,
            "software": VERSION,
            "observer": observer.describe(),
            "task": study.task.describe(),
            "block_order": order.iter().map(|b| b + 1).collect::<Vec<_>>(),
            "trials": "trials.tsv (docs/STUDIES.md)",
        });
        start(study_text, &dir, &meta)?;
        0
    };
    let mut file = std::fs::OpenOptions::new()
        .append(true)
        .open(&tsv)
        .map_err(|e| io(&tsv, e))?;
    let planned = sched.planned();
    let mut ran = 0;
    let mut complete = false;
    loop {
        if stop_after.is_some_and(|n| ran >= n) {
            break;
        }
        let Some(spec) = sched.next_trial() else {
            complete = true;
            break;
        };
        if spec.rest_before {
            observer.rest(study, &spec)?;
        }
        let a = observer.answer(study, &spec)?;
        sched.record(&spec, answer_correct(study, &spec, a.response));
        let r = row(study, &sched, &spec, &a);
        file.write_all(r.to_line().as_bytes())
            .map_err(|e| io(&tsv, e))?;
        file.sync_data().map_err(|e| io(&tsv, e))?;
        ran += 1;
        progress(spec.trial, planned);
    }
    let quest = sched
        .tracks
        .iter()
        .filter_map(|t| {
            t.tracker
                .estimate()
                .map(|(est, ci)| (study.conditions[t.condition].name.clone(), est, ci))
        })
        .collect();
    let slopes = sched
        .tracks
        .iter()
        .filter_map(|t| {
            t.tracker
                .slope_estimate()
                .map(|b| (study.conditions[t.condition].name.clone(), b))
        })
        .collect();
    Ok(RunSummary {
        dir,
        resumed,
        ran,
        complete,
        quest,
        slopes,
    })
}

/// An I/O error on `p`, for messages.
fn io(p: &Path, e: std::io::Error) -> String {
    format!("{}: {e}", p.display())
}

/// Starts a new session in `dir`: the study file's copy, `meta` as `session.json` and the header
/// of `trials.tsv`.
fn start(study_text: &str, dir: &Path, meta: &serde_json::Value) -> Result<(), String> {
    let tsv = dir.join("trials.tsv");
    let copy = dir.join("study.toml");
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    std::fs::write(&copy, study_text).map_err(|e| io(&copy, e))?;
    let mj = dir.join("session.json");
    std::fs::write(
        &mj,
        serde_json::to_string_pretty(meta).unwrap_or_default() + "\n",
    )
    .map_err(|e| io(&mj, e))?;
    std::fs::write(&tsv, format!("{HEADER}\n")).map_err(|e| io(&tsv, e))?;
    Ok(())
}

/// Resumes the session in `dir`: checks its study file, replays its rows into `sched` and drops a
/// line cut short. Returns the number of trials replayed.
fn resume(
    study: &Study,
    study_text: &str,
    dir: &Path,
    sched: &mut Schedule,
) -> Result<u32, String> {
    let tsv = dir.join("trials.tsv");
    let copy = dir.join("study.toml");
    let stored = std::fs::read_to_string(&copy).map_err(|e| io(&copy, e))?;
    if stored != study_text {
        return Err(format!(
            "{} holds a session of a different study file (its study.toml differs)\n    fix: give another --out, --participant or --session, or the study file this session was started with",
            dir.display()
        ));
    }
    let text = std::fs::read_to_string(&tsv).map_err(|e| io(&tsv, e))?;
    let (rows, complete) = trials::read(&text).map_err(|e| format!("{}: {e}", tsv.display()))?;
    let mut resumed = 0;
    for r in &rows {
        let spec = sched.next_trial().ok_or_else(|| {
            format!(
                "{}: row {} is beyond the end of the schedule",
                tsv.display(),
                r.trial
            )
        })?;
        let answer = Answer {
            response: r.response,
            rt: r.rt,
            magnitude: r.magnitude,
        };
        let expect = row(study, sched, &spec, &answer);
        let same = spec.trial == r.trial
            && spec.practice == r.practice
            && expect.condition == r.condition
            && spec.delta == r.delta
            && spec.comparison_interval == r.comparison_interval;
        if !same {
            return Err(format!(
                "{}: trial {} does not match the study's schedule (recorded {} delta {} interval {}, scheduled {} delta {} interval {}): the study file or its seed changed\n    fix: resume with the study file the session was started with",
                tsv.display(), r.trial, r.condition, r.delta, r.comparison_interval, expect.condition, spec.delta, spec.comparison_interval
            ));
        }
        sched.record(&spec, answer_correct(study, &spec, r.response));
        resumed += 1;
    }
    if complete < text.len() || text.is_empty() {
        // Drop the cut line (or write the header of an empty file).
        let f = std::fs::OpenOptions::new()
            .write(true)
            .open(&tsv)
            .map_err(|e| io(&tsv, e))?;
        f.set_len(complete as u64).map_err(|e| io(&tsv, e))?;
        if complete == 0 {
            std::fs::write(&tsv, format!("{HEADER}\n")).map_err(|e| io(&tsv, e))?;
        }
    }
    Ok(resumed)
}
