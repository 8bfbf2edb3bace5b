//! Wait-free transport of telemetry records from the real-time thread.
//!
//! One producer, [`TelemetryTx`], lives on the RT thread. Each record goes to
//! two places:
//!
//! - a bounded single-producer/single-consumer ring (`rtrb`) for a consumer
//!   that must see **every** record (the CSV logger). When the ring is full the
//!   record is dropped and counted — the RT thread never blocks or allocates;
//! - a triple buffer (`triple_buffer`) holding the **latest** record for a
//!   consumer that only wants the current state (the display), at its own pace.
//!
//! Both are allocated once, by [`telemetry_channel`]. Records are `Copy`, so
//! pushing is a memory copy plus a few atomic operations.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Counters shared by the producer and the consumers.
#[derive(Debug, Default)]
struct Counters {
    /// Records offered to the ring.
    offered: AtomicU64,
    /// Records dropped because the ring was full.
    dropped: AtomicU64,
}

/// The RT-side end: publishes records to the ring and to the latest snapshot.
pub struct TelemetryTx<T: Copy + Send + 'static> {
    ring: rtrb::Producer<T>,
    latest: triple_buffer::Input<T>,
    counters: Arc<Counters>,
}

/// The ring's consumer end, for a thread that needs every record (the logger).
pub struct RecordRx<T: Copy + Send + 'static> {
    ring: rtrb::Consumer<T>,
    counters: Arc<Counters>,
}

/// The latest-snapshot consumer end, for a thread that needs only the current
/// record (the display).
pub struct SnapshotRx<T: Copy + Send + 'static> {
    latest: triple_buffer::Output<T>,
}

/// The three ends of a telemetry channel: producer, ring consumer, snapshot consumer.
pub type TelemetryEnds<T> = (TelemetryTx<T>, RecordRx<T>, SnapshotRx<T>);

/// Memory cap of a telemetry ring sized by [`ring_capacity`]: 64 MiB (at 1 kHz the usual 2 s of
/// records are well under 1 MiB; the cap binds only at extreme rates).
pub const MAX_RING_BYTES: usize = 64 << 20;

/// Hard memory cap of any telemetry ring (1 GiB): [`telemetry_channel`] refuses a larger one.
pub const MAX_CHANNEL_BYTES: usize = 1 << 30;

/// Ring capacity (records of type `T`) holding `seconds` of records at `rate_hz`, at least
/// `min_records`, and at most `max_bytes` of memory (and at least 1 record). A non-finite or
/// negative product counts as the minimum, so no input can size an unbounded allocation.
///
/// Memory = capacity · `size_of::<T>()`; the cap is applied last, so it always holds.
pub fn ring_capacity<T>(rate_hz: f64, seconds: f64, min_records: usize, max_bytes: usize) -> usize {
    let want = rate_hz * seconds;
    let want = if want.is_finite() && want > 0.0 {
        // `as` saturates: a product above usize::MAX becomes usize::MAX, then the cap applies.
        want.ceil() as usize
    } else {
        0
    };
    let cap = max_bytes / std::mem::size_of::<T>().max(1);
    want.max(min_records).min(cap).max(1)
}

/// Creates a telemetry channel with a ring of `ring_capacity` records
/// (≥ 1; e.g. 2 s of records at the loop rate) and a snapshot initialised to
/// `initial`. Errors name the parameter.
pub fn telemetry_channel<T: Copy + Send + 'static>(
    ring_capacity: usize,
    initial: T,
) -> Result<TelemetryEnds<T>, String> {
    if ring_capacity == 0 {
        return Err(
            "ring_capacity = 0: the telemetry ring needs room for at least one record".into(),
        );
    }
    // However the caller sized it, the ring never takes more than MAX_CHANNEL_BYTES of memory.
    let bytes = ring_capacity.saturating_mul(std::mem::size_of::<T>());
    if ring_capacity > usize::MAX / 2 || bytes > MAX_CHANNEL_BYTES {
        return Err(format!(
            "ring_capacity = {ring_capacity} records ({bytes} bytes) is above the telemetry ring's cap of {MAX_CHANNEL_BYTES} bytes (1 GiB)"
        ));
    }
    let (producer, consumer) = rtrb::RingBuffer::new(ring_capacity);
    let (input, output) = triple_buffer::triple_buffer(&initial);
    let counters = Arc::new(Counters::default());
    Ok((
        TelemetryTx {
            ring: producer,
            latest: input,
            counters: counters.clone(),
        },
        RecordRx {
            ring: consumer,
            counters,
        },
        SnapshotRx { latest: output },
    ))
}

impl<T: Copy + Send + 'static> TelemetryTx<T> {
    /// Publishes `record` to both the ring and the snapshot. Wait-free; never
    /// allocates. Returns `false` if the ring was full and the record was
    /// dropped from it (the snapshot is updated regardless).
    #[inline]
    pub fn publish(&mut self, record: T) -> bool {
        self.latest.write(record);
        self.push(record)
    }

    /// Pushes `record` to the ring only; returns `false` (and counts a drop)
    /// when the ring is full. Wait-free.
    #[inline]
    pub fn push(&mut self, record: T) -> bool {
        self.counters.offered.fetch_add(1, Ordering::Relaxed);
        if self.ring.push(record).is_ok() {
            true
        } else {
            self.counters.dropped.fetch_add(1, Ordering::Relaxed);
            false
        }
    }

    /// Updates the latest snapshot only. Wait-free.
    #[inline]
    pub fn set_latest(&mut self, record: T) {
        self.latest.write(record);
    }

    /// Records offered to the ring so far.
    pub fn offered(&self) -> u64 {
        self.counters.offered.load(Ordering::Relaxed)
    }

    /// Records dropped from the ring so far because it was full.
    pub fn dropped(&self) -> u64 {
        self.counters.dropped.load(Ordering::Relaxed)
    }
}

impl<T: Copy + Send + 'static> RecordRx<T> {
    /// Takes the oldest record, if any.
    #[inline]
    pub fn pop(&mut self) -> Option<T> {
        self.ring.pop().ok()
    }

    /// Number of records waiting in the ring.
    pub fn len(&self) -> usize {
        self.ring.slots()
    }

    /// True when no record is waiting.
    pub fn is_empty(&self) -> bool {
        self.ring.is_empty()
    }

    /// True once the producer ([`TelemetryTx`]) has been dropped: after the
    /// ring is empty, no more records will come.
    pub fn is_producer_gone(&self) -> bool {
        self.ring.is_abandoned()
    }

    /// Records offered by the producer so far.
    pub fn offered(&self) -> u64 {
        self.counters.offered.load(Ordering::Acquire)
    }

    /// Records the producer dropped so far because the ring was full.
    pub fn dropped(&self) -> u64 {
        self.counters.dropped.load(Ordering::Acquire)
    }
}

impl<T: Copy + Send + 'static> SnapshotRx<T> {
    /// The most recent record published (or the initial one).
    pub fn latest(&mut self) -> T {
        *self.latest.read()
    }

    /// True if a record was published since the last [`latest`](Self::latest).
    pub fn has_new(&self) -> bool {
        self.latest.updated()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_ring_drops_and_counts_without_blocking() {
        let (mut tx, mut rx, mut snap) = telemetry_channel(4, 0u32).unwrap();
        for i in 1..=10u32 {
            tx.publish(i);
        }
        assert_eq!(tx.offered(), 10);
        assert_eq!(tx.dropped(), 6);
        let got: Vec<u32> = std::iter::from_fn(|| rx.pop()).collect();
        assert_eq!(got, vec![1, 2, 3, 4]);
        assert_eq!(snap.latest(), 10);
        assert!(!snap.has_new());
        assert!(!rx.is_producer_gone());
        drop(tx);
        assert!(rx.is_producer_gone());
        assert_eq!(rx.offered() - rx.dropped(), 4);
    }

    #[test]
    fn ring_capacity_is_bounded_by_the_memory_cap_at_any_rate() {
        #[derive(Clone, Copy)]
        #[allow(dead_code)] // only its size matters
        struct Big([u8; 312]);
        // `run --rate 1e9` asked for 2e9 records of 312 bytes (624 GB).
        for rate in [1e9, 1e300, f64::INFINITY, f64::NAN, -5.0] {
            let n = ring_capacity::<Big>(rate, 2.0, 4096, MAX_RING_BYTES);
            assert!(n >= 1);
            assert!(
                n * std::mem::size_of::<Big>() <= MAX_RING_BYTES,
                "rate {rate}: {n}"
            );
        }
        // Ordinary rates get their 2 s, or the minimum.
        assert_eq!(
            ring_capacity::<Big>(1000.0, 2.0, 4096, MAX_RING_BYTES),
            4096
        );
        assert_eq!(
            ring_capacity::<Big>(10_000.0, 2.0, 4096, MAX_RING_BYTES),
            20_000
        );
    }

    #[test]
    fn a_ring_above_the_byte_cap_is_an_error_not_an_allocation() {
        let too_many = MAX_CHANNEL_BYTES / 8 + 1;
        let e = telemetry_channel(too_many, 0u64).err().unwrap();
        assert!(e.contains("ring_capacity") && e.contains("cap"), "{e}");
        assert!(telemetry_channel(MAX_RING_BYTES / 8, 0u64).is_ok());
    }

    #[test]
    fn zero_capacity_is_an_error_naming_the_parameter() {
        assert!(telemetry_channel(0, 0u8)
            .err()
            .unwrap()
            .contains("ring_capacity"));
    }
}
