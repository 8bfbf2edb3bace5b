//! A network link with impairments, in simulated time: a fixed delay, uniform jitter, loss,
//! duplication and (through the jitter) reordering. Seeded and deterministic.
//!
//! A message sent at sample `k` arrives at `k + delay + j` (`j` uniform in `0..=jitter`), unless
//! it is lost; a duplicated message arrives twice (the copy one sample later). The receiver keeps
//! the newest message by sequence number, so a late, reordered or duplicated message never
//! replaces a newer one — what a real receiver with sequence numbers does.

use std::collections::VecDeque;

/// What the link does to messages. Delays in samples of the loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impairment {
    /// One-way delay (samples).
    pub delay: u32,
    /// Extra delay, uniform in `0..=jitter` (samples); above 0 it reorders messages.
    pub jitter: u32,
    /// Probability that a message is lost, in [0, 1].
    pub loss: f64,
    /// Probability that a message arrives twice, in [0, 1].
    pub duplicate: f64,
    /// Seed of the link's random numbers.
    pub seed: u64,
}

impl Impairment {
    /// A perfect link: no delay, no loss.
    pub const NONE: Impairment = Impairment {
        delay: 0,
        jitter: 0,
        loss: 0.0,
        duplicate: 0.0,
        seed: 1,
    };

    /// A link with a one-way `delay` (samples) and loss probability `loss`.
    pub fn delay_loss(delay: u32, loss: f64, seed: u64) -> Self {
        Impairment {
            delay,
            loss,
            seed,
            ..Self::NONE
        }
    }
}

/// One direction of a link carrying messages of type `T`.
#[derive(Clone, Debug)]
pub struct Link<T: Copy> {
    imp: Impairment,
    rng: u64,
    seq: u64,
    /// In flight: (arrival sample, sequence number, message), in send order.
    flight: VecDeque<(u64, u64, T)>,
    /// The newest message received so far and its sequence number.
    newest: Option<(u64, T)>,
    /// Messages lost so far.
    pub lost: u64,
    /// Messages received out of order or twice (kept out).
    pub stale: u64,
    /// Sequence number of the newest message [`Self::deliver`] handed out.
    delivered: u64,
}

impl<T: Copy> Link<T> {
    /// A link with impairment `imp`. Its queue is sized for everything that can be in flight
    /// (one message a sample, each held at most `delay + jitter` samples, plus its duplicate), so
    /// that sending and receiving never allocate: the link can sit in a real-time loop.
    pub fn new(imp: Impairment) -> Self {
        let in_flight = 2 * (imp.delay as usize + imp.jitter as usize + 2);
        Self {
            imp,
            rng: imp.seed ^ 0x9e37_79b9_7f4a_7c15,
            seq: 0,
            flight: VecDeque::with_capacity(in_flight),
            newest: None,
            lost: 0,
            stale: 0,
            delivered: 0,
        }
    }

    /// Uniform in [0, 1) (splitmix64).
    fn uniform(&mut self) -> f64 {
        self.rng = self.rng.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.rng;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Sends `msg` at sample `k`.
    pub fn send(&mut self, k: u64, msg: T) {
        self.seq += 1;
        if self.uniform() < self.imp.loss {
            self.lost += 1;
            return;
        }
        let jitter = if self.imp.jitter > 0 {
            (self.uniform() * (self.imp.jitter as f64 + 1.0)).floor() as u64
        } else {
            0
        };
        let at = k + self.imp.delay as u64 + jitter;
        self.flight.push_back((at, self.seq, msg));
        if self.uniform() < self.imp.duplicate {
            self.flight.push_back((at + 1, self.seq, msg));
        }
    }

    /// Delivers what has arrived by sample `k` and returns the newest message received so far
    /// (`None` before the first arrives).
    pub fn receive(&mut self, k: u64) -> Option<T> {
        let mut i = 0;
        while i < self.flight.len() {
            if self.flight[i].0 <= k {
                let Some((_, seq, msg)) = self.flight.remove(i) else {
                    break;
                };
                match self.newest {
                    Some((s, _)) if s >= seq => self.stale += 1,
                    _ => self.newest = Some((seq, msg)),
                }
            } else {
                i += 1;
            }
        }
        self.newest.map(|(_, m)| m)
    }
}

impl<T: Copy> Link<T> {
    /// As [`Self::receive`], but returns the newest message only the first time: `Some` when a
    /// message newer than any delivered before has arrived by sample `k`. For putting the
    /// impairment in front of a real socket: what this returns is what goes on the wire.
    pub fn deliver(&mut self, k: u64) -> Option<T> {
        let m = self.receive(k)?;
        let seq = self.newest.map_or(0, |(s, _)| s);
        if seq > self.delivered {
            self.delivered = seq;
            Some(m)
        } else {
            None
        }
    }

    /// True when nothing is in flight.
    pub fn is_idle(&self) -> bool {
        self.flight.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_message_arrives_after_exactly_the_delay() {
        let mut l = Link::new(Impairment::delay_loss(3, 0.0, 1));
        l.send(0, 7.0);
        for k in 0..3 {
            assert_eq!(l.receive(k), None, "sample {k}");
        }
        assert_eq!(l.receive(3), Some(7.0));
    }

    #[test]
    fn deliver_hands_out_each_newest_message_once_after_the_delay() {
        let mut l = Link::new(Impairment::delay_loss(2, 0.0, 1));
        l.send(0, 1.0);
        l.send(1, 2.0);
        assert_eq!(l.deliver(1), None);
        assert_eq!(l.deliver(2), Some(1.0));
        assert_eq!(l.deliver(2), None);
        assert_eq!(l.deliver(3), Some(2.0));
        assert_eq!(l.deliver(9), None);
        assert!(l.is_idle());
    }

    #[test]
    fn loss_drops_about_the_given_fraction() {
        let mut l = Link::new(Impairment::delay_loss(0, 0.1, 42));
        for k in 0..10_000 {
            l.send(k, k as f64);
        }
        assert!((800..1200).contains(&l.lost), "{}", l.lost);
    }

    #[test]
    fn reordered_or_duplicated_messages_never_replace_a_newer_one() {
        let imp = Impairment {
            jitter: 5,
            duplicate: 0.5,
            ..Impairment::delay_loss(2, 0.0, 7)
        };
        let mut l = Link::new(imp);
        let mut last = f64::NEG_INFINITY;
        for k in 0..2000u64 {
            l.send(k, k as f64);
            if let Some(v) = l.receive(k) {
                assert!(v >= last, "went back from {last} to {v} at {k}");
                last = v;
            }
        }
        assert!(
            l.stale > 0,
            "the jitter and duplicates produced no stale message"
        );
    }
}
