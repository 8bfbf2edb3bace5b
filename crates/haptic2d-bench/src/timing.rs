//! Interleaved timing of the two engines in one process: all worlds advance in alternating chunks of
//! steps (the first engine of a chunk rotates), every step timed on its own, so
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
/// of `chunk` steps; the engine that goes first rotates every chunk. Returns one sample set per
/// engine, in the order given.
pub fn interleaved(
    warmup: usize,
    steps: usize,
    chunk: usize,
    engines: &mut [&mut dyn FnMut()],
) -> Vec<Samples> {
    for _ in 0..warmup {
        for e in engines.iter_mut() {
            e();
        }
    }
    let chunk = chunk.max(1);
    let m = engines.len();
    let mut out: Vec<Vec<f64>> = (0..m).map(|_| Vec::with_capacity(steps)).collect();
    let mut done = 0;
    let mut k = 0;
    while done < steps {
        let n = chunk.min(steps - done);
        for r in 0..m {
            let e = (k + r) % m;
            let f = &mut engines[e];
            for _ in 0..n {
                let t0 = Instant::now();
                f();
                out[e].push(t0.elapsed().as_secs_f64() * 1e6);
            }
        }
        done += n;
        k += 1;
    }
    out.into_iter().map(Samples).collect()
}
