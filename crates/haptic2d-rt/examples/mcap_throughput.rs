//! Logger throughput (issue 14: ≥ 50 000 records/s): pushes N realistic ticks (the box-in-walls
//! world, its bodies and contacts captured after each step) through the telemetry ring into the
//! MCAP logger thread writing a file, and reports ticks/s against wall time and against the
//! process's CPU time (on a shared, loaded machine the wall figure understates the logger).
//!
//!     cargo run --release -p haptic2d-rt --example mcap_throughput -- [N] [FILE]

use haptic2d::haptic::TickRecord;
use haptic2d::scene::builtin;
use haptic2d_rt::mcap::{LoggedTick, McapLogger, McapSetup};
use haptic2d_rt::telemetry_channel;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

fn main() {
    let mut args = std::env::args().skip(1);
    let n: u64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(200_000);
    let path = args.next().unwrap_or_else(|| {
        std::env::temp_dir()
            .join("haptic2d-throughput.mcap")
            .display()
            .to_string()
    });
    let scene = builtin("box-in-walls", Some(10_000.0)).unwrap().unwrap();
    let mut world = scene.world;
    // Realistic records: 2000 distinct world states, cycled (stepping the world is not what is
    // being measured).
    let mut samples = Vec::new();
    for k in 0..2000u64 {
        world.step();
        let mut t = LoggedTick::default();
        t.world.capture(&world);
        t.rec = TickRecord {
            t: world.time(),
            contacts: t.world.contact_count,
            ..TickRecord::default()
        };
        t.q = [0.1 * k as f64, 0.2, 0.3, 0.4];
        samples.push(t);
    }
    let (mut tx, rx, _) = telemetry_channel(n as usize + 1, LoggedTick::default()).unwrap();
    let setup = McapSetup::for_world(&world, BTreeMap::new(), true);
    let logger = McapLogger::spawn_file(rx, std::path::Path::new(&path), setup).unwrap();
    let start = Instant::now();
    let cpu0 = cpu_s();
    for i in 0..n {
        let mut t = samples[(i % 2000) as usize];
        t.index = i;
        t.deadline_ns = 1_000_000_000 + i * 100_000;
        assert!(tx.push(t), "ring full");
        if i % 1000 == 0 {
            std::thread::sleep(Duration::from_micros(1)); // let the logger run, as the loop would
        }
    }
    drop(tx);
    let report = logger.finish(Vec::new()).unwrap();
    let s = start.elapsed().as_secs_f64();
    let cpu = cpu_s() - cpu0;
    let bytes = std::fs::metadata(&path).unwrap().len();
    println!(
        "{} ticks ({} messages) in {s:.3} s wall, {cpu:.3} s CPU: {:.0} ticks/s wall, {:.0} ticks per CPU-second ({:.0} messages/s wall); {:.0} bytes/tick; {}",
        report.log.written,
        report.stats.messages,
        report.log.written as f64 / s,
        report.log.written as f64 / cpu,
        report.stats.messages as f64 / s,
        bytes as f64 / report.log.written as f64,
        path
    );
    assert_eq!(report.log.written, n);
}

/// CPU time of the whole process (both threads), s.
fn cpu_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec.
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}
