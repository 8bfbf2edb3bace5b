//! `haptic2d study`: perceptual studies (docs/STUDIES.md). `study run FILE --observer simulated`
//! runs (or resumes) a session headless on the simulated observer; `--observer browser` runs it on
//! the real-time haptic loop with answers from the browser page (`study_browser.rs`); `study serve
//! FILE` presents stimuli on that loop to a local client (`study_serve.rs`); `study analyse DIR` fits the
//! psychometric functions and draws them; `study check FILE` validates a study file.

use crate::exit::{Failure, Status};
use crate::study_browser::BrowserOptions;
use crate::study_serve::ServeOptions;
use haptic2d_lab::study::analyse::{analyse_dir, AnalyseOptions};
use haptic2d_lab::study::fit::Shape;
use haptic2d_lab::study::method::Method;
use haptic2d_lab::study::{run as run_session, session_seed, SimulatedObserver, Study};
use std::path::{Path, PathBuf};

/// `haptic2d study` subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum StudyCmd {
    /// Run (or resume) one session of a study: writes OUT/sub-ID/ses-N/ with trials.tsv, the study
    /// file and session.json. An existing session resumes after its last recorded trial.
    Run {
        /// The study file (TOML, docs/STUDIES.md), e.g. studies/stiffness-walls.toml.
        file: PathBuf,
        /// Who answers: `simulated` (the simulated observer, a model, parameters in the file's
        /// [observer]) or `browser` (a participant on the real-time haptic loop, answering on the
        /// browser page: open the URL printed at startup). Device buttons are not built yet.
        #[arg(long, default_value = "simulated")]
        observer: String,
        /// With --observer browser: the device, as `haptic2d run --device` (sim, haply:…, udp:…,
        /// inverse3[:URL]).
        #[arg(long, default_value = "sim")]
        device: String,
        /// With --observer browser: the device file, as `haptic2d run --device-file`.
        #[arg(long, value_name = "FILE.toml")]
        device_file: Option<PathBuf>,
        /// With --observer browser: address of the page.
        #[arg(long, default_value = "127.0.0.1:8080")]
        bind: String,
        /// With --observer browser: exploration time per interval (s of loop time; paused time
        /// does not count).
        #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
        interval: f64,
        /// With --observer browser: normal scheduling instead of real-time.
        #[arg(long)]
        no_rt: bool,
        /// With --observer browser: the page's commands need the token on loopback too.
        #[arg(long)]
        require_token: bool,
        /// With --observer browser: drive a real device even if `haptic2d stability` finds it
        /// unstable with the hand released.
        #[arg(long)]
        allow_unstable: bool,
        /// With --observer browser: let --device udp:ADDR:PORT be beyond loopback.
        #[arg(long)]
        allow_remote_device: bool,
        /// Output folder (one sub-ID/ses-N directory per participant and session inside).
        #[arg(long, default_value = "study-data")]
        out: PathBuf,
        /// Pseudonymous participant ID (letters, digits, '-'; never a name).
        #[arg(long, default_value = "sim01")]
        participant: String,
        /// Session number.
        #[arg(long, default_value_t = 1)]
        session: u32,
        /// Stop after this many new trials (the session resumes on the next run).
        #[arg(long)]
        stop_after: Option<u32>,
    },
    /// Serve the study's stimuli on the real-time haptic loop to one local client (a Python or
    /// PsychoPy script: `haptic2d.StudyServer`), JSON lines over TCP on loopback: `present`
    /// {condition, delta, duration_s}, `end`, `status`, `stop` (docs/STUDIES.md, "Driving trials
    /// from Python or PsychoPy on the device"). The client keeps the trials and the answers.
    Serve {
        /// The study file (its scene, probe and stimuli; its method and [observer] are unused).
        file: PathBuf,
        /// The device, as `haptic2d run --device` (sim, haply:…, udp:…, inverse3[:URL]).
        #[arg(long, default_value = "sim")]
        device: String,
        /// The device file, as `haptic2d run --device-file`.
        #[arg(long, value_name = "FILE.toml")]
        device_file: Option<PathBuf>,
        /// The simulated device's hand, as `haptic2d run --hand` (follow, free, constant:…,
        /// sine:…, script:…); refused for a real device.
        #[arg(long)]
        hand: Option<String>,
        /// The clients' address: loopback only (the server has no key), port 0 picks a free one
        /// (printed as `study server: listening on ADDRESS`).
        #[arg(long, default_value = "127.0.0.1:7341")]
        listen: String,
        /// Address of the display page.
        #[arg(long, default_value = "127.0.0.1:8080")]
        bind: String,
        /// No display page.
        #[arg(long)]
        headless: bool,
        /// Write one MCAP log per presentation into OUT/trials/trial-NNNN.mcap (NNNN = the
        /// presentation's id).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Normal scheduling instead of real-time.
        #[arg(long)]
        no_rt: bool,
        /// The page's commands need the token on loopback too.
        #[arg(long)]
        require_token: bool,
        /// Drive a real device even if `haptic2d stability` finds it unstable with the hand
        /// released.
        #[arg(long)]
        allow_unstable: bool,
        /// Let --device udp:ADDR:PORT be beyond loopback.
        #[arg(long)]
        allow_remote_device: bool,
    },
    /// Fit psychometric functions per condition (maximum likelihood, guess rate 0.5, fitted lapse
    /// rate, parametric-bootstrap 95 % intervals), report JNDs and Weber fractions, and write
    /// analysis.tsv and psychometric.svg/.png into DIR.
    Analyse {
        /// A session directory (OUT/sub-ID/ses-N) or the --out folder of `study run` (its sessions
        /// are pooled per condition).
        dir: PathBuf,
        /// Psychometric function: weibull or normal (cumulative normal).
        #[arg(long, default_value = "weibull")]
        shape: String,
        /// Bootstrap repetitions.
        #[arg(long, default_value_t = 500)]
        bootstrap: u32,
        /// Seed of the bootstrap.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Validate a study file and explain every problem found.
    Check {
        /// The study file.
        file: PathBuf,
    },
}

/// Runs a `study` subcommand.
pub fn run(cmd: &StudyCmd) -> Result<Status, Failure> {
    match cmd {
        StudyCmd::Run {
            file,
            observer,
            out,
            participant,
            session,
            stop_after,
            device,
            device_file,
            bind,
            interval,
            no_rt,
            require_token,
            allow_unstable,
            allow_remote_device,
        } if observer == "browser" => crate::study_browser::run(
            file,
            out,
            participant,
            *session,
            *stop_after,
            &BrowserOptions {
                device: device.clone(),
                device_file: device_file.clone(),
                bind: bind.clone(),
                interval_s: *interval,
                no_rt: *no_rt,
                require_token: *require_token,
                allow_unstable: *allow_unstable,
                allow_remote_device: *allow_remote_device,
            },
        ),
        StudyCmd::Run {
            file,
            observer,
            out,
            participant,
            session,
            stop_after,
            ..
        } => study_run(file, observer, out, participant, *session, *stop_after),
        StudyCmd::Serve {
            file,
            device,
            device_file,
            hand,
            listen,
            bind,
            headless,
            out,
            no_rt,
            require_token,
            allow_unstable,
            allow_remote_device,
        } => crate::study_serve::run(
            file,
            &ServeOptions {
                rig: BrowserOptions {
                    device: device.clone(),
                    device_file: device_file.clone(),
                    bind: bind.clone(),
                    interval_s: 0.0,
                    no_rt: *no_rt,
                    require_token: *require_token,
                    allow_unstable: *allow_unstable,
                    allow_remote_device: *allow_remote_device,
                },
                hand: hand.clone(),
                listen: listen.clone(),
                out: out.clone(),
                headless: *headless,
            },
        ),
        StudyCmd::Analyse {
            dir,
            shape,
            bootstrap,
            seed,
        } => analyse(dir, shape, *bootstrap, *seed),
        StudyCmd::Check { file } => {
            let study = load(file)?;
            println!(
                "{}: ok: study `{}`, scene {}, {} condition(s), {} block(s), {}",
                file.display(),
                study.name,
                study.scene_source,
                study.conditions.len(),
                study.blocks.len(),
                describe_method(&study)
            );
            Ok(Status::Clean)
        }
    }
}

fn describe_method(study: &Study) -> String {
    match &study.method {
        Method::Constant { repeats, .. } => {
            let mut n: Vec<usize> = (0..study.conditions.len())
                .map(|c| study.deltas(c).len())
                .collect();
            n.dedup();
            let n: Vec<String> = n.iter().map(|k| k.to_string()).collect();
            format!(
                "constant stimuli: {} deltas × {repeats} repeats per condition",
                n.join("/")
            )
        }
        Method::Quest(q) => format!(
            "QUEST (Bayesian placement at the posterior {}, prior {} ± {} log10, Weibull β = {}, lapse {}), {} trials per condition",
            if q.place_at_mode { "mode" } else { "mean" },
            q.start,
            q.prior_sd,
            q.beta,
            q.lapse,
            q.max_trials
        ),
        Method::QuestPlus(q) => format!(
            "QUEST+ (placement by least expected entropy over threshold and slope, prior {} ± {} log10, slopes {:?}, lapse {}), {} trials per condition",
            q.start, q.prior_sd, q.slopes, q.lapse, q.max_trials
        ),
        Method::Staircase(s) => format!(
            "{} interleaved {} staircase(s) per condition (target {:.1} % correct), stop at {} trials or {} reversals",
            s.starts.len(),
            s.rule_name(),
            100.0 * s.target(),
            s.max_trials,
            s.max_reversals
        ),
    }
}

fn load(file: &Path) -> Result<Study, Failure> {
    Study::load(file).map_err(Failure::from)
}

fn study_run(
    file: &Path,
    observer: &str,
    out: &Path,
    participant: &str,
    session: u32,
    stop_after: Option<u32>,
) -> Result<Status, Failure> {
    if observer != "simulated" {
        return Err(Failure::from(format!(
            "--observer {observer}: unknown observer\n    fix: --observer simulated (the simulated observer, a model) or --observer browser (a participant on the browser page); device buttons are not built yet"
        )));
    }
    let (study, text) = Study::read(file).map_err(Failure::from)?;
    let seed = session_seed(study.seed, participant, session);
    let mut obs = SimulatedObserver::new(study.observer, seed);
    eprintln!(
        "study `{}`: participant {participant}, session {session}, {}; answered by the simulated observer (a model, not data: W = {}, λ = {})",
        study.name,
        describe_method(&study),
        study.observer.weber_fraction,
        study.observer.lapse_rate
    );
    let mut last_pct = u32::MAX;
    let mut progress = |done: u32, planned: u32| {
        let pct = (100 * done) / planned.max(1);
        if pct / 10 != last_pct / 10 || done == planned {
            last_pct = pct;
            eprintln!("  trial {done} of at most {planned} ({pct} %)");
        }
    };
    let s = run_session(
        &study,
        &text,
        out,
        participant,
        session,
        &mut obs,
        &mut progress,
        stop_after,
    )
    .map_err(Failure::error)?;
    print!("{}", s.report("run the same command again to resume"));
    Ok(Status::Clean)
}

fn analyse(dir: &Path, shape: &str, bootstrap: u32, seed: u64) -> Result<Status, Failure> {
    let shape = Shape::from_name(shape).map_err(|e| Failure::from(format!("--shape: {e}")))?;
    if !(10..=100_000).contains(&bootstrap) {
        return Err(Failure::from(format!(
            "--bootstrap {bootstrap}: give 10 to 100000 repetitions"
        )));
    }
    let opts = AnalyseOptions {
        shape,
        bootstrap,
        seed,
        ..Default::default()
    };
    let (res, paths) = analyse_dir(dir, &opts).map_err(Failure::from)?;
    for r in &res {
        print!("{}", haptic2d_lab::study::analyse::report(r, bootstrap));
    }
    for p in paths {
        println!("wrote {}", p.display());
    }
    Ok(Status::Clean)
}
