use super::*;
use haptic2d::scene::builtin;
use haptic2d_rt::mcap::columns::Val;
use haptic2d_rt::mcap::reader::{read_file, read_ticks, LogInfo};
use haptic2d_rt::mcap::schemas::{TOPIC_CONTACTS, TOPIC_TICK};
use haptic2d_rt::telemetry_channel;

const PERIOD_NS: u64 = 1_000_000;

fn info_at(i: u64) -> TickInfo {
    TickInfo {
        index: i,
        deadline_index: i,
        t_s: i as f64 * 1e-3,
        period_s: 1e-3,
        period_ns: PERIOD_NS,
        lateness_ns: 0,
        skipped: 0,
        deadline_ns: 5_000_000_000 + i * PERIOD_NS,
    }
}

/// Runs `f` with a tap whose logger writes into `dir`; returns the logger's report.
fn session(dir: &Path, world: &World, f: impl FnOnce(&mut TrialTap)) -> TrialLogReport {
    let (tx, rx, _) = telemetry_channel(4096, StudyRecord::default()).unwrap();
    let setup = McapSetup::for_world(world, BTreeMap::new(), true);
    let logger = TrialLogger::spawn(rx, dir.to_path_buf(), setup).unwrap();
    let mut tap = TrialTap::new(tx);
    f(&mut tap);
    drop(tap);
    logger.finish().unwrap()
}

fn ticks(tap: &mut TrialTap, world: &World, from: u64, n: u64) {
    for i in from..from + n {
        tap.tick(&info_at(i), &[0.0; 4], &TickRecord::default(), world);
    }
}

fn read(path: &Path) -> (LogInfo, Vec<u64>) {
    let bytes = read_file(path).unwrap();
    let (rows, info) = read_ticks(&bytes, "trial").unwrap();
    let idx = rows
        .iter()
        .map(|r| match r[0] {
            Some(Val::U(i)) => i,
            ref v => panic!("tick index {v:?}"),
        })
        .collect();
    (info, idx)
}

/// One file per trial holding exactly its ticks (none from between trials), complete, with the
/// answer in `haptic2d.trial`; a trial cut by the shutdown is finished as interrupted and, when the
/// resumed session presents it again, kept aside under a new name: no file is lost.
#[test]
fn each_trial_gets_its_own_complete_mcap_and_an_interrupted_one_is_kept_on_resume() {
    let dir = tempfile::tempdir().unwrap();
    let trials = dir.path().join("trials");
    let world = builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world;
    let r = session(&trials, &world, |tap| {
        ticks(tap, &world, 0, 7); // before any trial: not logged
        tap.start(1);
        ticks(tap, &world, 7, 50);
        tap.end(1, 2, 0.25);
        ticks(tap, &world, 57, 5); // between trials: not logged
        tap.start(2);
        ticks(tap, &world, 62, 30); // interrupted by the shutdown
    });
    assert_eq!(
        (r.answered, r.interrupted, r.ticks, r.dropped),
        (1, 1, 80, 0)
    );
    let (i1, idx1) = read(&trial_path(&trials, 1));
    assert!(i1.complete);
    assert_eq!(idx1, (7..57).collect::<Vec<_>>());
    assert_eq!(i1.count(TOPIC_CONTACTS), 50, "the world rides along");
    let m = i1.metadata("haptic2d.trial").unwrap();
    assert_eq!(
        (
            m["trial"].as_str(),
            m["outcome"].as_str(),
            m["response"].as_str()
        ),
        ("1", "answered", "2")
    );
    let (t0, t1) = i1.time_range_ns.unwrap();
    assert_eq!(
        t1 - t0,
        49 * PERIOD_NS,
        "log times are the ticks' deadlines"
    );
    let (i2, idx2) = read(&trial_path(&trials, 2));
    assert!(i2.complete, "finished on shutdown");
    assert_eq!(idx2.len(), 30);
    assert_eq!(
        i2.metadata("haptic2d.trial").unwrap()["outcome"],
        "interrupted"
    );

    // The resumed session presents trial 2 again.
    let r = session(&trials, &world, |tap| {
        tap.start(2);
        ticks(tap, &world, 0, 20);
        tap.end(2, 1, 0.5);
    });
    assert_eq!((r.answered, r.interrupted), (1, 0));
    let (i2, idx2) = read(&trial_path(&trials, 2));
    assert_eq!(idx2.len(), 20);
    assert_eq!(
        i2.metadata("haptic2d.trial").unwrap()["outcome"],
        "answered"
    );
    let (old, idx_old) = read(&trials.join("trial-0002-interrupted-1.mcap"));
    assert_eq!(idx_old.len(), 30);
    assert_eq!(
        old.metadata("haptic2d.trial").unwrap()["outcome"],
        "interrupted"
    );
    assert_eq!(
        read(&trial_path(&trials, 1)).1.len(),
        50,
        "trial 1 untouched"
    );
    assert_eq!(i2.count(TOPIC_TICK), 20);
}

/// A full ring drops ticks (counted), never the marks: the trial's file still opens and closes.
#[test]
fn a_full_ring_drops_ticks_but_never_a_trial_mark() {
    let dir = tempfile::tempdir().unwrap();
    let world = builtin("box-in-walls", Some(1000.0))
        .unwrap()
        .unwrap()
        .world;
    let (tx, rx, _) = telemetry_channel(8, StudyRecord::default()).unwrap();
    let mut tap = TrialTap::new(tx);
    tap.start(1);
    ticks(&mut tap, &world, 0, 20); // the ring (8) fills: ticks dropped
    tap.end(1, 1, 0.1); // no room: waits in the tap
    let setup = McapSetup::for_world(&world, BTreeMap::new(), true);
    let logger = TrialLogger::spawn(rx, dir.path().to_path_buf(), setup).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    ticks(&mut tap, &world, 20, 1); // flushes the end mark; the trial is closed: not logged
    drop(tap);
    let r = logger.finish().unwrap();
    assert_eq!((r.answered, r.interrupted), (1, 0), "{r:?}");
    assert_eq!(r.ticks, 7, "the ring held the start mark and 7 ticks");
    assert!(r.dropped >= 13, "{r:?}");
    let (info, _) = read(&trial_path(dir.path(), 1));
    assert_eq!(
        info.metadata("haptic2d.trial").unwrap()["outcome"],
        "answered"
    );
}
