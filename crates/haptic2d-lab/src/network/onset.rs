//! The simulated onset of instability of the delayed teleoperation loop (issue 41 item 4): the
//! nonlinear run of [`super::teleop`] without TDPA and without loss, bisected over the one-way
//! delay, to check the linear analysis of `stability::delayed` against (docs/TELEOP.md, "The
//! delayed loop's stability").
//!
//! A run **oscillates** if the master–slave separation along x swings by more than
//! [`SWING_UNSTABLE`] peak-to-peak over its last second, or a device fault stops it. In steady
//! contact the separation is the coupling's static deflection plus the encoders' quantisation:
//! at most 0.029 mm of swing in the default run at every one-way delay from 0 to 8 and at 10 ms;
//! the oscillating runs swing 0.43 mm (9 ms) and 0.88–1.5 mm (11–14 ms). The threshold, 0.1 mm,
//! lies in that gap (measured with the default `Teleop`, no TDPA, 3 s).

use super::link::Impairment;
use super::teleop::{run_teleop, Teleop};

/// Peak-to-peak separation over the last second above which a run oscillates (m).
pub const SWING_UNSTABLE: f64 = 1e-4;

/// The bracket the bisection found: one-way delays in samples of the link (the round trip is
/// twice them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Onset {
    /// The largest one-way delay tried that does not oscillate.
    pub last_stable: u32,
    /// The smallest one-way delay tried that oscillates (`last_stable + 1`).
    pub first_unstable: u32,
}

/// Whether `base` (its TDPA and loss replaced: off, none) oscillates at a one-way delay of
/// `delay` samples.
pub fn oscillates(base: &Teleop, delay: u32) -> Result<bool, String> {
    let cfg = Teleop {
        link: Impairment::delay_loss(delay, 0.0, base.link.seed),
        tdpa: false,
        ..*base
    };
    let r = run_teleop(&cfg)?;
    Ok(r.fault.is_some() || r.swing > SWING_UNSTABLE)
}

/// Bisects the one-way delay over `0..=max_delay` for the onset of oscillation, assuming one
/// crossing. `None` if the run oscillates without delay or does not at `max_delay`.
pub fn simulated_onset(base: &Teleop, max_delay: u32) -> Result<Option<Onset>, String> {
    if oscillates(base, 0)? || !oscillates(base, max_delay)? {
        return Ok(None);
    }
    let (mut lo, mut hi) = (0, max_delay);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if oscillates(base, mid)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(Some(Onset {
        last_stable: lo,
        first_unstable: hi,
    }))
}
