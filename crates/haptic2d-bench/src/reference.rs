//! The machine's own spread, measured in the same run: a deterministic workload interleaved with
//! the engines like a fifth one.
//!
//! Every "step" of the reference is the same read–modify–write pass over one buffer of `f64`, in a
//! fixed shuffled order: same instructions, same addresses, no branches that depend on data.
//! Shuffled, as engines gather their bodies' states by index: a sequential pass, which the
//! prefetchers stream, hid what the engines meet (in session 11, at pile:1000, its chunk starts
//! cost 1.06 × its median and its p99 was 1.14–1.21 ×; shuffled, 1.52–1.80 × and 1.51–2.00 ×).
//! Neither follows the long phases in which every engine speeds up or slows down together
//! (presumably the core clock): both are bound by memory.
//!
//! Whatever spread its step times show (p99 / median above 1, slow first steps of a chunk) is the
//! machine's: other tenants of the host, the hyperthread that shares the core's caches,
//! interrupts, and the other engines' chunks in between. The buffer is sized during the warm-up,
//! twice, by the ratio of haptic2d's median step time to its own in the same interleaved
//! conditions, so that one pass takes about as long as a haptic2d step: the reference meets those
//! sources over the same durations as haptic2d does (docs/PERFORMANCE.md, issue 17, session 11).

/// Smallest reference buffer (bytes).
pub const MIN_BYTES: usize = 1 << 10;
/// Largest reference buffer (bytes).
pub const MAX_BYTES: usize = 256 << 20;

/// The reference workload: one buffer of `f64`, passed over once per step in a fixed shuffled order.
#[derive(Debug, Default)]
pub struct Reference {
    buf: Vec<f64>,
    /// The order of the pass: a permutation of the buffer's indices, from a fixed seed.
    order: Vec<u32>,
    /// Carried from pass to pass, so no pass can be optimised away.
    acc: f64,
}

impl Reference {
    /// Bytes one step touches: the buffer and its order (12 per element).
    pub fn bytes(&self) -> usize {
        self.buf.len() * (std::mem::size_of::<f64>() + std::mem::size_of::<u32>())
    }

    /// One step: a pass over the whole buffer in its order, each element replaced by a running
    /// blend of the elements visited before it.
    #[inline(never)]
    pub fn step(&mut self) {
        let mut acc = self.acc;
        for &i in &self.order {
            let x = &mut self.buf[i as usize];
            acc = acc * 0.5 + *x;
            *x = acc * 0.5;
        }
        self.acc = std::hint::black_box(acc);
    }

    /// A reference touching about `bytes` (clamped to [`MIN_BYTES`]..=[`MAX_BYTES`]).
    pub fn new(bytes: usize) -> Self {
        let mut r = Self::default();
        r.resize(bytes);
        r
    }

    /// Rescales the buffer by `target_us / now_us`: `now_us` the median of its recent passes,
    /// `target_us` the time to match (µs); nothing when either is not a positive time.
    pub fn rescale(&mut self, target_us: f64, now_us: f64) {
        let f = target_us / now_us;
        if f.is_finite() && f > 0.0 {
            self.resize((self.bytes() as f64 * f) as usize);
        }
    }

    fn resize(&mut self, bytes: usize) {
        let n = bytes.clamp(MIN_BYTES, MAX_BYTES) / 12;
        self.buf.clear();
        self.buf.resize(n, 1.0);
        // Fisher–Yates with a fixed xorshift64 sequence: the same order on every run.
        self.order.clear();
        self.order.extend(0..n as u32);
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for i in (1..n).rev() {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            self.order.swap(i, (x % (i as u64 + 1)) as usize);
        }
    }
}
