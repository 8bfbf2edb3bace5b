//! Perceptual studies (issue 40): study files, the trial schedule (method of constant stimuli,
//! interleaved transformed up/down staircases, QUEST), 2AFC, 3AFC and same–different tasks,
//! discrimination and PSE designs, a simulated observer that explores the wall through the real
//! world step (pressing, tapping or stroking) and answers (a **model**, never data), sessions
//! written as per-trial TSV that resume without losing or repeating a trial, and the analysis.
//!
//! - [`file`](mod@file): the study file (TOML) and its validation → [`Study`].
//! - [`stimulus`]: a named parameter set applied to the scene → a [`World`](haptic2d::world::World).
//! - [`method`], [`staircase`], [`quest`], [`schedule`]: what is presented when.
//! - [`observer`], [`explore`]: the [`Observer`] trait, the [`SimulatedObserver`] model and the
//!   simulated hand's explorations.
//! - [`trials`], [`session`]: the data on disk, running and resuming a session.
//! - [`fit`], [`same_different`], [`analyse`]: psychometric and signal-detection fits, bootstrap
//!   intervals, reports and plots.
//! - [`numeric`], [`rng`]: the normal CDF, Nelder–Mead and a seeded generator.
//!
//! Trials on the real-time loop with answers from the browser page are the CLI's
//! (`haptic2d study run --observer browser`, an [`Observer`] in `haptic2d-cli/src/study_browser.rs`).
//! Not built yet: device buttons, MCAP per trial, QUEST+, magnitude estimation, PsychoPy (see
//! `docs/STUDIES.md`).

pub mod analyse;
pub mod explore;
pub mod file;
pub mod fit;
pub mod magnitude;
pub mod method;
pub mod numeric;
pub mod observer;
pub mod order;
pub mod quest;
pub mod quest_plus;
pub mod rng;
pub mod same_different;
pub mod schedule;
pub mod session;
pub mod staircase;
pub mod stimulus;
pub mod trials;

pub use analyse::{analyse_dir, AnalyseOptions, ConditionResult};
pub use file::Study;
pub use observer::{Observer, ObserverParams, SimulatedObserver};
pub use session::{run, session_dir, session_seed, RunSummary};
