//! Load test: five WebSocket viewers at once against `haptic2d-view-demo` (1 kHz loop). Checks that
//! frames keep arriving to every viewer, and reports the loop's own tick timing (from the frames'
//! `timing`, 1 s windows) with one viewer and with five. No timing assertions (machines are noisy);
//! run with `--nocapture` to see the numbers.

use crate::common;

use futures_util::StreamExt;
use serde_json::Value;
use std::time::{Duration, Instant};
use tokio_tungstenite::tungstenite::Message;

#[derive(Debug, Default, Clone)]
struct Phase {
    frames: Vec<u64>,
    bytes: u64,
    worst_late_p99: f64,
    worst_late_max: f64,
    worst_compute_p99: f64,
    achieved: Vec<f64>,
    overruns: (u64, u64),
    skipped: (u64, u64),
}

/// Runs `n` viewers for `secs` seconds; viewer 0 also records the loop timing it sees.
async fn phase(addr: &str, n: usize, secs: f64) -> Phase {
    let mut tasks = Vec::new();
    for i in 0..n {
        let url = format!("ws://{addr}/ws");
        tasks.push(tokio::spawn(async move {
            let (mut ws, _) = tokio_tungstenite::connect_async(url)
                .await
                .expect("connects");
            let end = Instant::now() + Duration::from_secs_f64(secs);
            let mut frames = 0u64;
            let mut bytes = 0u64;
            let mut timings = Vec::new();
            while let Ok(Some(Ok(msg))) = tokio::time::timeout_at(end.into(), ws.next()).await {
                if let Message::Text(t) = msg {
                    let v: Value = serde_json::from_str(t.as_str()).unwrap();
                    if v["type"] == "frame" {
                        frames += 1;
                        bytes += t.len() as u64;
                        if i == 0 {
                            timings.push(v["timing"].clone());
                        }
                    }
                }
            }
            (frames, bytes, timings)
        }));
    }
    let mut p = Phase::default();
    for (i, t) in tasks.into_iter().enumerate() {
        let (frames, bytes, timings) = t.await.unwrap();
        p.frames.push(frames);
        p.bytes += bytes;
        if i == 0 && !timings.is_empty() {
            // Skip the first second: its window may predate this phase.
            let skip = timings.len().min(60);
            for tm in &timings[skip..] {
                let f = |k: &str| tm[k].as_f64().unwrap_or(0.0);
                p.worst_late_p99 = p.worst_late_p99.max(f("lateness_p99_us"));
                p.worst_late_max = p.worst_late_max.max(f("lateness_max_us"));
                p.worst_compute_p99 = p.worst_compute_p99.max(f("compute_p99_us"));
                let a = f("achieved_hz");
                if p.achieved.last() != Some(&a) {
                    p.achieved.push(a);
                }
            }
            let u = |tm: &Value, k: &str| tm[k].as_u64().unwrap_or(0);
            let (a, b) = (&timings[0], &timings[timings.len() - 1]);
            p.overruns = (u(a, "overruns"), u(b, "overruns"));
            p.skipped = (u(a, "skipped"), u(b, "skipped"));
        }
    }
    p
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn five_viewers_keep_receiving_frames() {
    let _cores = crate::CORES.write().await;
    let demo = common::start_demo(&[]);
    let secs = 4.0;
    let one = phase(&demo.addr, 1, secs).await;
    let five = phase(&demo.addr, 5, secs).await;
    for (name, p) in [("1 viewer ", &one), ("5 viewers", &five)] {
        let total: u64 = p.frames.iter().sum();
        println!(
            "load {name}: frames per viewer {:?} in {secs} s ({:.1}/s each), mean frame {:.0} B; loop: achieved {:?} Hz, lateness p99 ≤ {:.1} µs, max ≤ {:.1} µs, compute p99 ≤ {:.1} µs, overruns {} → {}, skipped {} → {}",
            p.frames,
            total as f64 / p.frames.len() as f64 / secs,
            p.bytes as f64 / total.max(1) as f64,
            p.achieved,
            p.worst_late_p99,
            p.worst_late_max,
            p.worst_compute_p99,
            p.overruns.0,
            p.overruns.1,
            p.skipped.0,
            p.skipped.1,
        );
    }
    // Liveness only: every viewer got a steady stream (nominally 60 frames/s).
    for (i, f) in five.frames.iter().enumerate() {
        assert!(
            *f as f64 >= 10.0 * secs,
            "viewer {i} of 5 received only {f} frames in {secs} s"
        );
    }
    assert!(one.frames[0] as f64 >= 10.0 * secs);
}
