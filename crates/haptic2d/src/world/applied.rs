//! The applied wrenches of a sample: the scene's loads, evaluated once at `t = kT` and held over
//! the sample, and the drive (the slave drive `f_cs` of the teleoperation controller, or any user
//! force), held until changed (MODELS §0.5, "Addition (loads and drives before contact forces)").

use crate::body::Body;
use crate::contact::Wrench2;
use crate::geom::Vec2;
use crate::load::Load;

/// Loads and drive per body.
#[derive(Clone, Debug)]
pub(super) struct Applied {
    /// The drive wrench per body (N, N·m at the COM), held until changed.
    pub(super) drive: Vec<Wrench2>,
    /// The load wrench per body of the current sample.
    pub(super) held: Vec<Wrench2>,
}

impl Applied {
    /// No drive and no load on `n` bodies.
    pub(super) fn new(n: usize) -> Self {
        Self {
            drive: vec![Wrench2::default(); n],
            held: vec![Wrench2::default(); n],
        }
    }

    /// Evaluates the loads at time `t` (s) and sets each body's force accumulator to its load plus
    /// its drive, before the contact forces, so the classical friction model sees them (§4.1). A
    /// fixed body's velocity is set to zero: one set through the public fields would make its
    /// surfaces move in the contacts' eyes and feed energy in.
    pub(super) fn evaluate(&mut self, loads: &[Load], bodies: &mut [Body], t: f64) {
        for h in self.held.iter_mut() {
            *h = Wrench2::default();
        }
        for l in loads {
            let (f, tau) = l.wrench(&bodies[l.body], t);
            self.held[l.body].force += f;
            self.held[l.body].torque += tau;
        }
        for ((b, d), h) in bodies.iter_mut().zip(&self.drive).zip(&self.held) {
            b.force = d.force + h.force;
            b.torque = d.torque + h.torque;
            if !b.is_dynamic() {
                b.vel = Vec2::ZERO;
                b.omega = 0.0;
            }
        }
    }

    /// The applied wrench on body `i` now: its held load plus its drive as it is now (re-read, so
    /// a drive set after `begin_step` counts).
    #[inline]
    pub(super) fn wrench(&self, i: usize) -> Wrench2 {
        Wrench2 {
            force: self.held[i].force + self.drive[i].force,
            torque: self.held[i].torque + self.drive[i].torque,
        }
    }
}
