//! Interleaved timing of the two engines in one process: both worlds advance in alternating chunks of
//! steps (haptic2d first in even chunks, rapier2d first in odd ones), every step timed on its own, so
//! slow drifts of the machine (frequency, other processes) hit both engines alike.

use std::time::Instant;

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
}

/// Runs `warmup` untimed steps of each engine, then `steps` timed steps of each, interleaved in chunks
/// of `chunk` steps. Returns `(haptic2d, rapier2d)` samples.
pub fn interleaved(
    warmup: usize,
    steps: usize,
    chunk: usize,
    mut a: impl FnMut(),
    mut b: impl FnMut(),
) -> (Samples, Samples) {
    for _ in 0..warmup {
        a();
        b();
    }
    let chunk = chunk.max(1);
    let mut ta = Vec::with_capacity(steps);
    let mut tb = Vec::with_capacity(steps);
    let run = |f: &mut dyn FnMut(), out: &mut Vec<f64>, n: usize| {
        for _ in 0..n {
            let t0 = Instant::now();
            f();
            out.push(t0.elapsed().as_secs_f64() * 1e6);
        }
    };
    let mut done = 0;
    let mut k = 0;
    while done < steps {
        let n = chunk.min(steps - done);
        if k % 2 == 0 {
            run(&mut a, &mut ta, n);
            run(&mut b, &mut tb, n);
        } else {
            run(&mut b, &mut tb, n);
            run(&mut a, &mut ta, n);
        }
        done += n;
        k += 1;
    }
    (Samples(ta), Samples(tb))
}
