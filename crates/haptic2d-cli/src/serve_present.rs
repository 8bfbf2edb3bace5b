//! The study server's side of the real-time loop (`haptic2d study serve`, `study_serve.rs`): the
//! per-tick state machine that presents one stimulus a client asked for and measures what the
//! probe felt in the interval. It runs inside the haptic tick: no allocation, no lock, no I/O.
//!
//! Per presentation (a [`Request`], its laws built on the main thread):
//!
//! 1. **waiting**: the stimulus (wall law and friction model) is installed at the first tick in
//!    which the probe has **no contact record** (as the browser study's
//!    [`Presenter`](crate::study_present::Presenter)): its contact force is zero before and after the
//!    switch, so the switch cannot step the force the participant feels. If the probe does not
//!    leave contact within [`FREE_SPACE_WAIT_S`] of loop time, the request fails with that reason.
//! 2. **presenting**: for `duration_s` of loop time (paused ticks do not count), or until the
//!    client's `end`, each tick's contact force on the probe and its deepest penetration are
//!    measured after the world step ([`Measured`]).
//! 3. **returning**: the study's neutral stimulus (the first condition's reference, the one the loop
//!    starts with) is installed again at the first tick the probe is in free space; a new request
//!    in the meantime is installed instead (also only in free space).
//!
//! The torques start at zero and ramp in when the loop starts, are clamped, and are zeroed and
//! latched on a stall, a lost device or a safety trip: the rig's own safety, unchanged.

use crate::study_present::in_free_space;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NormalModel;
use haptic2d::world::World;

/// Longest wait (s of loop time) for the probe to leave contact before a stimulus is installed.
pub const FREE_SPACE_WAIT_S: f64 = 10.0;

/// A stimulus: wall law and friction model.
pub type Laws = (NormalModel, FrictionModel);

/// One presentation a client asked for, prepared off the loop thread.
#[derive(Clone, Copy, Debug)]
pub struct Request {
    /// The server's number of the presentation (from 1).
    pub id: u32,
    /// The stimulus.
    pub laws: Laws,
    /// Exploration time (s of loop time); `None`: until the client's `end`.
    pub duration_s: Option<f64>,
}

/// What the main thread sends the loop.
// Every slot of the ring is the size of a request anyway; boxing it would allocate per request.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum ToLoop {
    /// Present a stimulus.
    Present(Request),
    /// End presentation `id` now (or give it up while it waits for free space).
    End(u32),
}

/// What the probe felt in one interval.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measured {
    /// Loop time (s) of the tick that installed the stimulus.
    pub start_s: f64,
    /// Loop time (s) of the tick that ended the interval.
    pub end_s: f64,
    /// Largest contact force magnitude on the probe (N; normal plus friction, as
    /// `World::contact_wrench`).
    pub peak_force_n: f64,
    /// Sum of the contact force over the ticks with contact force (N).
    pub force_sum_n: f64,
    /// Ticks with a nonzero contact force on the probe.
    pub contact_ticks: u64,
    /// Ticks in the interval (not paused).
    pub ticks: u64,
    /// Deepest penetration of the probe into anything (m, `max(0, −d)` of its contact records).
    pub deepest_m: f64,
    /// Time with a nonzero contact force (s).
    pub contact_s: f64,
}

impl Measured {
    /// Mean contact force over the time in contact (N; 0 without contact).
    pub fn mean_force_n(&self) -> f64 {
        if self.contact_ticks == 0 {
            0.0
        } else {
            self.force_sum_n / self.contact_ticks as f64
        }
    }
}

/// What the loop reports to the main thread.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FromLoop {
    /// Presentation `id`'s stimulus was installed at loop time `t_s` (s).
    Started {
        /// The presentation.
        id: u32,
        /// Loop time (s).
        t_s: f64,
    },
    /// Presentation `id` ended; what the probe felt.
    Done {
        /// The presentation.
        id: u32,
        /// The measures.
        measured: Measured,
    },
    /// Presentation `id` never started: the probe stayed in contact for `waited_s` seconds (or the
    /// client ended it first).
    NotFree {
        /// The presentation.
        id: u32,
        /// Loop time waited (s).
        waited_s: f64,
    },
    /// A request arrived while another ran (the main thread prevents it; the loop checks again).
    Busy {
        /// The refused presentation.
        id: u32,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Idle,
    Waiting { waited_s: f64 },
    Presenting { elapsed_s: f64 },
    Returning,
}

/// The state machine (see the module documentation).
#[derive(Clone, Debug)]
pub struct ServePresenter {
    neutral: Laws,
    phase: Phase,
    request: Option<Request>,
    measured: Measured,
    end_asked: bool,
}

impl ServePresenter {
    /// A presenter returning to `neutral` between presentations.
    pub fn new(neutral: Laws) -> Self {
        Self {
            neutral,
            phase: Phase::Idle,
            request: None,
            measured: Measured::default(),
            end_asked: false,
        }
    }

    /// The presentation whose interval runs (its stimulus installed), if any.
    #[cfg(test)]
    pub fn presenting(&self) -> Option<u32> {
        match self.phase {
            Phase::Presenting { .. } => self.request.map(|r| r.id),
            _ => None,
        }
    }

    /// Before the world step of a tick at loop time `t_s` (s) of `dt` seconds, `paused` or not:
    /// takes the main thread's command `cmd`, installs a stimulus in `world` (only with `slave` in
    /// free space) and ends an interval that is over. Allocation-free.
    pub fn before_step(
        &mut self,
        cmd: Option<ToLoop>,
        world: &mut World,
        slave: usize,
        t_s: f64,
        dt: f64,
        paused: bool,
    ) -> Option<FromLoop> {
        match cmd {
            Some(ToLoop::Present(r)) => match self.phase {
                Phase::Idle | Phase::Returning => {
                    self.request = Some(r);
                    self.end_asked = false;
                    self.phase = Phase::Waiting { waited_s: 0.0 };
                }
                _ => return Some(FromLoop::Busy { id: r.id }),
            },
            Some(ToLoop::End(id)) if self.request.is_some_and(|r| r.id == id) => {
                self.end_asked = true;
            }
            _ => {}
        }
        let req = self.request?;
        let free = !paused && in_free_space(world, slave);
        match self.phase {
            Phase::Waiting { waited_s } => {
                if free && !self.end_asked {
                    (world.normal, world.friction) = req.laws;
                    self.measured = Measured {
                        start_s: t_s,
                        ..Measured::default()
                    };
                    self.phase = Phase::Presenting { elapsed_s: 0.0 };
                    return Some(FromLoop::Started { id: req.id, t_s });
                }
                let waited_s = waited_s + if paused { 0.0 } else { dt };
                if self.end_asked || waited_s > FREE_SPACE_WAIT_S {
                    self.phase = Phase::Idle;
                    self.request = None;
                    return Some(FromLoop::NotFree {
                        id: req.id,
                        waited_s,
                    });
                }
                self.phase = Phase::Waiting { waited_s };
            }
            Phase::Presenting { elapsed_s } => {
                let over = req.duration_s.is_some_and(|d| elapsed_s >= d - 0.5 * dt);
                if over || self.end_asked {
                    self.measured.end_s = t_s;
                    self.phase = Phase::Returning;
                    return Some(FromLoop::Done {
                        id: req.id,
                        measured: self.measured,
                    });
                }
            }
            Phase::Returning => {
                if free {
                    (world.normal, world.friction) = self.neutral;
                    self.phase = Phase::Idle;
                    self.request = None;
                }
            }
            Phase::Idle => {}
        }
        None
    }

    /// After the world step of a tick of `dt` seconds: measures the probe `slave` while an interval
    /// runs (not while `paused`). Allocation-free.
    pub fn after_step(&mut self, world: &World, slave: usize, dt: f64, paused: bool) {
        let Phase::Presenting { elapsed_s } = self.phase else {
            return;
        };
        if paused {
            return;
        }
        self.phase = Phase::Presenting {
            elapsed_s: elapsed_s + dt,
        };
        let m = &mut self.measured;
        let w = world.contact_wrench(slave);
        let f = w.force.x.hypot(w.force.y);
        m.ticks += 1;
        m.peak_force_n = m.peak_force_n.max(f);
        if f > 0.0 {
            m.force_sum_n += f;
            m.contact_ticks += 1;
            m.contact_s += dt;
        }
        for c in world.contact_records() {
            if c.body_a == slave || c.body_b == slave {
                m.deepest_m = m.deepest_m.max(-c.d[0]);
            }
        }
    }
}

#[cfg(test)]
#[path = "serve_present_tests.rs"]
mod tests;
