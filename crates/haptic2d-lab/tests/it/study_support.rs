//! Helpers shared by the study modules: a study file of `studies/` with its text, a session run by
//! the simulated observer, and the analysis of a folder of sessions.

use haptic2d_lab::study::analyse::{analyse_dir, AnalyseOptions, ConditionResult};
use haptic2d_lab::study::{run, session_seed, RunSummary, SimulatedObserver, Study};
use std::path::{Path, PathBuf};

/// The path of the study file `name` in `studies/`.
pub fn study_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../studies")
        .join(name)
}

/// The study file `name` of `studies/`, parsed, and its text.
pub fn load(name: &str) -> (Study, String) {
    let p = study_file(name);
    (
        Study::load(&p).unwrap(),
        std::fs::read_to_string(&p).unwrap(),
    )
}

/// Session 1 of participant `id`, run into `out` by the simulated observer seeded as `study run`
/// seeds it.
pub fn run_one(study: &Study, text: &str, out: &Path, id: &str) -> RunSummary {
    let mut obs = SimulatedObserver::new(study.observer, session_seed(study.seed, id, 1));
    run(study, text, out, id, 1, &mut obs, &mut |_, _| {}, None).unwrap()
}

/// The analysis of the sessions under `dir` with `bootstrap` resamples per interval.
pub fn analyse(dir: &Path, bootstrap: u32) -> Vec<ConditionResult> {
    analyse_dir(
        dir,
        &AnalyseOptions {
            bootstrap,
            ..Default::default()
        },
    )
    .unwrap()
    .0
}
