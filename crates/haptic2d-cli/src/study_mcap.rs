//! The per-trial MCAP logs of a browser study session (issue 40 item 3: "the full MCAP of every
//! trial"): `SESSION/trials/trial-NNNN.mcap`, one per trial, each a complete `haptic2d run --log
//! FILE.mcap` log (ticks, bodies, contacts, energy, the scene) of the ticks from the trial's start
//! (its plan reaching the loop) to the tick that took its answer.
//!
//! The loop thread never touches a file: [`TrialTap`] (on the loop thread) pushes [`StudyRecord`]s
//! into a wait-free ring — a `Start` mark, the trial's ticks, an `End` mark — and the
//! [`TrialLogger`] thread rotates files at the marks. Ticks between trials are not logged.
//!
//! A trial cut short (SIGINT, the page's stop, a lost device) has its file finished on shutdown
//! (complete and readable, metadata `haptic2d.trial` says `outcome = interrupted`). When the resumed
//! session presents that trial again, the interrupted file is renamed
//! `trial-NNNN-interrupted-K.mcap` (K = 1, 2, … the first free) before the new `trial-NNNN.mcap` is
//! written: no file is overwritten, and `trial-NNNN.mcap` is always the answered presentation.

use haptic2d::haptic::TickRecord;
use haptic2d::world::World;
use haptic2d_rt::drain_thread::DrainThread;
use haptic2d_rt::mcap::{LoggedTick, McapSetup, McapSink, Metadata};
use haptic2d_rt::telemetry::{ring_capacity, MAX_RING_BYTES};
use haptic2d_rt::{telemetry_channel, RecordRx, TelemetryTx, TickInfo};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// What the loop pushes to the trial logger.
// Every slot of the ring is the size of a tick anyway; boxing the tick would allocate per tick.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum StudyRecord {
    /// Trial `trial` starts: the logger opens its file.
    Start {
        /// Trial number (from 1).
        trial: u32,
    },
    /// A tick of the open trial.
    Tick(LoggedTick),
    /// Trial `trial` was answered `choice` after `rt_s` s: the logger finishes its file.
    End {
        /// Trial number.
        trial: u32,
        /// The answer (as `trials.tsv`'s `response`).
        choice: u8,
        /// Response time (s).
        rt_s: f64,
    },
}

impl Default for StudyRecord {
    fn default() -> Self {
        Self::Start { trial: 0 }
    }
}

/// Marks waiting for room in the ring (a full ring drops ticks, never marks).
const PENDING_MARKS: usize = 4;

/// The loop thread's end: pushes the marks and the open trial's ticks. Allocation-free.
pub struct TrialTap {
    tx: TelemetryTx<StudyRecord>,
    logged: LoggedTick,
    open: bool,
    pending: [Option<StudyRecord>; PENDING_MARKS],
}

impl TrialTap {
    /// A tap pushing into `tx`.
    pub fn new(tx: TelemetryTx<StudyRecord>) -> Self {
        Self {
            tx,
            logged: LoggedTick::default(),
            open: false,
            pending: [None; PENDING_MARKS],
        }
    }

    /// Trial `trial` starts (its plan reached the loop).
    pub fn start(&mut self, trial: u32) {
        self.open = true;
        self.mark(StudyRecord::Start { trial });
    }

    /// Trial `trial` was answered.
    pub fn end(&mut self, trial: u32, choice: u8, rt_s: f64) {
        self.open = false;
        self.mark(StudyRecord::End {
            trial,
            choice,
            rt_s,
        });
    }

    fn mark(&mut self, m: StudyRecord) {
        self.flush();
        if self.pending.iter().all(Option::is_none) && self.tx.push(m) {
            return;
        }
        if let Some(slot) = self.pending.iter_mut().find(|s| s.is_none()) {
            *slot = Some(m);
        }
    }

    /// Pushes the waiting marks, oldest first; true when none is left.
    fn flush(&mut self) -> bool {
        for slot in self.pending.iter_mut() {
            if let Some(m) = *slot {
                if !self.tx.push(m) {
                    return false;
                }
                *slot = None;
            }
        }
        true
    }

    /// The tick `info` (joints `q`, record `rec` with the torques sent, `world` after it): logged
    /// while a trial is open (dropped and counted if the ring is full or a mark still waits).
    pub fn tick(&mut self, info: &TickInfo, q: &[f64; 4], rec: &TickRecord, world: &World) {
        if !self.flush() || !self.open {
            return;
        }
        self.logged.capture(info, q, rec, Some(world));
        self.tx.push(StudyRecord::Tick(self.logged));
    }
}

/// The path of trial `trial`'s log in the trials directory `dir`.
pub fn trial_path(dir: &Path, trial: u32) -> PathBuf {
    dir.join(format!("trial-{trial:04}.mcap"))
}

/// What the trial logger wrote.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TrialLogReport {
    /// Trial files finished with an answer.
    pub answered: u32,
    /// Trial files finished without one (interrupted).
    pub interrupted: u32,
    /// Ticks written.
    pub ticks: u64,
    /// Records the loop dropped because the ring was full.
    pub dropped: u64,
}

/// The logger thread writing `trials/trial-NNNN.mcap`.
pub struct TrialLogger {
    thread: DrainThread<TrialLogReport>,
}

impl TrialLogger {
    /// Starts the thread draining `rx` into files in `dir` (created at the first trial), each
    /// described by `setup`.
    pub fn spawn(
        rx: RecordRx<StudyRecord>,
        dir: PathBuf,
        setup: McapSetup,
    ) -> Result<Self, String> {
        let thread = DrainThread::spawn("haptic2d-trials", "trial logger", move |stop| {
            Rotator::new(dir, setup).run(rx, &stop)
        })?;
        Ok(Self { thread })
    }

    /// Drains the ring, finishes an open trial's file as interrupted, and reports. Call it after
    /// the loop stopped.
    pub fn finish(self) -> Result<TrialLogReport, String> {
        self.thread.finish("trial logger")
    }
}

/// An open trial file.
struct Open {
    trial: u32,
    path: PathBuf,
    sink: McapSink<BufWriter<File>>,
    ticks: u64,
}

/// The logger thread's state: rotates files at the marks.
struct Rotator {
    dir: PathBuf,
    setup: McapSetup,
    open: Option<Open>,
    report: TrialLogReport,
    error: Option<String>,
}

impl Rotator {
    fn new(dir: PathBuf, setup: McapSetup) -> Self {
        Self {
            dir,
            setup,
            open: None,
            report: TrialLogReport::default(),
            error: None,
        }
    }

    fn run(
        mut self,
        mut rx: RecordRx<StudyRecord>,
        stop: &AtomicBool,
    ) -> Result<TrialLogReport, String> {
        loop {
            // Read the flag before draining: everything pushed before it was set is written.
            let stopping = stop.load(Ordering::Acquire);
            while let Some(rec) = rx.pop() {
                if let Err(e) = self.take(rec) {
                    // Keep draining (the loop must never see a full ring), report the first error.
                    self.error.get_or_insert(e);
                }
            }
            if stopping {
                break;
            }
            std::thread::park_timeout(Duration::from_millis(2));
        }
        if let Err(e) = self.close(None) {
            self.error.get_or_insert(e);
        }
        self.report.dropped = rx.dropped();
        match self.error {
            Some(e) => Err(e),
            None => Ok(self.report),
        }
    }

    fn take(&mut self, rec: StudyRecord) -> Result<(), String> {
        match rec {
            StudyRecord::Start { trial } => {
                self.close(None)?;
                self.open(trial)
            }
            StudyRecord::Tick(t) => match &mut self.open {
                Some(o) => {
                    o.ticks += 1;
                    o.sink.write_tick(&t).map_err(|e| write_error(&o.path, e))
                }
                None => Ok(()),
            },
            StudyRecord::End {
                trial,
                choice,
                rt_s,
            } => {
                if self.open.as_ref().is_some_and(|o| o.trial == trial) {
                    self.close(Some((choice, rt_s)))
                } else {
                    Ok(())
                }
            }
        }
    }

    fn open(&mut self, trial: u32) -> Result<(), String> {
        std::fs::create_dir_all(&self.dir)
            .map_err(|e| format!("cannot create {}: {e}", self.dir.display()))?;
        let path = trial_path(&self.dir, trial);
        if path.exists() {
            // An earlier presentation of this trial, interrupted: kept under a new name.
            let aside = (1..)
                .map(|k| {
                    self.dir
                        .join(format!("trial-{trial:04}-interrupted-{k}.mcap"))
                })
                .find(|p| !p.exists())
                .unwrap_or_default();
            std::fs::rename(&path, &aside).map_err(|e| {
                format!("cannot move {} to {}: {e}", path.display(), aside.display())
            })?;
        }
        let file = File::create(&path)
            .map_err(|e| format!("cannot create the trial log {}: {e}", path.display()))?;
        let sink = McapSink::new(BufWriter::with_capacity(1 << 20, file), self.setup.clone())
            .map_err(|e| write_error(&path, e))?;
        self.open = Some(Open {
            trial,
            path,
            sink,
            ticks: 0,
        });
        Ok(())
    }

    /// Finishes the open file (if any) with its answer, or as interrupted.
    fn close(&mut self, answer: Option<(u8, f64)>) -> Result<(), String> {
        let Some(o) = self.open.take() else {
            return Ok(());
        };
        let mut m = BTreeMap::new();
        m.insert("trial".to_string(), o.trial.to_string());
        m.insert("ticks".to_string(), o.ticks.to_string());
        match answer {
            Some((choice, rt)) => {
                m.insert("outcome".into(), "answered".into());
                m.insert("response".into(), choice.to_string());
                m.insert("rt_s".into(), rt.to_string());
                self.report.answered += 1;
            }
            None => {
                m.insert("outcome".into(), "interrupted".into());
                self.report.interrupted += 1;
            }
        }
        self.report.ticks += o.ticks;
        let meta = Metadata {
            name: "haptic2d.trial".into(),
            metadata: m,
        };
        o.sink
            .finish(&[meta])
            .map(|_| ())
            .map_err(|e| write_error(&o.path, e))
    }
}

fn write_error(path: &Path, e: impl std::fmt::Display) -> String {
    format!("cannot write the trial log {}: {e}", path.display())
}

/// Starts the trial logs of a session: the ring (2 s of ticks at `rate_hz`), the tap for the loop
/// and the logger writing into `session_dir/trials`, each file describing `world` and the study
/// (`study_text` verbatim, `participant`, `session`, the device file) in its `haptic2d.scene`
/// metadata.
pub fn start(
    session_dir: &Path,
    world: &World,
    scene: BTreeMap<String, String>,
    rate_hz: f64,
) -> Result<(TrialTap, TrialLogger), String> {
    let capacity = ring_capacity::<StudyRecord>(rate_hz, 2.0, 4096, MAX_RING_BYTES);
    let (tx, rx, _latest) = telemetry_channel(capacity, StudyRecord::default())?;
    let setup = McapSetup::for_world(world, scene, true);
    let logger = TrialLogger::spawn(rx, session_dir.join("trials"), setup)?;
    Ok((TrialTap::new(tx), logger))
}

impl std::fmt::Display for TrialLogReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "trial logs: {} answered and {} interrupted trial(s), {} ticks in trials/",
            self.answered, self.interrupted, self.ticks
        )?;
        if self.dropped > 0 {
            write!(f, ", {} records dropped (the ring was full)", self.dropped)?;
        }
        Ok(())
    }
}

#[cfg(test)]
#[path = "study_mcap_tests.rs"]
mod tests;
