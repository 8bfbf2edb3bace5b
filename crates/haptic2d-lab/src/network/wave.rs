//! Wave variables on the link (Niemeyer & Slotine 1991, 2004), the named alternative to TDPA, one
//! axis, with a drift compensation that spends only the wave energy the link has not delivered.
//!
//! # The transform
//!
//! With a wave impedance `b` (N·s/m), a port's velocity `ẋ` (m/s) and the force `F` (N) it pushes
//! the link with become two waves, one travelling each way:
//!
//! ```text
//! u = (b·ẋ + F)/√(2b)    (master → slave)       w = (b·ẋ − F)/√(2b)    (slave → master)
//! ```
//!
//! so that the port's power is `ẋ·F = ½u² − ½w²` (W): what a wave carries is its own energy,
//! `½u²` per second. A constant delay only stores waves, so the link is passive for any constant
//! delay (Niemeyer & Slotine, "Stable adaptive teleoperation", IEEE J. Oceanic Eng. 16(1), 1991;
//! "Telemanipulation with time delays", IJRR 23(9), 2004).
//!
//! - **Master side** ([`WaveMaster`]): it knows `ẋ_m` and receives `w_m`; it pushes the link with
//!   `F_m = b·ẋ_m − √(2b)·w_m` (the handle feels `−F_m`) and sends `u_m = √(2b)·ẋ_m − w_m`.
//! - **Slave side** ([`WaveSlave`]): it receives `u_s`; the link commands the velocity
//!   `ẋ_d = (√(2b)·u_s − F_s)/b` of a point `x_d` that pulls the slave body through a coupling
//!   (`F_s = K·(x_d − x_s) + B·(ẋ_d − v_s)`, solved together with `ẋ_d`, no algebraic loop left);
//!   it sends `w_s = u_s − √(2/b)·F_s`.
//!
//! # Loss, jitter, reordering: an energy budget on each wave
//!
//! A side uses the newest wave it has received, and keeps using it while no newer one arrives (a
//! lost message holds the last wave, as a held force would be). Each side also sends the wave energy it has put on the link so
//! far, `E_sent = Σ ½u²·T` (J); the receiving side never uses more, `Σ ½u_used²·T ≤ E_sent`
//! (received): a wave it would use is scaled down to fit. Then the network's energy
//! `∫(P_out,slave − P_in,master) = (Σ½u_s² − Σ½u_m²)·T + (Σ½w_m² − Σ½w_s²)·T ≤ 0` whatever the
//! link does to the messages: passive for any delay, loss, jitter or reordering.
//!
//! # Drift compensation
//!
//! Waves carry velocity and force, not position: a lost wave, or the force history in a contact
//! (`x_d(t) = x_m(t−T) + (p_m(t−T) − p_s(t))/b`, `p = ∫F dt`; Niemeyer & Slotine 2004, §4), leaves
//! the slave's reference `x_d` away from the master's position. The master also sends `x_m`; the
//! slave adds the correction `λ·(x_m − x_d)` to the commanded velocity, i.e. it uses the wave
//! `u' = u + λ·(x_m − x_d)·√(b/2)`, still under the energy budget above: the correction is paid
//! from the wave energy the master sent but the slave has not used (what loss and the contact
//! left over), so it never makes the link active. This is the position correction of wave
//! integrals (Niemeyer & Slotine 2004) done as a budgeted drift compensation (after Secchi,
//! Stramigioli & Fantuzzi, "Position drift compensation in port-Hamiltonian based
//! telemanipulation", IROS 2006, where an energy tank pays the correction). No allocation.

/// The wave link's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaveParams {
    /// Wave impedance `b` (N·s/m): the damping a port feels in free motion, and the stiffness
    /// scale of the link (larger: stiffer contacts, heavier free motion).
    pub b: f64,
    /// Drift compensation gain `λ` (1/s): the bandwidth with which `x_d` is pulled back to the
    /// master's position; 0 turns it off.
    pub drift_gain: f64,
}

impl Default for WaveParams {
    /// `b = 20 N·s/m`, `λ = 5 /s`: chosen on the lab's runs (docs/TELEOP.md). `λ = 2 /s` barely
    /// corrected the free-motion drift at a 200 ms round trip (0.68 mm against 0.81 mm without);
    /// `λ = 5 /s` does (0.06 mm) at the cost of force tracking in a lossy contact (0.44 N against
    /// 0.09 N without at 50 ms, 5 %); `b = 80 N·s/m` went unstable on the wall run.
    fn default() -> Self {
        Self {
            b: 20.0,
            drift_gain: 5.0,
        }
    }
}

/// What a wave side sends: its sample index, the wave sample, the wave energy it has sent so far
/// (J), and its position (m; used by the slave for the drift compensation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WaveMsg {
    /// The wave sample (√W).
    pub wave: f64,
    /// `Σ ½·wave²·T` over every sample sent so far, this one included (J).
    pub energy: f64,
    /// The sender's position (m): the master's `x_m`; the slave sends its `x_d`.
    pub x: f64,
}

/// The receiving end's energy budget: never use more wave energy than the sender sent.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WaveBudget {
    /// Wave energy used so far (J).
    used: f64,
    /// Wave energy the budget cut off so far (J).
    cut: f64,
}

impl WaveBudget {
    /// The wave `wanted` scaled down so that the energy used stays within `sent` (J), booked.
    pub fn spend(&mut self, wanted: f64, sent: f64, dt: f64) -> f64 {
        if !(wanted.is_finite() && sent.is_finite() && dt > 0.0) {
            return 0.0;
        }
        let room = (sent - self.used).max(0.0);
        let e = 0.5 * wanted * wanted * dt;
        let w = if e <= room {
            wanted
        } else {
            self.cut += e - room;
            wanted.signum() * (2.0 * room / dt).sqrt()
        };
        self.used += 0.5 * w * w * dt;
        w
    }

    /// Corrects the last [`Self::spend`]: the port really drew the wave `drawn` where `spent` was
    /// granted (a force that saturated, was ramped or gated); books the difference of their
    /// energies over `dt` (s). More drawn than granted is a debt: the room left shrinks, and
    /// the next samples get less until the sender has sent more.
    pub fn rebook(&mut self, spent: f64, drawn: f64, dt: f64) {
        if spent.is_finite() && drawn.is_finite() && dt > 0.0 {
            self.used += 0.5 * (drawn * drawn - spent * spent) * dt;
        }
    }

    /// Wave energy used so far (J).
    pub fn used(&self) -> f64 {
        self.used
    }

    /// Wave energy the budget refused so far (J).
    pub fn cut(&self) -> f64 {
        self.cut
    }
}

/// The master side of a wave link, one axis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WaveMaster {
    p: WaveParams,
    budget: WaveBudget,
    sent: f64,
    /// The newest returning wave and the slave's wave energy sent, as received.
    last: WaveMsg,
    /// The returning wave granted by the budget in the last [`WaveMaster::force`] (√W).
    w: f64,
}

impl WaveMaster {
    /// A master side with nothing sent.
    pub fn new(p: WaveParams) -> Self {
        Self {
            p,
            ..Self::default()
        }
    }

    /// One sample of `dt` (s): the handle at `x` (m) moving at `v` (m/s), `msg` the slave's
    /// newest wave if one arrived this sample. Returns the force on the handle (N, `−F_m`) and the
    /// message to send.
    pub fn step(&mut self, x: f64, v: f64, msg: Option<WaveMsg>, dt: f64) -> (f64, WaveMsg) {
        let f = self.force(v, msg, dt);
        (f, self.book(x, v, f, dt))
    }

    /// The force alone, for a caller that may apply less than it returns (a device whose torques
    /// saturate, a start-up ramp, a safety gate): the force on the handle (N, `−F_m`) from the
    /// newest returning wave within its budget, with the handle moving at `v` (m/s). Then book
    /// what was really applied with [`Self::book`].
    pub fn force(&mut self, v: f64, msg: Option<WaveMsg>, dt: f64) -> f64 {
        let b = self.p.b;
        if let Some(m) = msg.filter(|m| m.wave.is_finite() && m.energy.is_finite()) {
            self.last = m;
        }
        self.w = self.budget.spend(self.last.wave, self.last.energy, dt);
        let v = if v.is_finite() { v } else { 0.0 };
        -(b * v - (2.0 * b).sqrt() * self.w)
    }

    /// Books the sample in which `applied` (N) really acted on the handle at `x` (m) moving at `v`
    /// (m/s) — the force of [`Self::force`], or less — and returns the message to send. The wave
    /// sent and the returning wave drawn are those of the force really applied,
    /// `u = (b·v − applied)/√(2b)`, `w = (b·v + applied)/√(2b)`, so that the port's power is
    /// exactly `½u² − ½w²`; a drawn wave larger than the budget granted is booked as a debt
    /// ([`WaveBudget::rebook`]).
    pub fn book(&mut self, x: f64, v: f64, applied: f64, dt: f64) -> WaveMsg {
        let b = self.p.b;
        let (v, applied) = (
            if v.is_finite() { v } else { 0.0 },
            if applied.is_finite() { applied } else { 0.0 },
        );
        let u = (b * v - applied) / (2.0 * b).sqrt();
        let drawn = (b * v + applied) / (2.0 * b).sqrt();
        self.budget.rebook(self.w, drawn, dt);
        self.sent += 0.5 * u * u * dt;
        WaveMsg {
            wave: u,
            energy: self.sent,
            x,
        }
    }

    /// The returning waves' budget (energy used and cut).
    pub fn budget(&self) -> WaveBudget {
        self.budget
    }
}

/// The slave side of a wave link, one axis: the commanded point `x_d` and its coupling to the
/// slave body.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WaveSlave {
    p: WaveParams,
    budget: WaveBudget,
    sent: f64,
    /// The commanded point (m).
    x_d: f64,
    /// The master's newest position received (m).
    x_m: f64,
    /// The master's newest wave energy sent, as received (J).
    far_sent: f64,
    /// The master's newest wave received.
    u: f64,
}

/// What the slave side produced in one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlaveStep {
    /// The coupling force on the slave body (N); the link point feels `−F_s`.
    pub force: f64,
    /// The commanded velocity `ẋ_d` (m/s).
    pub v_d: f64,
    /// The message to send back.
    pub msg: WaveMsg,
}

impl WaveSlave {
    /// A slave side whose commanded point starts at `x0` (m).
    pub fn new(p: WaveParams, x0: f64) -> Self {
        Self {
            p,
            x_d: x0,
            x_m: x0,
            ..Self::default()
        }
    }

    /// One sample of `dt` (s): `msg` the master's newest wave if one arrived this sample; the
    /// slave body at `x_s` (m) moving at `v_s` (m/s), held by a coupling of stiffness `k` (N/m)
    /// and damping `c` (N·s/m) to the commanded point.
    pub fn step(
        &mut self,
        msg: Option<WaveMsg>,
        x_s: f64,
        v_s: f64,
        k: f64,
        c: f64,
        dt: f64,
    ) -> SlaveStep {
        let b = self.p.b;
        if let Some(m) = msg.filter(|m| m.wave.is_finite() && m.x.is_finite()) {
            self.u = m.wave;
            self.x_m = m.x;
            if m.energy.is_finite() {
                self.far_sent = self.far_sent.max(m.energy);
            }
        }
        let mut u = self.u;
        // The drift correction, in wave units; then the energy budget on the whole wave.
        u += self.p.drift_gain * (self.x_m - self.x_d) * (b / 2.0).sqrt();
        let u = self.budget.spend(u, self.far_sent, dt);
        // F_s = k·(x_d + ẋ_d·dt − x_s) + c·(ẋ_d − v_s) with ẋ_d = (√(2b)·u − F_s)/b.
        let g = (k * dt + c) / b;
        let f_s = (k * (self.x_d - x_s) - c * v_s + g * (2.0 * b).sqrt() * u) / (1.0 + g);
        let v_d = ((2.0 * b).sqrt() * u - f_s) / b;
        self.x_d += v_d * dt;
        let w = u - (2.0 / b).sqrt() * f_s;
        self.sent += 0.5 * w * w * dt;
        SlaveStep {
            force: f_s,
            v_d,
            msg: WaveMsg {
                wave: w,
                energy: self.sent,
                x: self.x_d,
            },
        }
    }

    /// The commanded point (m).
    pub fn x_d(&self) -> f64 {
        self.x_d
    }

    /// The forward waves' budget (energy used and cut).
    pub fn budget(&self) -> WaveBudget {
        self.budget
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::network::link::{Impairment, Link};

    /// A master handle driven in free motion by a position-controlled hand (`x_h = A·sin(ωt)` for
    /// `moving` s, then still), a 0.3 kg slave body on the wave link's coupling (600 N/m,
    /// 4 N·s/m), `round_trip` samples, `loss` each way. Returns (|x_m − x_s| at the end (m),
    /// network energy created (J)).
    fn free_motion(p: WaveParams, round_trip: u32, loss: f64, moving: f64) -> (f64, f64) {
        let dt = 1e-3;
        let n = ((moving + 3.0) / dt) as u64;
        let mut up: Link<WaveMsg> = Link::new(Impairment::delay_loss(round_trip / 2, loss, 5));
        let mut down: Link<WaveMsg> = Link::new(Impairment::delay_loss(round_trip / 2, loss, 6));
        let (mut m, mut s) = (WaveMaster::new(p), WaveSlave::new(p, 0.0));
        let (mut x_m, mut v_m, mut x_s, mut v_s) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let (mut e_in, mut e_out) = (0.0, 0.0);
        for k in 0..n {
            let t = k as f64 * dt;
            let x_h = if t < moving {
                0.02 * (2.0 * std::f64::consts::PI * 0.7 * t).sin()
            } else {
                0.0
            };
            let (f, out) = m.step(x_m, v_m, down.deliver(k), dt);
            up.send(k, out);
            let st = s.step(up.deliver(k), x_s, v_s, 600.0, 4.0, dt);
            down.send(k, st.msg);
            // Power out of the network: at the handle f·v_m, at the slave F_s·ẋ_d.
            for pw in [f * v_m, st.force * st.v_d] {
                if pw > 0.0 {
                    e_out += pw * dt;
                } else {
                    e_in -= pw * dt;
                }
            }
            let f_hand = 400.0 * (x_h - x_m) - 8.0 * v_m;
            v_m += dt * (f_hand + f) / 0.2;
            x_m += dt * v_m;
            v_s += dt * st.force / 0.3;
            x_s += dt * v_s;
        }
        ((x_m - x_s).abs(), e_out - e_in)
    }

    #[test]
    fn the_budget_never_spends_more_wave_energy_than_was_sent() {
        let mut b = WaveBudget::default();
        let dt = 1e-3;
        // 1 mJ sent; a wave of 10 √W wants 50 mJ in one sample: cut to what is left.
        let w = b.spend(10.0, 1e-3, dt);
        assert!((0.5 * w * w * dt - 1e-3).abs() < 1e-12, "{w}");
        assert_eq!(b.spend(-3.0, 1e-3, dt), 0.0);
        assert!((b.used() - 1e-3).abs() < 1e-12);
        assert!(b.spend(f64::NAN, 1.0, dt) == 0.0);
    }

    #[test]
    fn a_master_whose_force_is_cut_sends_and_draws_the_waves_of_the_force_applied() {
        let p = WaveParams::default();
        let dt = 1e-3;
        let back = WaveMsg {
            wave: 2.0,
            energy: 1.0,
            x: 0.0,
        };
        let (v, b) = (0.05, p.b);
        // Uncut, force + book is the step: u = √(2b)·v − w.
        let mut m = WaveMaster::new(p);
        let (f, out) = m.step(0.0, v, Some(back), dt);
        assert!((f - (-(b * v) + (2.0 * b).sqrt() * 2.0)).abs() < 1e-12);
        assert!((out.wave - ((2.0 * b).sqrt() * v - 2.0)).abs() < 1e-12);
        // The actuators apply half of it: the port's power v·(−applied) is ½u² − ½w² exactly,
        // with u sent and w drawn (booked in the budget) those of the half force.
        let mut m = WaveMaster::new(p);
        let f = m.force(v, Some(back), dt);
        let out = m.book(0.0, v, 0.5 * f, dt);
        let drawn = m.budget().used() / (0.5 * dt);
        let power = v * -(0.5 * f);
        assert!(
            (power - (0.5 * out.wave * out.wave - 0.5 * drawn)).abs() < 1e-9,
            "{power} {out:?} {drawn}"
        );
        assert!((out.energy - 0.5 * out.wave * out.wave * dt).abs() < 1e-15);
    }

    #[test]
    fn without_loss_or_delay_the_wave_link_is_lossless_and_tracks() {
        let (drift, created) = free_motion(WaveParams::default(), 0, 0.0, 5.0);
        assert!(created <= 1e-9, "{created}");
        assert!(drift < 2e-4, "{drift}");
    }

    #[test]
    fn drift_compensation_bounds_the_drift_that_loss_leaves_in_free_motion() {
        let none = WaveParams {
            drift_gain: 0.0,
            ..WaveParams::default()
        };
        for rt in [50, 200] {
            let (d0, c0) = free_motion(none, rt, 0.1, 20.0);
            let (d1, c1) = free_motion(WaveParams::default(), rt, 0.1, 20.0);
            assert!(c0 <= 1e-3 && c1 <= 1e-3, "{c0} {c1}");
            // Measured: 0.10 mm and 0.81 mm without, at most 0.06 mm with (λ = 5 /s).
            assert!(
                d1 < 2e-4,
                "round trip {rt} ms: drift {d1} m with compensation"
            );
            assert!(
                d1 < 0.5 * d0,
                "round trip {rt} ms: {d1} m with, {d0} m without"
            );
        }
    }
}
