//! Time-domain passivity of a two-port network with delay (TDPA; Ryu, Kwon & Hannaford 2004;
//! Ryu & Preusche 2007; Artigas et al. 2010): one [`TdpaPort`] on each side of a link.
//!
//! # The idea
//!
//! A link that carries velocities one way and forces the other is a two-port network. With delay,
//! loss or jitter it can create energy, and a stiff contact on the far side then rings or runs
//! away. Each port's power `p = F·v` is split every sample into what flows *into* the network
//! (`p < 0`: the port does work on it) and what flows *out* (`p > 0`: the network does work on the
//! port), and the two sums are kept as monotone energies `E_in`, `E_out` (J). Each side sends its
//! `E_in` with every message; the other side, holding the last value it received, knows a lower
//! bound of what entered the network at the far port. The network is passive if, at every port,
//! `E_out(here, now) ≤ E_in(there, delayed)`: energy out here must have entered there first.
//!
//! Where a force output would break that, the port's **passivity controller** adds a damping
//! `α ≥ 0` to it, `F' = F − α·v`, with `α` just large enough that this sample's output energy
//! keeps the bound, capped at `α_max` (the explicit-damping stability limit `2·m/T` of the
//! port's inertia, as §12 caps its one-port controller). The booked output is the one produced, so
//! a capped `α` leaves a debt the next samples pay off. Delay only makes the received `E_in` older
//! (smaller), and loss or reordering only keeps an older value: both are conservative.
//!
//! Sign convention: `F` is the force the network applies to the port's body (N, or N·m on a
//! rotational axis), `v` that body's velocity (m/s, rad/s); `F·v > 0` is energy out of the network.

/// One port of a two-port network, one axis: its energy observer and passivity controller.
/// Deterministic, no allocation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TdpaPort {
    /// Energy that flowed from the port into the network so far (J, non-decreasing).
    e_in: f64,
    /// Energy that flowed from the network out to the port so far (J, non-decreasing).
    e_out: f64,
    /// Energy dissipated by the passivity controller so far (J).
    dissipated: f64,
    /// The damping of the last sample (N·s/m or N·m·s/rad).
    alpha: f64,
}

impl Default for TdpaPort {
    fn default() -> Self {
        Self::new()
    }
}

impl TdpaPort {
    /// A port with nothing booked.
    pub const fn new() -> Self {
        Self {
            e_in: 0.0,
            e_out: 0.0,
            dissipated: 0.0,
            alpha: 0.0,
        }
    }

    /// Energy that entered the network at this port so far (J): the value to send to the other side.
    pub fn energy_in(&self) -> f64 {
        self.e_in
    }

    /// Energy that left the network at this port so far (J).
    pub fn energy_out(&self) -> f64 {
        self.e_out
    }

    /// Energy the passivity controller dissipated so far (J).
    pub fn dissipated(&self) -> f64 {
        self.dissipated
    }

    /// The damping applied in the last sample (N·s/m, or N·m·s/rad).
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// The passivity controller alone, for a caller that may apply less than it returns (a
    /// device whose torques saturate, a start-up ramp): the force to apply, damped as in
    /// [`Self::step`], without booking it. Book what was really applied with [`Self::book`].
    /// A non-finite input returns no force.
    pub fn control(&mut self, force: f64, v: f64, far_e_in: f64, dt: f64, alpha_max: f64) -> f64 {
        self.alpha = 0.0;
        if !(force.is_finite() && v.is_finite() && far_e_in.is_finite() && dt > 0.0) {
            return 0.0;
        }
        let p = force * v;
        if p <= 0.0 || v == 0.0 {
            return force;
        }
        // Output this sample: keep e_out + p·dt ≤ far_e_in.
        let excess = self.e_out + p * dt - far_e_in.max(0.0);
        if excess <= 0.0 {
            return force;
        }
        self.alpha = (excess / (v * v * dt)).min(alpha_max.max(0.0));
        force - self.alpha * v
    }

    /// Books one sample in which the network really applied `force` to a body moving at `v` for
    /// `dt` (s), with the damping of the last [`Self::control`] call (whose dissipation `α·v²·dt`
    /// is booked, J). Non-finite values book nothing.
    pub fn book(&mut self, force: f64, v: f64, dt: f64) {
        if !(force.is_finite() && v.is_finite() && dt > 0.0) {
            return;
        }
        self.dissipated += self.alpha * v * v * dt;
        self.book_power(force * v, dt);
    }

    /// One sample of length `dt` (s): the network asks to apply `force` to a body moving at `v`;
    /// `far_e_in` (J) is the last energy-in received from the other port; `alpha_max` caps the
    /// damping (use `f64::INFINITY` for no cap). Returns the force to apply, with the damping that
    /// keeps `E_out ≤ far_e_in`, and books its power. A non-finite input applies no force.
    pub fn step(&mut self, force: f64, v: f64, far_e_in: f64, dt: f64, alpha_max: f64) -> f64 {
        if !(force.is_finite() && v.is_finite() && far_e_in.is_finite() && dt > 0.0) {
            self.alpha = 0.0;
            return 0.0;
        }
        let mut f = force;
        self.alpha = 0.0;
        let p = f * v;
        if p > 0.0 {
            // Output this sample: keep e_out + p·dt ≤ far_e_in.
            let excess = self.e_out + p * dt - far_e_in.max(0.0);
            if excess > 0.0 && v != 0.0 {
                let wanted = excess / (v * v * dt);
                self.alpha = wanted.min(alpha_max.max(0.0));
                f -= self.alpha * v;
                self.dissipated += self.alpha * v * v * dt;
            }
        }
        self.book_power(f * v, dt);
        f
    }

    /// Books the power `p = F·v` (W) over `dt` (s): into `E_out` when the port outputs (`p > 0`),
    /// into `E_in` otherwise.
    #[inline]
    fn book_power(&mut self, p: f64, dt: f64) {
        self.add_work(p * dt);
    }

    /// Books the work `w` (J) the network did on the port's body: into `E_out` when it is
    /// positive, into `E_in` otherwise.
    #[inline]
    fn add_work(&mut self, w: f64) {
        if w > 0.0 {
            self.e_out += w;
        } else {
            self.e_in -= w;
        }
    }

    /// Books one sample by its work rather than its power: the network did the work `work` (J,
    /// `> 0`: energy out to the port's body) and a controller removed `dissipated` (J) from it
    /// (for a controller that predicts the work of a held force,
    /// [`super::held_work::HeldWorkControl`]). Non-finite values book nothing.
    pub fn book_work(&mut self, work: f64, dissipated: f64) {
        if !(work.is_finite() && dissipated.is_finite()) {
            return;
        }
        self.dissipated += dissipated;
        self.add_work(work);
    }

    /// Books one sample without a controller: the network applied `force` to a body moving at `v`
    /// for `dt` (s). For observing a link that is not controlled (the comparison runs).
    pub fn observe(&mut self, force: f64, v: f64, dt: f64) {
        if !(force.is_finite() && v.is_finite()) {
            return;
        }
        self.book_power(force * v, dt);
        self.alpha = 0.0;
    }
}

/// What a two-port network did over a run: the energy that entered it at both ports, left it, and
/// the difference `created = out − in` (J; ≤ 0 for a passive network).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NetworkEnergy {
    /// Energy in at both ports (J).
    pub energy_in: f64,
    /// Energy out at both ports (J).
    pub energy_out: f64,
    /// `energy_out − energy_in` (J): energy the network created.
    pub created: f64,
}

impl NetworkEnergy {
    /// The balance of the two ports `a` and `b`.
    pub fn of(a: &TdpaPort, b: &TdpaPort) -> Self {
        let energy_in = a.energy_in() + b.energy_in();
        let energy_out = a.energy_out() + b.energy_out();
        Self {
            energy_in,
            energy_out,
            created: energy_out - energy_in,
        }
    }
}

/// The three ports of one side of a planar link, one per axis `(x, y, θ)`: a [`TdpaPort`] each.
/// Deterministic, no allocation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanarTdpa {
    /// The ports of the x, y and θ axes.
    pub axes: [TdpaPort; 3],
}

impl PlanarTdpa {
    /// Energy in per axis (J): the values to send to the other side.
    pub fn energy_in(&self) -> [f64; 3] {
        self.axes.map(|p| p.energy_in())
    }

    /// Energy out per axis (J).
    pub fn energy_out(&self) -> [f64; 3] {
        self.axes.map(|p| p.energy_out())
    }

    /// Energy in, out and dissipated summed over the three axes (J).
    pub fn totals(&self) -> (f64, f64, f64) {
        self.axes.iter().fold((0.0, 0.0, 0.0), |(i, o, d), p| {
            (i + p.energy_in(), o + p.energy_out(), d + p.dissipated())
        })
    }

    /// [`TdpaPort::control`] on each axis: `force` (N, N, N·m), `v` (m/s, m/s, rad/s), the far
    /// side's energy-in per axis (J), `alpha_max` per axis.
    pub fn control(
        &mut self,
        force: &[f64; 3],
        v: &[f64; 3],
        far_e_in: &[f64; 3],
        dt: f64,
        alpha_max: &[f64; 3],
    ) -> [f64; 3] {
        std::array::from_fn(|i| self.axes[i].control(force[i], v[i], far_e_in[i], dt, alpha_max[i]))
    }

    /// [`TdpaPort::book`] on each axis.
    pub fn book(&mut self, force: &[f64; 3], v: &[f64; 3], dt: f64) {
        for i in 0..3 {
            self.axes[i].book(force[i], v[i], dt);
        }
    }

    /// [`TdpaPort::observe`] on each axis (a link without the controller).
    pub fn observe(&mut self, force: &[f64; 3], v: &[f64; 3], dt: f64) {
        for i in 0..3 {
            self.axes[i].observe(force[i], v[i], dt);
        }
    }
}

/// The balance of a planar link from the totals `(in, out)` (J) of its two sides.
pub fn planar_balance(a: (f64, f64), b: (f64, f64)) -> NetworkEnergy {
    let (energy_in, energy_out) = (a.0 + b.0, a.1 + b.1);
    NetworkEnergy {
        energy_in,
        energy_out,
        created: energy_out - energy_in,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_beyond_the_far_input_is_damped_to_the_bound() {
        let mut p = TdpaPort::new();
        // 1 N on a body at 1 m/s for 1 ms would put out 1 mJ; only 0.4 mJ came in at the far end.
        let f = p.step(1.0, 1.0, 0.4e-3, 1e-3, f64::INFINITY);
        assert!(
            (p.energy_out() - 0.4e-3).abs() < 1e-15,
            "{}",
            p.energy_out()
        );
        assert!((f - 0.4).abs() < 1e-12, "{f}");
        assert!((p.dissipated() - 0.6e-3).abs() < 1e-15);
    }

    #[test]
    fn a_capped_damping_leaves_a_debt_that_later_samples_pay() {
        let mut p = TdpaPort::new();
        let f = p.step(1.0, 1.0, 0.0, 1e-3, 0.5);
        assert!((f - 0.5).abs() < 1e-12, "{f}");
        assert!(p.energy_out() > 0.0);
        assert!((p.energy_out() - 0.5e-3).abs() < 1e-15);
        // The next sample with the same request pays the 0.5 mJ debt: α = (0.5 + 1) mJ / (1·1 ms)
        // = 1.5, so the force reverses to −0.5 N and puts 0.5 mJ back into the network.
        let f2 = p.step(1.0, 1.0, 0.0, 1e-3, 10.0);
        assert!((f2 + 0.5).abs() < 1e-12, "{f2}");
        assert!((p.energy_in() - p.energy_out()).abs() < 1e-15);
    }

    #[test]
    fn input_power_is_never_damped_and_is_booked_as_input() {
        let mut p = TdpaPort::new();
        let f = p.step(-2.0, 1.0, 0.0, 1e-3, f64::INFINITY);
        assert_eq!(f, -2.0);
        assert!((p.energy_in() - 2e-3).abs() < 1e-15);
        assert_eq!(p.energy_out(), 0.0);
    }

    #[test]
    fn control_then_book_of_the_full_output_equals_step() {
        let (mut a, mut b) = (TdpaPort::new(), TdpaPort::new());
        for k in 0..50 {
            let (f, v) = ((k as f64 * 0.3).sin() * 2.0, (k as f64 * 0.17).cos());
            let fa = a.step(f, v, 1e-3 * k as f64, 1e-3, 100.0);
            let fb = b.control(f, v, 1e-3 * k as f64, 1e-3, 100.0);
            b.book(fb, v, 1e-3);
            assert_eq!(fa, fb);
        }
        assert_eq!(a, b);
    }

    #[test]
    fn booking_a_saturated_output_books_what_was_applied() {
        // The controller allows 1 N at 1 m/s; the device applied only half of it.
        let mut p = TdpaPort::new();
        let f = p.control(1.0, 1.0, 1.0, 1e-3, f64::INFINITY);
        assert_eq!(f, 1.0);
        p.book(0.5 * f, 1.0, 1e-3);
        assert!((p.energy_out() - 0.5e-3).abs() < 1e-15);
    }

    #[test]
    fn planar_ports_keep_each_axis_within_its_far_input() {
        let mut side = PlanarTdpa::default();
        let f = side.control(
            &[1.0, -1.0, 0.1],
            &[1.0, -1.0, 1.0],
            &[0.2e-3, 0.0, 1.0],
            1e-3,
            &[f64::INFINITY; 3],
        );
        side.book(&f, &[1.0, -1.0, 1.0], 1e-3);
        let out = side.energy_out();
        assert!((out[0] - 0.2e-3).abs() < 1e-15, "{out:?}");
        assert!(out[1].abs() < 1e-15, "{out:?}");
        assert!((out[2] - 0.1e-3).abs() < 1e-15, "{out:?}");
        let bal = planar_balance((0.0, side.totals().1), (0.3e-3, 0.0));
        assert!((bal.created - 0.0).abs() < 1e-15, "{bal:?}");
    }

    #[test]
    fn booking_by_work_puts_positive_work_out_negative_work_in_and_adds_the_dissipation() {
        let mut p = TdpaPort::new();
        p.book_work(2e-3, 1e-4);
        p.book_work(-5e-4, 0.0);
        p.book_work(f64::NAN, 1.0);
        assert_eq!(
            (p.energy_out(), p.energy_in(), p.dissipated()),
            (2e-3, 5e-4, 1e-4)
        );
    }

    #[test]
    fn non_finite_inputs_apply_no_force() {
        let mut p = TdpaPort::new();
        assert_eq!(p.step(f64::NAN, 1.0, 1.0, 1e-3, 1.0), 0.0);
        assert_eq!(p.step(1.0, f64::INFINITY, 1.0, 1e-3, 1.0), 0.0);
        assert_eq!(p.energy_out(), 0.0);
    }
}
