//! The TOML schema of a study file (serde types, unknown fields are errors) and its validation into a
//! [`Study`]: every problem is reported with the field it concerns and the fix, as scene files are.
//!
//! The format is documented in `docs/STUDIES.md`; `studies/stiffness-walls.toml` is a worked example.

use super::method::Method;
use super::observer::ObserverParams;
use super::stimulus::{self, Param};
use haptic2d::scene::{SceneError, SceneErrors, BUILTIN, MAX_FILE_BYTES};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// A whole study file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudyFile {
    /// Study name (used in reports).
    pub name: Option<String>,
    /// One-line description.
    pub description: Option<String>,
    /// A built-in scene name (`haptic2d scenes`) or a scene file path relative to the study file.
    pub scene: String,
    /// Control rate (Hz) overriding the scene's `world.rate`.
    pub rate: Option<f64>,
    /// The body the participant's handle holds (the simulated hand presses it).
    pub probe: String,
    /// Unit direction (world frame) from the probe toward the wall it explores.
    pub toward: [f64; 2],
    /// Seed of every random choice (trial order, interval order); recorded with the data.
    pub seed: u64,
    /// The task.
    pub task: TaskSection,
    /// Named stimuli: parameter sets of the wall (`normal`) and friction (`friction`) laws.
    #[serde(default)]
    pub stimuli: BTreeMap<String, StimulusSection>,
    /// Conditions: a reference stimulus, the comparison and the parameter the method varies.
    #[serde(rename = "condition", default)]
    pub conditions: Vec<ConditionSection>,
    /// The psychophysical method.
    pub method: MethodSection,
    /// Blocks (default: one block with every condition, no practice).
    #[serde(rename = "block", default)]
    pub blocks: Vec<BlockSection>,
    /// Parameters of the simulated observer (a model, not data).
    #[serde(default)]
    pub observer: ObserverSection,
    /// The block order across participants: `"none"` (default), `"reverse"`, `"williams"`.
    pub counterbalance: Option<String>,
    /// When the session rests.
    pub breaks: Option<super::order::BreaksSection>,
}

/// `[task]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskSection {
    /// `"2afc"` or `"2ifc"`: two intervals, one reference and one comparison; "which was stiffer?".
    pub kind: String,
    /// Magnitude estimation: the number the reference (the modulus, first interval) stands for
    /// (default 100).
    pub modulus: Option<f64>,
}

/// `[stimuli.NAME]`: a parameter set; each table is a scene file's `[normal]`/`[friction]` table.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StimulusSection {
    /// Wall law and its parameters, e.g. `{ model = "paper", kc = 1000.0, bc = 5.0 }` (default: the scene's).
    pub normal: Option<toml::Table>,
    /// Friction model and its parameters (default: the scene's).
    pub friction: Option<toml::Table>,
}

/// `[[condition]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConditionSection {
    /// Condition name (a label in the data).
    pub name: String,
    /// The reference stimulus (a key of `[stimuli]`).
    pub reference: String,
    /// The comparison's base stimulus (default: the reference).
    pub comparison: Option<String>,
    /// The comparison parameter the method varies, `normal.KEY` or `friction.KEY`: the comparison
    /// presents the base stimulus with that parameter raised by the method's delta.
    pub vary: String,
    /// Constant stimuli: this condition's own deltas (default: the method's), e.g. a PSE condition
    /// whose comparison must reach far from the reference.
    pub deltas: Option<Vec<f64>>,
}

/// `[method]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MethodSection {
    /// `"constant"` (method of constant stimuli) or `"staircase"` (transformed up/down).
    pub kind: String,
    /// Constant stimuli: the deltas (comparison − base, in the unit of `vary`), all > 0.
    pub deltas: Option<Vec<f64>>,
    /// Constant stimuli: presentations of each delta per condition.
    pub repeats: Option<u32>,
    /// Staircase: `"1-up-2-down"` (→ 70.7 % correct), `"1-up-3-down"` (→ 79.4 %) or
    /// `"weighted"` (Kaernbach 1991, converging on `target`).
    pub rule: Option<String>,
    /// Weighted staircase: the proportion correct it converges on, in (0.5, 0.99).
    pub target: Option<f64>,
    /// Staircase: the starting delta of each interleaved staircase of a condition.
    pub starts: Option<Vec<f64>>,
    /// Staircase: multiplicative step (down = delta / f, up = delta · f), > 1.
    pub step_factor: Option<f64>,
    /// Staircase: the step factor until the second reversal (default `step_factor`).
    pub initial_step_factor: Option<f64>,
    /// Staircase: stop after this many trials.
    pub max_trials: Option<u32>,
    /// Staircase: stop after this many reversals.
    pub max_reversals: Option<u32>,
    /// Staircase: smallest delta (default: the smallest start / 64).
    pub min_delta: Option<f64>,
    /// Staircase: largest delta (default: 4 × the largest start). QUEST: the grid's ends.
    pub max_delta: Option<f64>,
    /// QUEST: the prior's centre, the expected threshold (delta).
    pub start: Option<f64>,
    /// QUEST: the prior's sd of log₁₀ threshold (default 0.5).
    pub prior_sd: Option<f64>,
    /// QUEST: the assumed Weibull slope (default 3.5).
    pub beta: Option<f64>,
    /// QUEST: the assumed lapse rate (default 0.01).
    pub lapse: Option<f64>,
    /// QUEST: `"mean"` (default) or `"mode"` of the posterior.
    pub placement: Option<String>,
    /// QUEST+: the Weibull slopes the posterior spans (default [`super::method::DEFAULT_SLOPES`]).
    pub slopes: Option<Vec<f64>>,
}

/// `[[block]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockSection {
    /// The conditions run (interleaved at random) in this block.
    pub conditions: Vec<String>,
    /// Practice trials at the start of the block (easiest delta; not analysed).
    pub practice: Option<u32>,
}

/// `[observer]`: the simulated observer's model parameters.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObserverSection {
    /// Weber fraction `W`: the relative stiffness increment the model discriminates at 75 % correct.
    pub weber_fraction: Option<f64>,
    /// Lapse rate `λ`: the probability the model answers at random.
    pub lapse_rate: Option<f64>,
    /// The two press forces `[F1, F2]` (N) of the exploration, `0 < F1 < F2`.
    pub press_forces: Option<[f64; 2]>,
    /// Duration of each press (s).
    pub press_time: Option<f64>,
    /// Median decision time added to the exploration time (s).
    pub decision_time: Option<f64>,
    /// `"press"` (default), `"tap"` or `"stroke"` (docs/STUDIES.md, the simulated observer).
    pub exploration: Option<String>,
    /// Same–different: the differencing criterion in units of the percept noise (default 1.8).
    pub sd_criterion: Option<f64>,
    /// Magnitude estimation: Stevens' exponent on the percepts (default 0.8).
    pub magnitude_exponent: Option<f64>,
    /// Ramp time of each change of the press force (s), default 0 (a step).
    pub press_ramp: Option<f64>,
    /// The hand's damping on the probe's velocity (N·s/m), default 0.
    pub hand_damping: Option<f64>,
    /// Torsional stiffness of the hand's grip on the probe's angle (N·m/rad), default 0.
    pub grip_stiffness: Option<f64>,
    /// Torsional damping of the grip (N·m·s/rad), default 0.
    pub grip_damping: Option<f64>,
    /// Tap speed (m/s).
    pub tap_speed: Option<f64>,
    /// Tap window (s).
    pub tap_window: Option<f64>,
    /// Stroke normal force (N).
    pub stroke_normal: Option<f64>,
    /// Stroke tangential pushes `[F_t1, F_t2]` (N).
    pub stroke_forces: Option<[f64; 2]>,
    /// Stroke tremor amplitude (N).
    pub tremor_amplitude: Option<f64>,
    /// Stroke tremor frequency (Hz).
    pub tremor_hz: Option<f64>,
}

/// The task of a study.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Task {
    /// Two intervals (reference and comparison in random order), "which was stiffer?".
    TwoAfc,
    /// Three intervals (two references and the comparison, in random order), "which was
    /// stiffest?".
    ThreeAfc,
    /// Two intervals, "same or different?": half the trials present the reference twice, half
    /// the reference and the comparison in random order.
    SameDifferent,
    /// Magnitude estimation (Stevens 1957): the reference (the modulus) then the comparison;
    /// "if the first was [`Study::modulus`], what number is the second?".
    Magnitude,
}

impl Task {
    /// The guess rate `γ` of the task (1 / the number of intervals; same–different trials are
    /// analysed by signal detection instead, see `analyse.rs`).
    pub fn guess_rate(self) -> f64 {
        1.0 / self.intervals() as f64
    }
    /// The number of intervals of a trial.
    pub fn intervals(self) -> usize {
        match self {
            Task::TwoAfc | Task::SameDifferent | Task::Magnitude => 2,
            Task::ThreeAfc => 3,
        }
    }
    /// The task as written in `session.json`.
    pub fn describe(self) -> &'static str {
        match self {
            Task::TwoAfc => "2afc: which interval was stiffer?",
            Task::ThreeAfc => "3afc: which of three intervals was stiffest?",
            Task::SameDifferent => "same-different: were the two intervals the same? (response 0 = same, 1 = different; comparison_interval 0 = a same trial)",
            Task::Magnitude => "magnitude: the first interval is the modulus; what number is the second? (column magnitude; response 0)",
        }
    }
    /// Parses `[task] kind` (as stored in a session's `study.toml`).
    pub fn from_name(s: &str) -> Option<Task> {
        match s {
            "2afc" | "2ifc" => Some(Task::TwoAfc),
            "3afc" | "3ifc" => Some(Task::ThreeAfc),
            "same-different" => Some(Task::SameDifferent),
            "magnitude" => Some(Task::Magnitude),
            _ => None,
        }
    }
}

/// A validated condition.
#[derive(Clone, Debug)]
pub struct Condition {
    /// Condition name.
    pub name: String,
    /// Reference stimulus name.
    pub reference: String,
    /// Comparison base stimulus name.
    pub comparison: String,
    /// The varied parameter.
    pub vary: Param,
    /// The value of `vary` in the reference stimulus (unit of the parameter).
    pub reference_value: f64,
    /// The value of `vary` in the comparison base stimulus.
    pub base_value: f64,
    /// A PSE condition: the comparison is another stimulus than the reference, so no answer is
    /// correct; the analysis fits P(comparison named stiffer) against the comparison's value.
    pub pse: bool,
    /// Constant stimuli: the condition's own deltas (else the method's).
    pub deltas: Option<Vec<f64>>,
}

/// A validated block.
#[derive(Clone, Debug)]
pub struct Block {
    /// Indices into [`Study::conditions`].
    pub conditions: Vec<usize>,
    /// Practice trials at its start.
    pub practice: u32,
}

/// A validated study, ready to run.
#[derive(Clone, Debug)]
pub struct Study {
    /// Study name.
    pub name: String,
    /// Description.
    pub description: String,
    /// Where the study came from (file path).
    pub source: String,
    /// The scene's TOML text and its source (built-in name or path).
    pub scene_text: String,
    /// The scene's source, for messages.
    pub scene_source: String,
    /// Control rate override (Hz).
    pub rate: Option<f64>,
    /// Probe body name.
    pub probe: String,
    /// Unit direction toward the wall.
    pub toward: [f64; 2],
    /// Recorded seed.
    pub seed: u64,
    /// Task.
    pub task: Task,
    /// Named stimuli.
    pub stimuli: BTreeMap<String, StimulusSection>,
    /// Conditions.
    pub conditions: Vec<Condition>,
    /// Method.
    pub method: Method,
    /// Blocks.
    pub blocks: Vec<Block>,
    /// The simulated observer's parameters.
    pub observer: ObserverParams,
    /// Magnitude estimation: the number the reference stands for.
    pub modulus: f64,
    /// The block order across participants (`order.rs`).
    pub counterbalance: super::order::Counterbalance,
    /// When the session rests (`order.rs`).
    pub breaks: super::order::Breaks,
}

impl Study {
    /// Reads and validates a study file; a relative `scene` path is resolved beside it.
    pub fn load(path: &Path) -> Result<Study, String> {
        Self::read(path).map(|(s, _)| s)
    }

    /// As [`load`](Self::load), also returning the file's text (the text validated is the text to
    /// store beside the data: the file is read once).
    pub fn read(path: &Path) -> Result<(Study, String), String> {
        let meta = std::fs::metadata(path)
            .map_err(|e| format!("cannot read study file {}: {e}", path.display()))?;
        if meta.len() > MAX_FILE_BYTES {
            return Err(format!(
                "study file {} is {} bytes, more than {MAX_FILE_BYTES}",
                path.display(),
                meta.len()
            ));
        }
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read study file {}: {e}", path.display()))?;
        let study = Study::from_toml(&text, &path.display().to_string(), path.parent())
            .map_err(|e| e.to_string().trim_end().to_string())?;
        Ok((study, text))
    }

    /// Parses and validates study text; `dir` resolves a relative scene path.
    pub fn from_toml(text: &str, source: &str, dir: Option<&Path>) -> Result<Study, SceneErrors> {
        let fail = |errors| SceneErrors {
            source: source.to_string(),
            errors,
        };
        let file: StudyFile = toml::from_str(text).map_err(|e| {
            fail(vec![SceneError::from_toml(
                text,
                &e,
                "check the TOML syntax and field names against docs/STUDIES.md",
            )])
        })?;
        let mut errs = Vec::new();
        let study = validate(file, source, dir, &mut errs);
        match study {
            Some(s) if errs.is_empty() => Ok(s),
            _ => Err(fail(errs)),
        }
    }

    /// The constant-stimuli deltas of condition `c`: its own, or the method's (empty for staircases).
    pub fn deltas(&self, c: usize) -> &[f64] {
        match (&self.conditions[c].deltas, &self.method) {
            (Some(d), _) => d,
            (None, Method::Constant { deltas, .. }) => deltas,
            _ => &[],
        }
    }

    /// The largest delta condition `c` can present (practice trials use it).
    pub fn largest_delta(&self, c: usize) -> f64 {
        match self.method {
            Method::Constant { .. } => self
                .deltas(c)
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max),
            _ => self.method.largest_delta(),
        }
    }

    /// The smallest delta condition `c` can present.
    pub fn smallest_delta(&self, c: usize) -> f64 {
        match self.method {
            Method::Constant { .. } => self.deltas(c).iter().copied().fold(f64::INFINITY, f64::min),
            _ => self.method.smallest_delta(),
        }
    }

    /// The delta of condition `c`'s practice trials: its largest constant delta, or the largest
    /// staircase start.
    pub fn practice_delta(&self, c: usize) -> f64 {
        match self.method {
            Method::Constant { .. } => self.largest_delta(c),
            _ => self.method.practice_delta(),
        }
    }

    /// The index of the condition called `name`.
    pub fn condition_index(&self, name: &str) -> Option<usize> {
        self.conditions.iter().position(|c| c.name == name)
    }
}

fn err(errs: &mut Vec<SceneError>, field: &str, msg: impl Into<String>, fix: impl Into<String>) {
    errs.push(SceneError::new(field, msg, fix));
}

fn scene_text(scene: &str, dir: Option<&Path>) -> Result<(String, String), String> {
    if let Some((_, _, text)) = BUILTIN.iter().find(|b| b.0 == scene) {
        return Ok((text.to_string(), format!("built-in:{scene}")));
    }
    let p = match dir {
        Some(d) if Path::new(scene).is_relative() => d.join(scene),
        _ => Path::new(scene).to_path_buf(),
    };
    match std::fs::metadata(&p) {
        Ok(m) if m.len() > MAX_FILE_BYTES => Err(format!(
            "{} is larger than {MAX_FILE_BYTES} bytes",
            p.display()
        )),
        Ok(_) => std::fs::read_to_string(&p)
            .map(|t| (t, p.display().to_string()))
            .map_err(|e| format!("cannot read {}: {e}", p.display())),
        Err(e) => Err(format!(
            "`{scene}` is no built-in scene and no readable file ({}: {e})",
            p.display()
        )),
    }
}

fn validate(
    f: StudyFile,
    source: &str,
    dir: Option<&Path>,
    errs: &mut Vec<SceneError>,
) -> Option<Study> {
    let task = task_from(&f.task, errs);
    let (scene_text, scene_source) = match scene_text(&f.scene, dir) {
        Ok(t) => t,
        Err(e) => {
            err(errs, "scene", e, "give a built-in scene name (`haptic2d scenes`) or a scene file path relative to the study file");
            return None;
        }
    };
    let toward = head_fields(&f, errs);
    let observer = ObserverParams::from_section(&f.observer, errs);
    let own = !f.conditions.is_empty() && f.conditions.iter().all(|c| c.deltas.is_some());
    let method = Method::from_section(&f.method, own, errs);
    let conditions = conditions_from(&f, task, errs);
    let blocks = blocks_from(&f, conditions.len(), errs);
    let (counterbalance, breaks) = super::order::from_file(&f, errs);
    let modulus = modulus_from(&f, task, errs);
    let method = method?;
    let study = Study {
        name: f.name.clone().unwrap_or_else(|| "study".into()),
        description: f.description.clone().unwrap_or_default(),
        source: source.to_string(),
        scene_text,
        scene_source,
        rate: f.rate,
        probe: f.probe.clone(),
        toward,
        seed: f.seed,
        task,
        stimuli: f.stimuli.clone(),
        conditions,
        method,
        blocks,
        observer: observer.unwrap_or_default(),
        modulus,
        counterbalance,
        breaks,
    };
    check_worlds(&study, errs)?;
    Some(study)
}

/// `[task] modulus`: magnitude estimation's number for the reference (default 100).
fn modulus_from(f: &StudyFile, task: Task, errs: &mut Vec<SceneError>) -> f64 {
    let m = f.task.modulus.unwrap_or(100.0);
    if f.task.modulus.is_some() && task != Task::Magnitude {
        err(
            errs,
            "task.modulus",
            "only magnitude estimation has a modulus",
            "remove it, or set kind = \"magnitude\"",
        );
    } else if !(m.is_finite() && m > 0.0) {
        err(
            errs,
            "task.modulus",
            format!("{m}"),
            "give the positive number the reference stands for, e.g. modulus = 100.0",
        );
    }
    m
}

/// `[task]`: the task (an unknown one is reported and taken as 2AFC).
fn task_from(t: &TaskSection, errs: &mut Vec<SceneError>) -> Task {
    match Task::from_name(&t.kind) {
        Some(t) => t,
        None => {
            err(
                errs,
                "task.kind",
                format!("unknown task `{}`", t.kind),
                "write kind = \"2afc\" (or \"2ifc\"), \"3afc\" (or \"3ifc\"), \"same-different\" or \"magnitude\"",
            );
            Task::TwoAfc
        }
    }
}

/// The top-level `rate`, `toward` and `[stimuli]`; returns the unit `toward`.
fn head_fields(f: &StudyFile, errs: &mut Vec<SceneError>) -> [f64; 2] {
    if let Some(r) = f.rate {
        if !(r.is_finite() && r > 0.0) {
            err(
                errs,
                "rate",
                format!("must be a positive rate in Hz, got {r}"),
                "e.g. rate = 500.0, or remove it to use the scene's",
            );
        }
    }
    let n = (f.toward[0].powi(2) + f.toward[1].powi(2)).sqrt();
    let toward = if n.is_finite() && n > 1e-9 {
        [f.toward[0] / n, f.toward[1] / n]
    } else {
        err(
            errs,
            "toward",
            "must be a non-zero direction",
            "e.g. toward = [-1.0, 0.0] for a wall on the probe's left",
        );
        [1.0, 0.0]
    };
    if f.stimuli.is_empty() {
        err(
            errs,
            "stimuli",
            "no stimulus defined",
            "add e.g. [stimuli.spring] normal = { model = \"paper\", kc = 1000.0 }",
        );
    }
    toward
}

/// The `[[condition]]` tables; a condition with a problem is reported and left out.
fn conditions_from(f: &StudyFile, task: Task, errs: &mut Vec<SceneError>) -> Vec<Condition> {
    if f.conditions.is_empty() {
        err(
            errs,
            "condition",
            "no condition defined",
            "add a [[condition]] with name, reference and vary",
        );
    }
    (0..f.conditions.len())
        .filter_map(|i| condition_from(f, i, task, errs))
        .collect()
}

/// `[[condition]]` number `i`.
fn condition_from(
    f: &StudyFile,
    i: usize,
    task: Task,
    errs: &mut Vec<SceneError>,
) -> Option<Condition> {
    let c = &f.conditions[i];
    let field = format!("condition[{i}]");
    condition_name(f, i, &field, errs);
    let comparison = c.comparison.clone().unwrap_or_else(|| c.reference.clone());
    let mut ok = true;
    for (key, s) in [("reference", &c.reference), ("comparison", &comparison)] {
        if !f.stimuli.contains_key(s) {
            ok = false;
            err(
                errs,
                &format!("{field}.{key}"),
                format!("no stimulus called `{s}`"),
                format!(
                    "use one of: {}",
                    f.stimuli.keys().cloned().collect::<Vec<_>>().join(", ")
                ),
            );
        }
    }
    let vary = match Param::parse(&c.vary) {
        Ok(p) => p,
        Err(e) => {
            err(
                errs,
                &format!("{field}.vary"),
                e,
                "write vary = \"normal.KEY\" or \"friction.KEY\", e.g. \"normal.kc\"",
            );
            return None;
        }
    };
    if !ok {
        return None;
    }
    // A PSE condition compares two different stimuli (e.g. a spring against a pulse wall):
    // the reference need not set `vary`; its nominal value is then the comparison's base.
    let pse = comparison != c.reference;
    let base_value = stimulus_value(f, &comparison, &vary, errs)?;
    let reference_value = if pse {
        stimulus::param_value(&f.stimuli[&c.reference], &vary).unwrap_or(base_value)
    } else {
        stimulus_value(f, &c.reference, &vary, errs)?
    };
    condition_deltas(f, c, &field, pse, errs);
    condition_method(f, c, &field, pse, task, errs);
    Some(Condition {
        name: c.name.clone(),
        reference: c.reference.clone(),
        comparison,
        vary,
        reference_value,
        base_value,
        pse,
        deltas: c.deltas.clone(),
    })
}

/// The name of condition `i`: unique, non-empty, without tabs or newlines.
fn condition_name(f: &StudyFile, i: usize, field: &str, errs: &mut Vec<SceneError>) {
    let c = &f.conditions[i];
    if f.conditions[..i].iter().any(|o| o.name == c.name) {
        err(
            errs,
            &format!("{field}.name"),
            format!("`{}` is used twice", c.name),
            "give every condition its own name",
        );
    }
    if c.name.is_empty() || c.name.contains(['\t', '\n']) {
        err(
            errs,
            &format!("{field}.name"),
            "must be non-empty, without tabs or newlines",
            "e.g. name = \"spring-1000\"",
        );
    }
}

/// The value of `vary` in stimulus `name` (which the method varies, so it must set it).
fn stimulus_value(
    f: &StudyFile,
    name: &str,
    vary: &Param,
    errs: &mut Vec<SceneError>,
) -> Option<f64> {
    match stimulus::param_value(&f.stimuli[name], vary) {
        Ok(v) => Some(v),
        Err(e) => {
            err(
                errs,
                &format!("stimuli.{name}.{vary}"),
                e,
                format!("set {vary} in stimulus `{name}` (the method varies it)"),
            );
            None
        }
    }
}

/// A condition's own deltas, and the sign of the deltas it presents.
fn condition_deltas(
    f: &StudyFile,
    c: &ConditionSection,
    field: &str,
    pse: bool,
    errs: &mut Vec<SceneError>,
) {
    if c.deltas.is_some() && f.method.kind != "constant" {
        err(
            errs,
            &format!("{field}.deltas"),
            "a condition's own deltas belong to the method of constant stimuli",
            "remove them, or set [method] kind = \"constant\"",
        );
    }
    if let Some(d) = &c.deltas {
        if d.is_empty() || d.iter().any(|x| !x.is_finite()) {
            err(
                errs,
                &format!("{field}.deltas"),
                format!("{d:?}"),
                "give at least one finite delta, e.g. deltas = [-300.0, 0.0, 300.0]",
            );
        }
    }
    let field_d = if c.deltas.is_some() {
        format!("{field}.deltas")
    } else {
        "method.deltas".to_string()
    };
    if let Some(d) = c.deltas.as_ref().or(f.method.deltas.as_ref()) {
        if !pse && f.task.kind != "magnitude" {
            if let Some(x) = d.iter().find(|x| x.is_finite() && **x <= 0.0) {
                err(
                    errs,
                    &field_d,
                    format!("{x} is not positive, and condition `{}` is a discrimination (its comparison is its reference)", c.name),
                    "every delta of a discrimination must be > 0 (the comparison is the stiffer stimulus); negative deltas belong to a PSE condition, whose `comparison` is another stimulus",
                );
            }
        }
    }
}

/// The task and method a condition needs: PSE conditions and same–different tasks need two
/// intervals and constant stimuli.
fn condition_method(
    f: &StudyFile,
    c: &ConditionSection,
    field: &str,
    pse: bool,
    task: Task,
    errs: &mut Vec<SceneError>,
) {
    if pse && !matches!(f.task.kind.as_str(), "2afc" | "2ifc") {
        err(
            errs,
            "task.kind",
            format!(
                "condition `{}` compares two stimuli (a PSE design), which needs two intervals",
                c.name
            ),
            "use kind = \"2afc\" for PSE conditions",
        );
    }
    if task == Task::Magnitude && f.method.kind != "constant" {
        err(
            errs,
            "method.kind",
            "magnitude estimation presents fixed levels; adaptive methods converge on a proportion correct",
            "use kind = \"constant\" with deltas on both sides of the reference (the comparison's value must stay valid)",
        );
    }
    if task == Task::SameDifferent && f.method.kind != "constant" {
        err(
            errs,
            "method.kind",
            "same–different trials are analysed by signal detection, and adaptive methods converge on a proportion correct",
            "use kind = \"constant\" with a same–different task",
        );
    }
    if pse && f.method.kind != "constant" {
        err(
            errs,
            &format!("{field}.comparison"),
            format!("condition `{}` compares two stimuli (a PSE design), and adaptive methods converge on a proportion correct", c.name),
            "use kind = \"constant\" with deltas on both sides of the expected PSE",
        );
    }
}

/// The `[[block]]` tables (default: one block of the `n_conditions` valid conditions).
fn blocks_from(f: &StudyFile, n_conditions: usize, errs: &mut Vec<SceneError>) -> Vec<Block> {
    let mut blocks = Vec::new();
    if f.blocks.is_empty() {
        blocks.push(Block {
            conditions: (0..n_conditions).collect(),
            practice: 0,
        });
    }
    let mut used = vec![false; f.conditions.len()];
    for (i, b) in f.blocks.iter().enumerate() {
        blocks.push(block_from(f, i, b, &mut used, errs));
    }
    if !f.blocks.is_empty() {
        for (k, u) in used.iter().enumerate() {
            if !u {
                err(
                    errs,
                    "block",
                    format!("condition `{}` is in no block", f.conditions[k].name),
                    "add it to a block's conditions, or remove it",
                );
            }
        }
    }
    blocks
}

/// `[[block]]` number `i`; `used` marks the conditions of this and earlier blocks.
fn block_from(
    f: &StudyFile,
    i: usize,
    b: &BlockSection,
    used: &mut [bool],
    errs: &mut Vec<SceneError>,
) -> Block {
    let field = format!("block[{i}]");
    let mut idx = Vec::new();
    if b.conditions.is_empty() {
        err(
            errs,
            &format!("{field}.conditions"),
            "lists no condition",
            "list the condition names this block runs",
        );
    }
    for name in &b.conditions {
        match f.conditions.iter().position(|c| &c.name == name) {
            Some(k) if used[k] => err(
                errs,
                &format!("{field}.conditions"),
                format!("condition `{name}` is already in an earlier block"),
                "put each condition in one block",
            ),
            Some(k) => {
                used[k] = true;
                idx.push(k);
            }
            None => err(
                errs,
                &format!("{field}.conditions"),
                format!("no condition called `{name}`"),
                "use the names of the [[condition]] tables",
            ),
        }
    }
    let practice = b.practice.unwrap_or(0);
    if practice > 1000 {
        err(
            errs,
            &format!("{field}.practice"),
            format!("{practice} practice trials"),
            "use at most 1000",
        );
    }
    Block {
        conditions: idx,
        practice,
    }
}

/// Every stimulus a condition can present must build a valid scene with the probe in it (checked
/// even when other fields have problems, so all are reported at once). `None`: the scene has no
/// probe (reported).
fn check_worlds(study: &Study, errs: &mut Vec<SceneError>) -> Option<()> {
    for (ci, c) in study.conditions.iter().enumerate() {
        let largest = study.largest_delta(ci);
        let smallest = study.smallest_delta(ci);
        let mut cases = vec![(&c.reference, None), (&c.comparison, Some(largest))];
        if c.pse && smallest < 0.0 {
            cases.push((&c.comparison, Some(smallest)));
        }
        for (which, delta) in cases {
            if delta.is_some_and(|d| !d.is_finite() || (d <= 0.0 && !c.pse)) {
                continue; // the method's own error is reported
            }
            let vary = delta.map(|d| (&c.vary, d));
            match stimulus::world(study, which, vary) {
                Ok(w) => {
                    if w.body_index(&study.probe).is_none() {
                        err(
                            errs,
                            "probe",
                            format!("the scene has no body called `{}`", study.probe),
                            "name a dynamic body of the scene",
                        );
                        return None;
                    }
                }
                Err(e) => {
                    for mut s in e {
                        s.field = format!("stimuli.{which}.{}", s.field);
                        if delta.is_some() {
                            s.message = format!(
                                "{} (comparison at delta {})",
                                s.message,
                                delta.unwrap_or(largest)
                            );
                        }
                        // The same stimulus as reference and comparison: report it once.
                        if !errs.iter().any(|e| e.field == s.field) {
                            errs.push(s);
                        }
                    }
                }
            }
        }
    }
    Some(())
}
