//! UDP round trip on loopback (docs/PERFORMANCE.md): paced by the haptic loop's own runner at
//! `--rate HZ`, each tick sends one command and waits (at most 0.8 of a period) for its answer;
//! prints the round trip p50/p99/p99.9/max, the answers that missed the wait, and the fraction of
//! ticks on time.
//!
//! ```text
//! python3 devices/udp/sim_device.py --bind 127.0.0.1:5005 &
//! cargo run --release -p haptic2d-devices --example udp_roundtrip -- 127.0.0.1:5005 1000 3
//! ```

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use haptic2d_devices::udp::codec::FLAG_ENABLE;
use haptic2d_devices::udp::UdpTransport;
use haptic2d_rt::histogram::LogHistogram;
use haptic2d_rt::{run_loop, LoopConfig, TickControl};

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 2 {
        return Err("usage: udp_roundtrip ADDR:PORT [RATE_HZ] [SECONDS] [--rt]".into());
    }
    let addr = args[1].parse().map_err(|e| format!("{}: {e}", args[1]))?;
    let rate: f64 = args
        .get(2)
        .map_or(Ok(1000.0), |s| s.parse())
        .map_err(|e| format!("{e}"))?;
    let secs: f64 = args
        .get(3)
        .map_or(Ok(3.0), |s| s.parse())
        .map_err(|e| format!("{e}"))?;
    let rt = args.iter().any(|a| a == "--rt");
    let mut t = UdpTransport::connect(addr).map_err(|e| e.to_string())?;
    // Warm up (and check that the device answers).
    t.send(0, [0.0; 3]).map_err(|e| e.to_string())?;
    if !t
        .wait_answer(Instant::now() + Duration::from_secs(1))
        .map_err(|e| e.to_string())?
    {
        return Err(format!("no answer from {addr}"));
    }
    let wait = Duration::from_secs_f64(0.8 / rate);
    let mut rtt = LogHistogram::new();
    let stop = AtomicBool::new(false);
    let config = LoopConfig {
        rate_hz: rate,
        duration: Some(Duration::from_secs_f64(secs)),
        rt,
        spin_us: (0.4e6 / rate).min(400.0),
        ..LoopConfig::default()
    };
    let summary = run_loop(&config, &stop, |_| {
        if t.send(FLAG_ENABLE, [0.0; 3]).is_err() {
            return TickControl::Stop;
        }
        if let Ok(true) = t.wait_answer(Instant::now() + wait) {
            if let Some(ns) = t.take_rtt() {
                rtt.record(ns);
            }
        }
        TickControl::Continue
    })?;
    let us = |v: Option<u64>| v.map_or(f64::NAN, |v| v as f64 * 1e-3);
    println!(
        "{addr} at {rate} Hz for {secs} s: round trip p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs, max {:.1} µs ({} answers); on time {:.3} % of {} deadlines ({} ticks, {} skipped)",
        us(rtt.quantile(0.5)),
        us(rtt.quantile(0.99)),
        us(rtt.quantile(0.999)),
        us(rtt.max()),
        rtt.count(),
        summary.on_time_fraction * 100.0,
        summary.deadlines,
        summary.ticks,
        summary.skipped
    );
    println!("udp: {}", t.counters());
    Ok(())
}
