//! Interleaved timing of the two engines in one process: all worlds advance in alternating chunks of
//! steps (the first engine of a chunk rotates), every step timed on its own, so
//! slow drifts of the machine (frequency, other processes) hit both engines alike.

use std::time::Instant;

/// Which clock times a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Clock {
    /// Wall time (`Instant`): what a real-time loop sees, including time the thread was preempted.
    Wall,
    /// This thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`): leaves out preemption by other
    /// processes, so it is the fairer measure on a loaded machine (it still sees their cache misses).
    Cpu,
}

/// The current time of `clock` (s).
#[inline]
pub fn now(clock: Clock, origin: Instant) -> f64 {
    match clock {
        Clock::Wall => origin.elapsed().as_secs_f64(),
        Clock::Cpu => {
            let mut ts = libc::timespec {
                tv_sec: 0,
                tv_nsec: 0,
            };
            // SAFETY: `ts` is a valid, writable timespec; the clock id is a Linux/POSIX constant.
            let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
            if rc != 0 {
                return f64::NAN;
            }
            ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
        }
    }
}

/// Per-step wall times of one engine (µs), in step order.
pub struct Samples(pub Vec<f64>);

impl Samples {
    /// The `q`-quantile (0..=1) by nearest rank (µs); NaN when empty.
    pub fn quantile(&self, q: f64) -> f64 {
        if self.0.is_empty() {
            return f64::NAN;
        }
        let mut v = self.0.clone();
        v.sort_by(f64::total_cmp);
        let rank = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
        v[rank - 1]
    }
    /// Median step time (µs).
    pub fn median(&self) -> f64 {
        self.quantile(0.5)
    }
    /// 99th-percentile step time (µs).
    pub fn p99(&self) -> f64 {
        self.quantile(0.99)
    }
    /// These samples of one engine from [`interleaved`] with `chunk`, without the first step of
    /// each chunk: the step that runs right after the other engines, with its data evicted from
    /// the caches (every engine's samples are its chunks back to back, each `chunk` steps long
    /// but the last).
    pub fn without_chunk_starts(&self, chunk: usize) -> Samples {
        let chunk = chunk.max(1);
        Samples(
            self.0
                .iter()
                .enumerate()
                .filter(|(i, _)| i % chunk != 0)
                .map(|(_, &x)| x)
                .collect(),
        )
    }
    /// The first step of each chunk of these samples (see
    /// [`without_chunk_starts`](Self::without_chunk_starts)): what a step costs right after the
    /// other engines ran.
    pub fn chunk_starts(&self, chunk: usize) -> Samples {
        Samples(self.0.iter().step_by(chunk.max(1)).copied().collect())
    }
}

/// Most warm-up steps of each calibration window of [`interleaved`].
pub const CALIBRATION_STEPS: usize = 200;

/// Runs `warmup` steps of each engine, then `steps` timed steps of each, interleaved in chunks of
/// `chunk` steps; the engine that goes first rotates every chunk. Returns one sample set per
/// engine, in the order given.
///
/// `calibrate(first, last)` is called twice during the warm-up, at its middle and at its end,
/// with the median times (µs) of the first and the last engine over the warm-up steps just before
/// (at most [`CALIBRATION_STEPS`], and only when the warm-up has at least 8): the last engine can
/// resize itself to the first one's time in the same interleaved conditions.
pub fn interleaved(
    clock: Clock,
    warmup: usize,
    steps: usize,
    chunk: usize,
    engines: &mut [&mut dyn FnMut()],
    calibrate: &mut dyn FnMut(f64, f64),
) -> Vec<Samples> {
    let origin = Instant::now();
    let m = engines.len();
    let window = if warmup >= 8 {
        CALIBRATION_STEPS.min(warmup / 4)
    } else {
        0
    };
    let ends = [warmup / 2, warmup];
    let (mut first, mut last) = (Vec::with_capacity(window), Vec::with_capacity(window));
    for i in 0..warmup {
        let timed = window > 0 && ends.iter().any(|&e| i < e && i + window >= e);
        for (k, e) in engines.iter_mut().enumerate() {
            if timed && (k == 0 || k + 1 == m) {
                let t0 = now(clock, origin);
                e();
                let us = (now(clock, origin) - t0) * 1e6;
                if k == 0 {
                    first.push(us);
                } else {
                    last.push(us);
                }
            } else {
                e();
            }
        }
        if timed && ends.contains(&(i + 1)) {
            let f = Samples(std::mem::take(&mut first)).median();
            let l = Samples(std::mem::take(&mut last)).median();
            calibrate(f, l);
        }
    }
    let chunk = chunk.max(1);
    let mut out: Vec<Vec<f64>> = (0..m).map(|_| Vec::with_capacity(steps)).collect();
    let mut done = 0;
    let mut k = 0;
    while done < steps {
        let n = chunk.min(steps - done);
        for r in 0..m {
            let e = (k + r) % m;
            let f = &mut engines[e];
            for _ in 0..n {
                let t0 = now(clock, origin);
                f();
                out[e].push((now(clock, origin) - t0) * 1e6);
            }
        }
        done += n;
        k += 1;
    }
    out.into_iter().map(Samples).collect()
}
