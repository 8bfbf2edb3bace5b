//! `haptic2d teleop --live` (docs/TELEOP.md, "Two devices in real time"): bilateral
//! teleoperation of two devices — any two of the simulated twin, a Haply board, a UDP device, an
//! Inverse3 — in one real-time loop (`haptic2d_rt::run_loop`, 1 kHz), position–force with TDPA on
//! both ports, across the in-process impaired link of the lab (`--delay-ms`, `--loss`, `--seed`).
//! Every period:
//!
//! ```text
//! read master, read slave                 a lost device: zero both, stop (exit 4, naming it)
//! sense both (DeviceEnd: stall on the loop's own time, plausibility, pose, singularity)
//! master: newest (−F_c', E_in,s') → TDPA → DeviceEnd::actuate (ramp, wall, clamp, gate) → book
//!         send (x_m, v_m, E_in,m) ─── Link (delay, loss) ──►
//! slave:  newest (x_m', v_m', E_in,m') → F_c = K·(x_m' − x_s) + B·(v_m' − v_s) → TDPA → actuate
//!         → book; send (−F_c, E_in,s) ─── Link ──► master
//! a latch at either end: zero BOTH in this tick, stop (exit 3); else write both
//! ```
//!
//! Positions are from each device's origin (its first valid reading), on the axes both devices
//! render (x, y; θ too between two twins), in each device's own frame: the two frames must point
//! the same way. Velocities are the unfiltered rate of the measured pose over the period, as in the
//! lab's teleop. The tick allocates nothing once the link's queues have grown to the delay (the
//! lab's `Link` keeps its messages in a `VecDeque` that grows during the first `delay` ticks: 8
//! allocations at 25 ms each way, counted in `tests::once_the_link_is_full_a_tick_allocates_nothing`).

use std::sync::atomic::Ordering;
use std::time::Duration;

use haptic2d::device::linalg::V3;
use haptic2d::haptic::SafetyTrip;
use haptic2d_lab::network::{Impairment, Link};
use haptic2d_rt::{DeviceError, LoopConfig, TickControl, TickInfo, TickInterval};

use crate::cmd_teleop::{ArchitectureArg, TeleopArgs};
use crate::exit::{Failure, Status};
use crate::push_arg::Push;
use crate::teleop_end::{LiveEnd, Role};

/// The simulated master's push when `--push` is not given: the lab teleop's (15 mm left at
/// 50 mm/s from 0.6 s, after the 0.5 s ramp).
pub const DEFAULT_PUSH: &str = "-0.015,0,0.05,0.6";

/// Master → slave: the master's pose from its origin, its rate, its port's energy in.
#[derive(Clone, Copy, Debug)]
struct Up {
    x: V3,
    v: V3,
    e_in: V3,
}

/// Slave → master: the force for the master (`−F_c`), the slave port's energy in.
#[derive(Clone, Copy, Debug)]
struct Down {
    f: V3,
    e_in: V3,
}

/// Why the loop stopped before its duration.
#[derive(Debug)]
pub enum LiveStop {
    /// A safety latch at this end (the other end was zeroed in the same tick).
    Latch(Role, SafetyTrip),
    /// This end's device was lost (the other end was zeroed in the same tick).
    Lost(Role, DeviceError),
    /// `run` consecutive ticks missed their deadline, reaching this end's device file's limit
    /// (both ends zeroed in that tick).
    Missed {
        /// The end whose limit it was.
        role: Role,
        /// Consecutive ticks that missed.
        run: u32,
        /// The limit.
        limit: u32,
    },
}

/// The slave's contact with the simulated wall (see [`LiveEnd::contact`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Contact {
    /// Largest wall force on the slave (N).
    pub max_wall: f64,
    /// Deepest penetration (m).
    pub max_pen: f64,
    /// Over the last second, the ticks in contact: their count, the sum of the wall's force and of
    /// the master's force along x (N).
    pub n: u64,
    pub wall_sum: f64,
    pub master_sum: f64,
}

/// The loop's state, owned by the loop thread.
pub struct Live {
    /// The master device.
    pub m: LiveEnd,
    /// The slave device.
    pub s: LiveEnd,
    up: Link<Up>,
    down: Link<Down>,
    /// Coupling stiffness (N/m, N/m, N·m/rad) and damping (N·s/m, N·s/m, N·m·s/rad), zero on an
    /// axis one of the devices does not render.
    k: V3,
    b: V3,
    /// The axes both devices render.
    pub axes: [bool; 3],
    tdpa: bool,
    dt: f64,
    /// Time from which the contact is averaged (s): the last second.
    tail_from: f64,
    interval: TickInterval,
    /// The previous tick's wait for both devices (ns).
    prev_wait_ns: u64,
    /// Consecutive ticks that missed their deadline (the watchdog of `run`).
    missed_run: u32,
    /// Slave contact (a simulated slave only).
    pub contact: Option<Contact>,
    /// Why and when (s) it stopped, if the tick stopped it.
    pub stop: Option<(f64, LiveStop)>,
}

impl Live {
    /// Both ends, the link `link` (each way; the slave's direction seeded with `seed + 1`), the
    /// coupling `(stiffness, damping)` on x and y (θ: the lab's 1 N·m/rad, 0.01 N·m·s/rad),
    /// `tdpa`, period `dt` (s), run length `duration` (s).
    pub fn new(
        m: LiveEnd,
        s: LiveEnd,
        link: Impairment,
        coupling: (f64, f64),
        tdpa: bool,
        dt: f64,
        duration: f64,
    ) -> Self {
        let (am, as_) = (m.end.axes(), s.end.axes());
        let axes: [bool; 3] = std::array::from_fn(|i| am[i] && as_[i]);
        let on = |v: [f64; 3]| -> V3 { std::array::from_fn(|i| if axes[i] { v[i] } else { 0.0 }) };
        let (kc, bc) = coupling;
        let contact = s.contact().map(|_| Contact::default());
        Self {
            m,
            s,
            up: Link::new(link),
            down: Link::new(Impairment {
                seed: link.seed.wrapping_add(1),
                ..link
            }),
            k: on([kc, kc, 1.0]),
            b: on([bc, bc, 0.01]),
            axes,
            tdpa,
            dt,
            tail_from: duration - 1.0,
            interval: TickInterval::new(),
            prev_wait_ns: 0,
            missed_run: 0,
            contact,
            stop: None,
        }
    }

    /// One period (see the module doc). Never allocates (but see the module doc on the link),
    /// locks or prints; a stop builds its reason (the lost device's message) once.
    pub fn tick(&mut self, info: &TickInfo) -> TickControl {
        let (k, t, dt) = (info.deadline_index, info.t_s, self.dt);
        let at = (k, t);
        let elapsed = self.interval.update(info) as f64 * 1e-9;
        let wait = self.prev_wait_ns as f64 * 1e-9;
        if let Some(stop) = self.watch_deadlines(info) {
            self.m.zero(Some(t));
            self.s.zero(Some(t));
            self.stop.get_or_insert((t, stop));
            return TickControl::Stop;
        }
        let qm = match self.m.read(t) {
            Ok(q) => q,
            Err(e) => return self.lost(t, Role::Master, e),
        };
        let qs = match self.s.read(t) {
            Ok(q) => q,
            Err(e) => return self.lost(t, Role::Slave, e),
        };
        self.prev_wait_ns = self.m.read_wait_ns() + self.s.read_wait_ns();
        let sm = self.m.sense(at, &qm, elapsed, wait, dt);
        let ss = self.s.sense(at, &qs, elapsed, wait, dt);
        // Master: the newest message from the slave through its port.
        let (f_req, far_s) = self
            .down
            .receive(k)
            .map_or(([0.0; 3], [0.0; 3]), |d| (d.f, d.e_in));
        let f_m = self.m.drive(at, &f_req, &far_s, self.tdpa, dt);
        if let Some((x, v)) = sm {
            let e_in = self.m.port.energy_in();
            self.up.send(k, Up { x, v, e_in });
        }
        // Slave: the coupling to the newest master state, through its port.
        let newest = self.up.receive(k);
        let far_m = newest.map_or([0.0; 3], |u| u.e_in);
        let f_c: V3 = match (newest, ss) {
            (Some(u), Some((xs, vs))) => {
                std::array::from_fn(|i| self.k[i] * (u.x[i] - xs[i]) + self.b[i] * (u.v[i] - vs[i]))
            }
            _ => [0.0; 3],
        };
        self.s.drive(at, &f_c, &far_m, self.tdpa, dt);
        let e_in = self.s.port.energy_in();
        self.down.send(
            k,
            Down {
                f: f_c.map(|f| -f),
                e_in,
            },
        );
        self.book_contact(t, f_m[0]);
        // A latch at either end zeroes both in this tick.
        let trip = (self.m.end.trip_info().map(|r| (Role::Master, r)))
            .or_else(|| self.s.end.trip_info().map(|r| (Role::Slave, r)));
        if let Some((role, trip)) = trip {
            self.m.zero(Some(t));
            self.s.zero(Some(t));
            self.stop.get_or_insert((t, LiveStop::Latch(role, trip)));
            return TickControl::Stop;
        }
        if let Err(e) = self.m.write(t) {
            return self.lost(t, Role::Master, e);
        }
        if let Err(e) = self.s.write(t) {
            return self.lost(t, Role::Slave, e);
        }
        TickControl::Continue
    }

    /// Counts consecutive ticks that missed their deadline; the stop when the count reaches a real
    /// device's limit (its device file's `max_missed_deadlines`, as `run`'s watchdog).
    fn watch_deadlines(&mut self, info: &TickInfo) -> Option<LiveStop> {
        self.missed_run = if info.missed_deadline() {
            self.missed_run.saturating_add(1)
        } else {
            0
        };
        [&self.m, &self.s].into_iter().find_map(|e| {
            let limit = e.max_missed_run?;
            (self.missed_run >= limit).then_some(LiveStop::Missed {
                role: e.role,
                run: self.missed_run,
                limit,
            })
        })
    }

    /// The simulated slave's wall contact at time `t` (s), with the master's force `f_mx` (N, x).
    fn book_contact(&mut self, t: f64, f_mx: f64) {
        let (Some(c), Some((f_wall, pen))) = (self.contact.as_mut(), self.s.contact()) else {
            return;
        };
        c.max_wall = c.max_wall.max(f_wall);
        c.max_pen = c.max_pen.max(pen);
        if t >= self.tail_from && f_wall > 0.0 {
            c.n += 1;
            c.wall_sum += f_wall;
            c.master_sum += f_mx;
        }
    }

    /// `role`'s device was lost with `e`: both ends zeroed (the lost one best effort), stop.
    fn lost(&mut self, t: f64, role: Role, e: DeviceError) -> TickControl {
        self.m.zero(Some(t));
        self.s.zero(Some(t));
        self.stop.get_or_insert((t, LiveStop::Lost(role, e)));
        TickControl::Stop
    }

    /// The link's counters: (lost, stale) master → slave and slave → master.
    pub fn link_counters(&self) -> [(u64, u64); 2] {
        [
            (self.up.lost, self.up.stale),
            (self.down.lost, self.down.stale),
        ]
    }
}

/// Checks the options `teleop --live` does not take; the reason says why.
fn refuse_sim_only(a: &TeleopArgs) -> Result<(), Failure> {
    let refuse = |what: &str, why: &str| {
        Err(Failure::from(format!(
            "teleop --live: {what} {why}\n    fix: leave it out, or run two simulated devices without --live"
        )))
    };
    if a.architecture == ArchitectureArg::FourChannel {
        return refuse(
            "--architecture four-channel",
            "needs the hand's force at the master and the environment's at the slave, measured: the twin pantograph, the Haply boards, the UDP devices and the Inverse3 have no force sensor at the handle (their hand force is an observer's estimate, MODELS §10.6; docs/TELEOP.md, the four-channel section)",
        );
    }
    if a.filtered_velocity {
        return refuse("--filtered-velocity", "is the simulated run's study of the 10 ms chatter; the live loop uses the unfiltered rate");
    }
    if a.stability || a.figures.is_some() {
        return refuse("--stability / --figures", "are analyses, not runs");
    }
    if a.push.is_some() && a.master != "sim" {
        return refuse(
            "--push",
            "moves the simulated master's grip: it needs --master sim",
        );
    }
    Ok(())
}

/// Runs `teleop --live` with the link `link` (checked by the caller).
pub fn run(a: &TeleopArgs, link: Impairment) -> Result<Status, Failure> {
    refuse_sim_only(a)?;
    let dt = 1e-3;
    let push = match (a.master.as_str(), &a.push) {
        ("sim", p) => {
            Some(Push::parse(p.as_deref().unwrap_or(DEFAULT_PUSH)).map_err(Failure::from)?)
        }
        _ => None,
    };
    let file = |f: &Option<std::path::PathBuf>| f.as_deref().map(|p| p.to_path_buf());
    let (mf, sf) = (file(&a.master_device_file), file(&a.slave_device_file));
    let m = LiveEnd::open(
        Role::Master,
        &a.master,
        mf.as_deref(),
        a.allow_remote_device,
        push,
        dt,
    )?;
    let s = LiveEnd::open(
        Role::Slave,
        &a.slave,
        sf.as_deref(),
        a.allow_remote_device,
        None,
        dt,
    )?;
    let stop = haptic2d_rt::signal::install_stop_signals().map_err(Failure::error)?;
    let coupling = (a.stiffness, a.damping);
    let mut live = Live::new(m, s, link, coupling, !a.no_tdpa, dt, a.duration);
    crate::teleop_report::start_line(&live, a, link);
    let config = LoopConfig {
        rate_hz: 1.0 / dt,
        duration: Some(Duration::from_secs_f64(a.duration)),
        rt: !a.no_rt,
        spin_us: 400.0,
        ..LoopConfig::default()
    };
    config.validate().map_err(Failure::from)?;
    let summary = crate::rt_thread::run_on_rt_thread(&config, &stop, |info| live.tick(&info));
    // Whatever ended the loop (the duration, a signal, a stop, a failure): both at zero.
    live.m.zero(None);
    live.s.zero(None);
    let summary = summary?;
    Ok(crate::teleop_report::report(
        &live,
        &summary,
        stop.load(Ordering::Relaxed),
    ))
}

#[cfg(test)]
#[path = "teleop_live_tests.rs"]
mod tests;
