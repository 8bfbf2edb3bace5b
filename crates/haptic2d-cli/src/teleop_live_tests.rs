//! The live teleop's tick on synthetic tick times: a simulated master and a fake point device as
//! the slave, whose readings and written forces the test sees.

use std::sync::{Arc, Mutex};

use haptic2d::haptic::{DeviceEnd, SafetyConfig, WorkspaceSquare};
use haptic2d_lab::network::Impairment;
use haptic2d_rt::{DeviceError, DeviceIo, TickControl, TickInfo};

use super::{Live, LiveStop};
use crate::push_arg::Push;
use crate::run_rig::test_rig::tick_info;
use crate::teleop_end::{LiveEnd, Role};

/// What the fake slave reads at a tick: a point (m), a non-finite reading, or a lost device.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Reading {
    Point([f64; 2]),
    NonFinite,
    Lost,
}

/// The fake slave's script (its reading, changed by the test) and every force written (N).
#[derive(Default)]
struct Shared {
    reading: Option<Reading>,
    written: Vec<[f64; 2]>,
}

struct FakePoint(Arc<Mutex<Shared>>);

impl DeviceIo for FakePoint {
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        match self
            .0
            .lock()
            .unwrap()
            .reading
            .unwrap_or(Reading::Point([0.0; 2]))
        {
            Reading::Point(p) => Ok([p[0], p[1], 0.0, 0.0]),
            Reading::NonFinite => Ok([f64::NAN, 0.0, 0.0, 0.0]),
            Reading::Lost => Err(DeviceError::Lost("fake: unplugged".into())),
        }
    }
    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
        self.0.lock().unwrap().written.push([tau[0], tau[1]]);
        Ok(())
    }
    fn zero_torques(&mut self) {}
    fn name(&self) -> &str {
        "fake"
    }
}

/// A simulated master pushed 15 mm left from t = 0 and a fake point slave (5 N, ± 0.1 m around
/// the origin, 0.1 kg) held at the origin, no delay, TDPA on, 3 s.
fn live() -> (Live, Arc<Mutex<Shared>>) {
    let push = Push::parse("-0.015,0,0.05,0").unwrap();
    let m = LiveEnd::open(Role::Master, "sim", None, false, Some(push), 1e-3).unwrap();
    let square = WorkspaceSquare::around([0.0, 0.0], 0.1);
    let end = DeviceEnd::point(5.0, square, 0.1, SafetyConfig::default(), 1e-3).unwrap();
    let shared = Arc::new(Mutex::new(Shared::default()));
    let s = LiveEnd::with_io(Role::Slave, Box::new(FakePoint(shared.clone())), end);
    let link = Impairment::delay_loss(0, 0.0, 1);
    (Live::new(m, s, link, (500.0, 5.0), true, 1e-3, 3.0), shared)
}

/// Runs ticks `from..to`, all of which must continue.
fn run(l: &mut Live, from: u64, to: u64) {
    for k in from..to {
        assert_eq!(l.tick(&tick_info(k)), TickControl::Continue, "tick {k}");
    }
}

fn norm(f: &[f64; 2]) -> f64 {
    f[0].hypot(f[1])
}

/// Both ends start at zero and ramp in: the slave's first force is zero, its force 10 ms in is
/// far below the force after the 0.5 s ramp, and the coupling then pulls the held slave towards
/// the master's push (−x).
#[test]
fn both_ends_start_at_zero_force_and_ramp_in() {
    let (mut l, shared) = live();
    run(&mut l, 0, 800);
    let w = shared.lock().unwrap().written.clone();
    assert_eq!(w[0], [0.0, 0.0]);
    assert_eq!(l.m.last_torque_t.map(|t| t > 0.0), Some(true));
    let (early, late) = (norm(&w[10]), norm(&w[799]));
    assert!(
        late > 0.5 && early < 0.05 * late,
        "early {early} N, late {late} N"
    );
    assert!(w[799][0] < 0.0, "{:?}", w[799]);
}

/// [`live`] run for 800 ms, then the slave reads `reading` at tick 800, which must stop the loop
/// (its master's last non-zero torques were written at 0.799 s).
fn slave_reads_at_800_ms(reading: Reading) -> (Live, Arc<Mutex<Shared>>) {
    let (mut l, shared) = live();
    run(&mut l, 0, 800);
    shared.lock().unwrap().reading = Some(reading);
    assert_eq!(l.tick(&tick_info(800)), TickControl::Stop);
    (l, shared)
}

/// A latch at the slave alone (a non-finite reading) zeroes the master too, in the same tick:
/// the master's zero torques are written at the trip's time, its last non-zero ones a tick
/// before, and the slave is written zero.
#[test]
fn a_latch_at_the_slave_zeroes_the_master_in_the_same_tick() {
    let (l, shared) = slave_reads_at_800_ms(Reading::NonFinite);
    assert!(
        matches!(l.stop, Some((_, LiveStop::Latch(Role::Slave, _)))),
        "{:?}",
        l.stop
    );
    assert!(
        l.m.end.trip_info().is_none(),
        "the master did not latch by itself"
    );
    assert_eq!(l.m.tau, [0.0; 4]);
    assert_eq!(l.m.zeroed_t, Some(0.8));
    assert_eq!(l.m.last_torque_t, Some(0.799));
    assert_eq!(shared.lock().unwrap().written.last(), Some(&[0.0, 0.0]));
}

/// A lost slave zeroes the master in that tick, and the stop names the slave.
#[test]
fn a_lost_slave_zeroes_the_master_and_names_the_slave() {
    let (l, _) = slave_reads_at_800_ms(Reading::Lost);
    assert!(
        matches!(
            l.stop,
            Some((_, LiveStop::Lost(Role::Slave, DeviceError::Lost(_))))
        ),
        "{:?}",
        l.stop
    );
    assert_eq!(
        (l.m.tau, l.m.zeroed_t, l.m.last_torque_t),
        ([0.0; 4], Some(0.8), Some(0.799))
    );
}

/// The hot path: two simulated devices across a 25 ms link with 5 % loss. The lab's `Link` sizes
/// its queue for everything that can be in flight, so no tick allocates, from the first (1 100
/// ticks counted, on this thread, by the counting allocator the CLI's unit tests install:
/// run_view.rs).
#[test]
fn no_tick_allocates_even_while_the_link_fills() {
    let m = LiveEnd::open(Role::Master, "sim", None, false, None, 1e-3).unwrap();
    let s = LiveEnd::open(Role::Slave, "sim", None, false, None, 1e-3).unwrap();
    let link = Impairment::delay_loss(25, 0.05, 3);
    let mut l = Live::new(m, s, link, (500.0, 5.0), true, 1e-3, 3.0);
    let count = haptic2d_test_support::alloc::allocations;
    // The counter counts (so the zero below means something).
    let a = count();
    std::hint::black_box(Box::new(1u64));
    assert!(count() > a, "the counting allocator is installed");
    let a0 = count();
    run(&mut l, 0, 1100);
    assert_eq!(count() - a0, 0, "allocations in 1 100 ticks");
}

/// `run`'s watchdog: with the slave's device file allowing 10 consecutive missed deadlines, the
/// tenth late tick stops the loop before reading, both ends zeroed in it; nine do not.
#[test]
fn ten_missed_deadlines_in_a_row_stop_with_both_ends_zeroed() {
    let (mut l, _) = live();
    l.s.max_missed_run = Some(10);
    run(&mut l, 0, 600);
    let late = |k: u64| TickInfo {
        skipped: 1,
        ..tick_info(k)
    };
    for k in 600..609 {
        assert_eq!(l.tick(&late(k)), TickControl::Continue, "tick {k}");
    }
    run(&mut l, 609, 700);
    for k in 700..709 {
        assert_eq!(l.tick(&late(k)), TickControl::Continue, "tick {k}");
    }
    assert_eq!(l.tick(&late(709)), TickControl::Stop);
    assert!(
        matches!(
            l.stop,
            Some((
                _,
                LiveStop::Missed {
                    role: Role::Slave,
                    run: 10,
                    limit: 10
                }
            ))
        ),
        "{:?}",
        l.stop
    );
    assert_eq!(
        (l.m.zeroed_t, l.m.last_torque_t),
        (Some(0.709), Some(0.708))
    );
}
