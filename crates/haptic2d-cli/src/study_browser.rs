//! `haptic2d study run FILE --observer browser`: a study session on the real-time haptic loop, the
//! participant answering on the browser page (docs/STUDIES.md, "A session with people").
//!
//! The main thread runs the session exactly as the simulated observer's path does
//! ([`haptic2d_lab::study::run`]: the schedule, `trials.tsv` appended and synced per answer, resume
//! from the log); its observer, [`BrowserObserver`], builds each trial's stimuli (the laws of every
//! interval, allocated here, never in a tick), hands the [`Plan`] to the loop through a wait-free
//! ring and waits for the answer. The loop thread runs the haptic tick of `haptic2d run` (device,
//! system, watchdog, display) with the [`Presenter`] in it: stimulus switches in free space, the
//! intervals, the answer and its response time (see `study_present.rs`).
//!
//! A SIGINT or SIGTERM, the page's stop button, a lost device or a safety stop end the loop (torques
//! zeroed and latched as in `haptic2d run`); the trial in progress is not written, so running the
//! same command again resumes at it.
//!
//! The rig ([`build_rig`]), the loop's settings, the haptic step ([`haptic_step`]), the stimulus
//! laws ([`stimulus_laws`]) and the end reasons ([`loop_end_status`]) are shared with `haptic2d
//! study serve` (`study_serve.rs`), which presents stimuli on the same loop to a Python client.

use crate::device_arg;
use crate::exit::{Failure, Status};
use crate::hand_arg::HandSpec;
use crate::loop_end::LoopEnd;
use crate::run_rig::{DeviceChoice, RealOpenError, Rig};
use crate::run_view::{self, LiveView, LoadedScene};
use crate::study_mcap::{self, TrialLogger, TrialTap};
use crate::study_present::{Event, Plan, Presenter, MAX_INTERVALS};
use haptic2d::haptic::HapticConfig;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NormalModel;
use haptic2d::scene::Scene;
use haptic2d_lab::study::observer::{Answer, Observer};
use haptic2d_lab::study::schedule::{Schedule, TrialSpec};
use haptic2d_lab::study::session::session_dir;
use haptic2d_lab::study::{run as run_session, session_seed, stimulus, Study};
use haptic2d_rt::clock::now_ns;
use haptic2d_rt::signal::install_stop_signals;
use haptic2d_rt::{run_loop, LoopConfig, TickControl, TickInfo, TimingSummary, Watchdog};
use std::collections::HashMap;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Shortest and longest interval (s).
pub const INTERVAL_RANGE_S: (f64, f64) = (0.05, 600.0);

/// The options of the browser session.
#[derive(Clone, Debug)]
pub struct BrowserOptions {
    /// `--device` (as `haptic2d run`).
    pub device: String,
    /// `--device-file`.
    pub device_file: Option<PathBuf>,
    /// `--bind` of the page.
    pub bind: String,
    /// `--interval`: exploration time per interval (s).
    pub interval_s: f64,
    /// `--no-rt`: normal scheduling.
    pub no_rt: bool,
    /// `--require-token`.
    pub require_token: bool,
    /// `--allow-unstable`.
    pub allow_unstable: bool,
    /// `--allow-remote-device`.
    pub allow_remote_device: bool,
}

/// Why the session ended early (from the observer's side).
#[derive(Clone, Copy, Debug, PartialEq)]
enum EarlyEnd {
    /// The page's stop button.
    Page,
    /// The loop ended (a signal, or the tick stopped it).
    Loop,
}

/// Runs (or resumes) the session with answers from the browser page.
pub fn run(
    file: &Path,
    out: &Path,
    participant: &str,
    session: u32,
    stop_after: Option<u32>,
    o: &BrowserOptions,
) -> Result<Status, Failure> {
    let bind = check_options(o)?;
    haptic2d_lab::study::session::check_participant(participant)?;
    let (study, text) = Study::read(file).map_err(Failure::from)?;
    let (mut rig, loaded, rate) = build_rig(&study, o, HandSpec::Follow)?;
    let seed = session_seed(study.seed, participant, session);
    let planned = Schedule::new(&study, seed).planned();

    let (server, mut view) = run_view::start(bind, &rig, loaded, rate, o.require_token)?;
    view.enable_study();
    crate::outln!("{}", server.banner());
    let stop = install_stop_signals()?;
    let watchdog = Watchdog::new(rig.watchdog_config())?;
    let loop_config = study_loop_config(rate, o.no_rt)?;
    let (tap, trial_log) =
        start_trial_log(&study, &text, &rig, out, participant, session, o, rate)?;
    let (plan_tx, plan_rx) = rtrb::RingBuffer::<Plan>::new(2);
    let (event_tx, event_rx) = rtrb::RingBuffer::<Event>::new(16);
    eprintln!(
        "study `{}`: participant {participant}, session {session}, {} trial(s) planned; device {}, {} Hz, {} s per interval; answers from the page (Ctrl-C or the page's Stop ends the session; it resumes)",
        study.name,
        planned,
        rig.io.name(),
        rate,
        o.interval_s
    );

    let ended = AtomicBool::new(false);
    let mut state = StudyLoop {
        rig: &mut rig,
        view,
        watchdog,
        presenter: Presenter::new(study.task, o.interval_s).with_modulus(study.modulus),
        plans: plan_rx,
        events: event_tx,
        tap,
        end: None,
    };
    let mut observer = BrowserObserver {
        plans: plan_tx,
        events: event_rx,
        ended: &ended,
        planned,
        laws: HashMap::new(),
        rest_next: false,
        early: None,
    };
    let beside = beside_the_loop(
        &loop_config,
        &stop,
        &ended,
        |i| state.tick(&i),
        || {
            let mut progress = |done: u32, planned: u32| {
                eprintln!("  trial {done} of at most {planned} answered");
            };
            run_session(
                &study,
                &text,
                out,
                participant,
                session,
                &mut observer,
                &mut progress,
                stop_after,
            )
        },
    );
    let (session_result, timing) = beside.unwrap_or_else(|e| (Err(e), None));
    // Zero torques before anything else.
    state.rig.io.zero_torques();
    let end = state.end.take();
    drop(state);
    server.shutdown();
    report_trials_and_timing(
        Some(trial_log),
        timing.as_ref().and_then(|t| t.as_ref().ok()),
    );
    if let Some(trip) = rig.system.safety_trip() {
        crate::outln!("{trip}");
    }
    finish(end, observer.early, session_result)
}

/// Runs the study's loop (`tick` at each deadline of `config`) on its own thread, `ended` set when
/// it ends, while `session` runs on this one; when the session is over (complete, stopped or
/// failed), sets `stop` and joins the loop. Returns the session's result and the loop's timing
/// (`None` if the loop's thread panicked), or why the loop's thread could not start.
#[allow(clippy::type_complexity)]
pub(crate) fn beside_the_loop<R>(
    config: &LoopConfig,
    stop: &AtomicBool,
    ended: &AtomicBool,
    tick: impl FnMut(TickInfo) -> TickControl + Send,
    session: impl FnOnce() -> R,
) -> Result<(R, Option<Result<TimingSummary, String>>), String> {
    std::thread::scope(|s| {
        let handle = std::thread::Builder::new()
            .name("haptic2d-rt".into())
            .spawn_scoped(s, || {
                let r = run_loop(config, stop, tick);
                ended.store(true, Ordering::SeqCst);
                r
            })
            .map_err(|e| format!("cannot start the real-time loop thread: {e}"))?;
        let r = session();
        stop.store(true, Ordering::SeqCst);
        Ok((r, handle.join().ok()))
    })
}

/// Prints, once a study's loop has stopped, what its trial logger wrote (a failure as a warning:
/// the answers are in `trials.tsv` all the same) and how many of the loop's deadlines it met.
pub(crate) fn report_trials_and_timing(log: Option<TrialLogger>, timing: Option<&TimingSummary>) {
    if let Some(l) = log {
        match l.finish() {
            Ok(r) => crate::outln!("{r}"),
            Err(e) => crate::outln!("warning: {e}"),
        }
    }
    if let Some(t) = timing {
        crate::outln!(
            "on time: {:.3} % of {} deadlines ({} overruns)",
            t.on_time_fraction * 100.0,
            t.deadlines,
            t.overruns
        );
    }
}

/// Checks the options that need no file: `--interval` and `--bind`.
fn check_options(o: &BrowserOptions) -> Result<SocketAddr, Failure> {
    let (lo, hi) = INTERVAL_RANGE_S;
    if !(o.interval_s.is_finite() && (lo..=hi).contains(&o.interval_s)) {
        return Err(format!(
            "--interval {}: give the exploration time per interval in seconds, {lo} to {hi}\n    fix: e.g. --interval 3",
            o.interval_s
        )
        .into());
    }
    o.bind.parse::<SocketAddr>().map_err(|e| {
        Failure::from(format!(
            "--bind `{}` is not an ADDRESS:PORT ({e})\n    fix: e.g. --bind 127.0.0.1:8080",
            o.bind
        ))
    })
}

/// The loop of a study on the device (the browser study, the study server): `rate` Hz, no end of
/// its own, real-time scheduling unless `no_rt`.
pub(crate) fn study_loop_config(rate: f64, no_rt: bool) -> Result<LoopConfig, Failure> {
    let loop_config = LoopConfig {
        rate_hz: rate,
        duration: None,
        rt: !no_rt,
        spin_us: (0.4e6 / rate).min(400.0),
        ..LoopConfig::default()
    };
    loop_config.validate()?;
    Ok(loop_config)
}

/// Builds the rig (device, system, the study's first reference stimulus in the world) as `haptic2d
/// run` does, gated by the released-stability check for a real device; `hand` drives the simulated
/// device (the browser study's is `follow`). Returns the rig, the scene for the display and the
/// loop rate (Hz).
pub(crate) fn build_rig(
    study: &Study,
    o: &BrowserOptions,
    hand: HandSpec,
) -> Result<(Rig, LoadedScene, f64), Failure> {
    let first = &study.conditions[0].reference;
    let scene_text = stimulus::scene_text(study, first, None).map_err(scene_errors)?;
    let scene = Scene::from_toml(&scene_text, &study.scene_source, study.rate)
        .map_err(|e| scene_errors(e.errors))?;
    let dt = scene.world.params.dt;
    let rate = 1.0 / dt;
    let device = DeviceChoice::parse(&o.device)?;
    if matches!(device, DeviceChoice::Replay(_)) {
        return Err("--device replay:… plays recorded motion: nobody explores a stimulus\n    fix: --device sim or a real device".into());
    }
    let real = device.load_real(o.device_file.as_deref(), o.allow_remote_device)?;
    let device_params = match &real {
        Some(r) => r.model.twin_params(),
        None => device_arg::resolve(o.device_file.as_deref(), &scene, dt)?.params,
    };
    let mut config = HapticConfig {
        device: device_params,
        ..HapticConfig::default()
    };
    if let Some(m) = real.as_ref().and_then(|r| r.match_controller.as_ref()) {
        config.controller = m(config.controller);
    }
    if let (Some(r), false) = (&real, o.allow_unstable) {
        crate::cmd_stability::check_real_device(&r.model, &config, &scene.world)?;
    }
    let loaded = LoadedScene {
        name: study.name.clone(),
        description: study.description.clone(),
        world: scene.world.clone(),
    };
    let mut rig = match real {
        None => Rig::new(scene.world, &scene.source, config, device, hand)?,
        Some(r) => {
            Rig::with_real(scene.world, &scene.source, config, device, r).map_err(|e| match e {
                RealOpenError::Config(m) => Failure::from(m),
                RealOpenError::Open(m) => Failure {
                    status: Status::DeviceLost,
                    message: m,
                },
            })?
        }
    };
    if !o.allow_unstable {
        rig.enforce_released_stability();
    }
    let slave = rig.system.slave();
    if rig.system.world().body_index(&study.probe) != Some(slave) {
        return Err(format!(
            "the study's probe `{}` is not the body the handle drives (`{}`)\n    fix: set probe to the scene's driven body",
            study.probe,
            rig.system.world().bodies[slave].name
        )
        .into());
    }
    Ok((rig, loaded, rate))
}

/// Starts the per-trial MCAP logs (`study_mcap.rs`) in the session's directory.
#[allow(clippy::too_many_arguments)]
fn start_trial_log(
    study: &Study,
    text: &str,
    rig: &Rig,
    out: &Path,
    participant: &str,
    session: u32,
    o: &BrowserOptions,
    rate: f64,
) -> Result<(TrialTap, TrialLogger), Failure> {
    let scene = crate::run_log::scene_strings(
        &study.scene_source,
        &study.name,
        o.device_file.as_deref(),
        &[
            ("rate_hz", rate.to_string()),
            ("command", "study run --observer browser".into()),
            ("device", o.device.clone()),
            ("study_toml", text.to_string()),
            ("participant", participant.to_string()),
            ("session", session.to_string()),
        ],
    );
    let dir = session_dir(out, participant, session);
    Ok(study_mcap::start(&dir, rig.system.world(), scene, rate)?)
}

/// The exit status of a study loop the tick stopped, and why (for the terminal).
pub(crate) fn loop_end_status(end: LoopEnd) -> (Status, String) {
    match end {
        LoopEnd::DeviceLost(m) => (
            Status::DeviceLost,
            format!("{m}\n    torques were set to zero and latched"),
        ),
        // A study refuses a replay, so its data cannot end; were it to, the device is gone.
        LoopEnd::ReplayEnded => (
            Status::DeviceLost,
            "the device's data ended\n    torques were set to zero and latched".into(),
        ),
        LoopEnd::Watchdog(m) => (Status::SafetyStop, m),
        LoopEnd::SafetyLatch => (Status::SafetyStop, "safety stop".into()),
        LoopEnd::WorldDiverged(m) => (Status::Diverged, m),
    }
}

/// Reports how the session ended and returns the exit status.
fn finish(
    end: Option<LoopEnd>,
    early: Option<EarlyEnd>,
    session_result: Result<haptic2d_lab::study::RunSummary, String>,
) -> Result<Status, Failure> {
    let resume_hint = "run the same command again to resume at the next unanswered trial";
    let (status, why) = match (end, early) {
        (Some(end), _) => loop_end_status(end),
        (None, Some(EarlyEnd::Page)) => (Status::Clean, "stopped from the page".into()),
        (None, Some(EarlyEnd::Loop)) => (
            Status::Interrupted,
            "interrupted by a signal (SIGINT or SIGTERM)".into(),
        ),
        (None, None) => match session_result {
            Ok(s) => {
                crate::outln!("{}", s.report(resume_hint).trim_end());
                return Ok(Status::Clean);
            }
            Err(e) => return Err(Failure::error(e)),
        },
    };
    crate::outln!("stopped: {why}; the trials answered are in trials.tsv; {resume_hint}");
    Ok(status)
}

fn scene_errors(e: Vec<haptic2d::scene::SceneError>) -> Failure {
    Failure::from(
        e.iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join("\n"),
    )
}

/// The observer whose answers come from the page through the loop.
struct BrowserObserver<'a> {
    plans: rtrb::Producer<Plan>,
    events: rtrb::Consumer<Event>,
    ended: &'a AtomicBool,
    planned: u32,
    /// The laws of a stimulus: (condition, comparison, delta bits) → (normal, friction).
    laws: HashMap<(usize, bool, u64), (NormalModel, FrictionModel)>,
    /// The next trial starts with a rest break (`Observer::rest` was called).
    rest_next: bool,
    early: Option<EarlyEnd>,
}

impl BrowserObserver<'_> {
    fn stimulus(
        &mut self,
        study: &Study,
        c: usize,
        comparison: bool,
        delta: f64,
    ) -> Result<(NormalModel, FrictionModel), String> {
        let key = (c, comparison, if comparison { delta.to_bits() } else { 0 });
        if let Some(l) = self.laws.get(&key) {
            return Ok(*l);
        }
        let l = stimulus_laws(study, c, comparison, delta)?;
        self.laws.insert(key, l);
        Ok(l)
    }
}

/// The wall law and friction model of condition `c`'s reference, or of its comparison with the
/// varied parameter raised by `delta` (its unit), built from the study's scene (allocates: call
/// it off the loop thread). The error names the problem (an invalid parameter value).
pub(crate) fn stimulus_laws(
    study: &Study,
    c: usize,
    comparison: bool,
    delta: f64,
) -> Result<(NormalModel, FrictionModel), String> {
    let w = stimulus::interval_world(study, c, comparison, delta)?;
    Ok((w.normal, w.friction))
}

impl Observer for BrowserObserver<'_> {
    fn answer(&mut self, study: &Study, spec: &TrialSpec) -> Result<Answer, String> {
        let n = study.task.intervals();
        let reference = self.stimulus(study, spec.condition, false, 0.0)?;
        let comparison = self.stimulus(study, spec.condition, true, spec.delta)?;
        let mut laws = [reference; MAX_INTERVALS];
        for (i, l) in laws.iter_mut().enumerate().take(n) {
            if usize::from(spec.comparison_interval) == i + 1 {
                *l = comparison;
            }
        }
        let plan = Plan {
            trial: spec.trial,
            done: spec.trial - 1,
            planned: self.planned,
            intervals: n as u8,
            laws,
            rest: std::mem::take(&mut self.rest_next),
        };
        self.plans
            .push(plan)
            .map_err(|_| "the loop is not taking trials".to_string())?;
        loop {
            while let Ok(ev) = self.events.pop() {
                match ev {
                    Event::Answered {
                        trial,
                        choice,
                        rt_s,
                        magnitude,
                    } if trial == spec.trial => {
                        return Ok(Answer {
                            response: choice,
                            rt: rt_s,
                            magnitude,
                        })
                    }
                    Event::Answered { .. } => {}
                    Event::Stop => {
                        self.early = Some(EarlyEnd::Page);
                        return Err("the session was stopped from the page".into());
                    }
                }
            }
            if self.ended.load(Ordering::SeqCst) {
                self.early = Some(EarlyEnd::Loop);
                return Err("the haptic loop stopped".into());
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn describe(&self) -> String {
        "browser (a participant answering on the page)".into()
    }

    /// The break is shown by the loop when the next trial's plan arrives (`Plan::rest`).
    fn rest(&mut self, _study: &Study, _next: &TrialSpec) -> Result<(), String> {
        self.rest_next = true;
        Ok(())
    }
}

/// True when the tick holds the world with zero force: the page's pause, or a rest break (the
/// torques then ramp in from zero, as after a pause).
fn held(paused: bool, presenter: &Presenter) -> bool {
    paused || presenter.on_break()
}

/// Everything one tick touches, owned by the loop thread while it runs.
struct StudyLoop<'r> {
    rig: &'r mut Rig,
    view: LiveView,
    watchdog: Watchdog,
    presenter: Presenter,
    plans: rtrb::Consumer<Plan>,
    events: rtrb::Producer<Event>,
    /// The open trial's ticks and the trial marks, for the per-trial MCAP logs.
    tap: TrialTap,
    end: Option<LoopEnd>,
}

impl StudyLoop<'_> {
    /// One tick: the page's commands, the presenter (stimulus switch, interval, answer), then the
    /// haptic tick of `haptic2d run` (device read, system, watchdog, device write) and the display.
    /// Allocation-free in steady state.
    fn tick(&mut self, info: &TickInfo) -> TickControl {
        self.view.apply_commands(self.rig);
        let inbox = self.view.take_study();
        let paused = self.view.paused();
        if let Ok(plan) = self.plans.pop() {
            self.presenter.start(plan);
        }
        let slave = self.rig.system.slave();
        let watched = self.view.viewers() > 0;
        self.presenter.set_buttons(self.rig.io.buttons());
        if let Some(ev) = self.presenter.tick(
            self.rig.system.world_mut(),
            slave,
            info.period_s,
            paused,
            watched,
            now_ns(),
            inbox,
        ) {
            if let Event::Answered {
                trial,
                choice,
                rt_s,
                ..
            } = ev
            {
                self.tap.end(trial, choice, rt_s);
            }
            // The ring holds 16 events and the main thread drains it every 2 ms.
            let _ = self.events.push(ev);
        }
        if let Some(trial) = self.presenter.take_started() {
            self.tap.start(trial);
        }
        let paused = held(paused, &self.presenter);
        if let Err(end) = haptic_step(
            self.rig,
            &mut self.watchdog,
            Some(&mut self.tap),
            info,
            paused,
        ) {
            self.end = Some(end);
            return TickControl::Stop;
        }
        self.view.set_study_view(Some(self.presenter.view()));
        self.view.after_tick(info, self.rig);
        TickControl::Continue
    }
}

/// The haptic tick of `haptic2d run` inside a study loop (the browser study, the study server):
/// device read, system tick (`paused`: the world held, zero force), watchdog, device write, the
/// tick logged to `tap` (a trial's MCAP, when one is open). `Err` is why the loop must stop; the
/// torques are then zeroed already. Allocation-free (a reason allocates its message, on the tick
/// that stops).
pub(crate) fn haptic_step(
    rig: &mut Rig,
    watchdog: &mut Watchdog,
    tap: Option<&mut TrialTap>,
    info: &TickInfo,
    paused: bool,
) -> Result<(), LoopEnd> {
    let (q, lost) = match rig.read() {
        Ok(q) => (q, None),
        Err(e) => ([f64::NAN; 4], Some(e)),
    };
    let out = rig.tick_system(&q, info, paused);
    let mut tau = out.torques;
    let safety = rig.safety_input(info, &out, lost.is_some());
    let Rig { system, io, .. } = rig;
    let guard = watchdog.guard(&safety, &mut tau);
    // A lost reading, or a world that diverged in this tick, stops the loop before its torques
    // reach the device (as in `haptic2d run`).
    if let Some(end) = lost
        .map(LoopEnd::read_failed)
        .or_else(|| LoopEnd::diverged(system.world()))
    {
        io.zero_torques();
        return Err(end);
    }
    if let Err(e) = io.write_torques(&tau) {
        io.zero_torques();
        return Err(LoopEnd::DeviceLost(e.to_string()));
    }
    if let Some(tap) = tap {
        let mut rec = out.record;
        rec.tau = tau;
        tap.tick(info, &q, &rec, system.world());
    }
    if let Some(end) = LoopEnd::after_write(guard, out.tripped) {
        io.zero_torques();
        return Err(end);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run_rig::test_rig::{sim_rig, tick_info};
    use crate::study_present::{in_free_space, Phase};
    use haptic2d_lab::study::file::Task;

    /// One tick of the simulated rig with the presenter in it (as `StudyLoop::tick`, without the
    /// display and the watchdog); returns the presenter's event and the slave's contact force (N).
    fn step(rig: &mut Rig, p: &mut Presenter) -> (Option<Event>, f64) {
        let slave = rig.system.slave();
        let ev = p.tick(
            rig.system.world_mut(),
            slave,
            1e-3,
            false,
            true,
            0,
            Default::default(),
        );
        let q = rig.io.read_encoders().unwrap();
        let out = rig.system.tick(&q, None, false);
        rig.io.write_torques(&out.torques).unwrap();
        let w = rig.system.world().contact_wrench(slave);
        (ev, w.force.x.hypot(w.force.y))
    }

    /// The stimulus switch is passive: while the handle presses the wall the next interval's law
    /// is not installed (the wall keeps the law being felt), and it is installed at the first tick
    /// in which the slave has no contact, where its contact force is zero before and after the
    /// switch: no step in the force the participant feels.
    #[test]
    fn stimulus_switch_waits_for_free_space_so_the_felt_force_never_steps() {
        let mut rig = sim_rig();
        let home = rig.hand_target_world();
        let before = rig.system.world().normal;
        let minsky = NormalModel::from_name("minsky", true).unwrap();
        assert_ne!(before, minsky);
        let f = rig.system.world().friction;
        let mut p = Presenter::new(Task::TwoAfc, 0.5);
        // Press the box into the left wall.
        rig.set_hand_target([-0.01, 0.0, 0.0]);
        let mut force = 0.0;
        for _ in 0..3000 {
            force = step(&mut rig, &mut p).1;
        }
        let slave = rig.system.slave();
        assert!(
            !in_free_space(rig.system.world(), slave),
            "the box presses the wall"
        );
        assert!(force > 0.1, "the wall pushes back: {force} N");
        assert!(p.start(Plan {
            trial: 1,
            done: 0,
            planned: 1,
            intervals: 2,
            laws: [(minsky, f); MAX_INTERVALS],
            rest: false,
        }));
        for _ in 0..500 {
            step(&mut rig, &mut p);
            assert_eq!(p.phase(), Phase::FreeSpace(0));
            assert_eq!(rig.system.world().normal, before, "no switch in contact");
        }
        // Back to free space: the switch happens at the first free tick, at zero contact force.
        rig.set_hand_target(home);
        let mut last_force = force;
        for k in 0..5000 {
            let free_before = in_free_space(rig.system.world(), slave);
            let (_, f_after) = step(&mut rig, &mut p);
            if let Phase::Presenting(..) = p.phase() {
                assert!(free_before, "installed only in free space (tick {k})");
                assert_eq!(last_force, 0.0, "zero contact force before the switch");
                assert_eq!(f_after, 0.0, "zero contact force after the switch");
                assert_eq!(rig.system.world().normal, minsky);
                return;
            }
            assert_eq!(rig.system.world().normal, before);
            last_force = f_after;
        }
        panic!("the box never left the wall");
    }

    /// One tick as `StudyLoop::tick` does it (presenter, hold, the rig's system tick at tick `k`
    /// of 1 ms, torques written); returns the torques sent.
    fn loop_tick(
        rig: &mut Rig,
        p: &mut Presenter,
        k: u64,
        inbox: crate::run_view::StudyInbox,
    ) -> [f64; 4] {
        let slave = rig.system.slave();
        p.tick(rig.system.world_mut(), slave, 1e-3, false, true, 0, inbox);
        let info = tick_info(k);
        let q = rig.read().unwrap();
        let out = rig.tick_system(&q, &info, held(false, p));
        rig.io.write_torques(&out.torques).unwrap();
        out.torques
    }

    fn norm(t: [f64; 4]) -> f64 {
        t.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// A rest break commands zero torque from its first tick while the hand presses the wall, for
    /// as long as it lasts; after the page continues, the torque ramps in from zero (no jolt): its
    /// mean over the first 50 ms stays under a fifth of where it settles.
    #[test]
    fn a_break_commands_zero_torque_and_the_torque_ramps_in_after_it() {
        let mut rig = sim_rig();
        let mut p = Presenter::new(Task::TwoAfc, 0.5);
        let idle = crate::run_view::StudyInbox::default();
        rig.set_hand_target([-0.01, 0.0, 0.0]);
        let mut k = 0;
        let mut pressing = 0.0;
        for _ in 0..3000 {
            pressing = norm(loop_tick(&mut rig, &mut p, k, idle));
            k += 1;
        }
        assert!(
            pressing > 1e-3,
            "the hand presses the wall: |τ| = {pressing} N·m"
        );
        let f = rig.system.world().friction;
        let n = rig.system.world().normal;
        assert!(p.start(Plan {
            trial: 3,
            done: 2,
            planned: 10,
            intervals: 2,
            laws: [(n, f); MAX_INTERVALS],
            rest: true,
        }));
        for _ in 0..500 {
            assert_eq!(
                loop_tick(&mut rig, &mut p, k, idle),
                [0.0; 4],
                "no force on a break"
            );
            k += 1;
        }
        let cont = crate::run_view::StudyInbox {
            cont: Some(3),
            ..idle
        };
        let first = norm(loop_tick(&mut rig, &mut p, k, cont));
        k += 1;
        assert!(!p.on_break());
        assert!(
            first < 0.05 * pressing,
            "the torque ramps in from zero: {first} after the break, {pressing} before"
        );
        // The ramp: over the first 50 ms the torque stays far below where it settles (0.5–0.6 s).
        let (mut early, mut settled) = (first, 0.0);
        for i in 1..600 {
            let t = norm(loop_tick(&mut rig, &mut p, k, idle));
            if i < 50 {
                early += t;
            } else if i >= 500 {
                settled += t;
            }
            k += 1;
        }
        let (early, settled) = (early / 50.0, settled / 100.0);
        assert!(
            settled > 1e-3 && early < 0.2 * settled,
            "the torque ramps in: mean {early} N·m over the first 50 ticks, {settled} at 0.5–0.6 s"
        );
    }
}
