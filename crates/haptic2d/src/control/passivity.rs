//! Passivity observer / passivity controller (Hannaford & Ryu 2002), §12.
//!
//! The port is the device–environment interface: the environment (controller plus virtual environment)
//! applies `F_out,k` to the device along `+x_m`, and the device moves `Δx_m,k = x_m,k+1 − x_m,k`. The
//! observer tracks the energy that has flowed **into** the environment, which must stay ≥ 0; the
//! controller (impedance causality: velocity in, force out) adds damping `α_k` whenever the observed
//! energy is negative.
//!
//! Two things the textbook form leaves to the integrator, done here:
//!
//! - **Book what was applied.** The observer must pair the displacement with the force the device
//!   actually produced, which after saturation, the start-up ramp or a safety stop is not `F_out`.
//!   [`PassivityController::book_applied`] replaces the held force by the applied one (ZOH pairing).
//! - **Bound α by the explicit-damping limit.** The added damping `−α·v̂_k` is computed from the
//!   state at `k` and held over the sample: on a mass `M` that is the explicit-Euler update
//!   `v_{k+1} = (1 − α·T/M)·v_k`, which is stable only for `|1 − α·T/M| < 1`, i.e. `α < 2·M/T`
//!   ([`explicit_damping_limit`]). Above it the "damping" injects energy: each sample reverses the
//!   velocity and grows it. [`PassivityController::update_limited`] caps α at
//!   `min(α_max, 2·M/T)` for the axis's inertia `M`.

/// The explicit-damping limit `2·M/T` (N·s/m, or N·m·s/rad for an inertia in kg·m²): the largest
/// damping a sampled controller can add to mass `M` (kg or kg·m²) at period `dt` (s) without making
/// the sampled velocity update unstable (see the module doc).
#[inline]
pub fn explicit_damping_limit(mass: f64, dt: f64) -> f64 {
    2.0 * mass / dt
}

/// How the observer pairs force and motion.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EnergyPairing {
    /// ZOH-consistent pairing (default, \[DER\]): the force held over the previous interval times the
    /// displacement it produced, `E_obs,k = E_obs,k−1 − F_out,k−1·(x_k − x_{k−1})`.
    #[default]
    ZohConsistent,
    /// The original same-sample pairing, `E_obs,k = E_obs,k−1 − T·F_env,k·v̂_k + T·α_{k−1}·v̂²_{k−1}`
    /// (the last term books the controller's own dissipation). With a backward-difference velocity it
    /// misses the energy a ZOH stiffness generates; kept for comparison (§12, PC3).
    SameSample,
}

/// One passivity observer/controller for one DOF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassivityController {
    /// Energy pairing of the observer.
    pub pairing: EnergyPairing,
    /// Speed below which the controller does not act (m/s, or rad/s for θ).
    pub v_min: f64,
    /// Largest added damping `α_max` (N·s/m, or N·m·s/rad for θ).
    pub alpha_max: f64,
    /// `false` runs the observer only (α ≡ 0).
    pub control: bool,
    /// Observed energy into the environment `E_obs,k` (J).
    e_obs: f64,
    /// Force output at the previous sample `F_out,k−1` (N).
    f_prev: f64,
    /// Position at the previous sample `x_m,k−1` (m).
    x_prev: f64,
    /// Velocity estimate at the previous sample (m/s).
    v_prev: f64,
    /// Damping applied at the previous sample (N·s/m).
    alpha_prev: f64,
    /// Damping applied at this sample `α_k` (N·s/m).
    alpha: f64,
    /// Whether a previous sample exists.
    started: bool,
}

impl PassivityController {
    /// Valid parameter names for [`PassivityController::set_param`].
    pub const PARAMS: &'static str =
        "v_min, alpha_max, control (0 or 1), pairing (0 = zoh, 1 = same-sample)";

    /// A controller with threshold `v_min` and bound `alpha_max`, ZOH-consistent pairing, control on.
    pub fn new(v_min: f64, alpha_max: f64) -> Self {
        Self {
            pairing: EnergyPairing::ZohConsistent,
            v_min,
            alpha_max,
            control: true,
            e_obs: 0.0,
            f_prev: 0.0,
            x_prev: 0.0,
            v_prev: 0.0,
            alpha_prev: 0.0,
            alpha: 0.0,
            started: false,
        }
    }
    /// Defaults for a translational DOF: `v_min = 1e-4 m/s`, `α_max = 200 N·s/m`.
    pub fn linear() -> Self {
        Self::new(1e-4, 200.0)
    }
    /// Defaults for the rotational DOF: `v_min = 1e-3 rad/s`, `α_max = 200 N·m·s/rad`.
    pub fn angular() -> Self {
        Self::new(1e-3, 200.0)
    }
    /// The same controller with another pairing.
    pub fn with_pairing(mut self, pairing: EnergyPairing) -> Self {
        self.pairing = pairing;
        self
    }
    /// The same controller as an observer only (`control = false`, α ≡ 0).
    pub fn observer_only(mut self) -> Self {
        self.control = false;
        self
    }
    /// Checks the parameters; the error names the bad one.
    pub fn validate(&self) -> Result<(), String> {
        for (key, v) in [("v_min", self.v_min), ("alpha_max", self.alpha_max)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!(
                    "passivity: parameter `{key}` must be finite and ≥ 0, got {v}"
                ));
            }
        }
        Ok(())
    }
    /// Sets a parameter by name (see [`PassivityController::PARAMS`]).
    pub fn set_param(&mut self, key: &str, value: f64) -> Result<(), String> {
        match key {
            "v_min" => self.v_min = value,
            "alpha_max" => self.alpha_max = value,
            "control" | "pairing" => {
                let flag = if value == 0.0 {
                    false
                } else if value == 1.0 {
                    true
                } else {
                    return Err(format!(
                        "passivity: parameter `{key}` must be 0 or 1, got {value}"
                    ));
                };
                if key == "control" {
                    self.control = flag;
                } else if flag {
                    self.pairing = EnergyPairing::SameSample;
                } else {
                    self.pairing = EnergyPairing::ZohConsistent;
                }
            }
            _ => {
                return Err(format!(
                    "passivity: unknown parameter `{key}`; valid parameters: {}",
                    Self::PARAMS
                ))
            }
        }
        Ok(())
    }
    /// Forgets the observed energy and history.
    pub fn reset(&mut self) {
        *self = Self {
            pairing: self.pairing,
            v_min: self.v_min,
            alpha_max: self.alpha_max,
            control: self.control,
            ..Self::new(0.0, 0.0)
        };
    }
    /// Observed energy into the environment `E_obs,k` (J) after the last update.
    pub fn e_obs(&self) -> f64 {
        self.e_obs
    }
    /// Damping `α_k` (N·s/m) added at the last update.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// One sample: device position `x` (m) and velocity estimate `v_hat` (m/s) at sample `k`, the
    /// uncorrected environment force `f_env` (N) and the period `dt` (s). Returns `F_out,k` (N), which
    /// the caller must hold over the sample.
    pub fn update(&mut self, x: f64, v_hat: f64, f_env: f64, dt: f64) -> f64 {
        self.update_limited(x, v_hat, f_env, dt, f64::INFINITY)
    }

    /// [`update`](Self::update) with α capped at `min(α_max, alpha_cap)`; pass
    /// [`explicit_damping_limit`] of the axis's inertia as `alpha_cap` (N·s/m or N·m·s/rad).
    pub fn update_limited(
        &mut self,
        x: f64,
        v_hat: f64,
        f_env: f64,
        dt: f64,
        alpha_cap: f64,
    ) -> f64 {
        // Observer.
        match self.pairing {
            EnergyPairing::ZohConsistent => {
                if self.started {
                    self.e_obs -= self.f_prev * (x - self.x_prev);
                }
            }
            EnergyPairing::SameSample => {
                self.e_obs +=
                    -dt * f_env * v_hat + dt * self.alpha_prev * self.v_prev * self.v_prev;
            }
        }
        // Controller.
        self.alpha = if self.control && self.e_obs < 0.0 && v_hat.abs() > self.v_min {
            (-self.e_obs / (dt * v_hat * v_hat))
                .min(self.alpha_max)
                .min(alpha_cap.max(0.0))
        } else {
            0.0
        };
        let f_out = f_env - self.alpha * v_hat;
        self.started = true;
        self.f_prev = f_out;
        self.x_prev = x;
        self.v_prev = v_hat;
        self.alpha_prev = self.alpha;
        f_out
    }
}

impl PassivityController {
    /// Books `f_applied` (N or N·m), the force the device actually produced over this sample (after
    /// saturation, ramp or a safety stop), as the held force the next sample pairs with its
    /// displacement (ZOH pairing). With the same-sample pairing (a comparison option) this only
    /// records the value; that pairing books `F_env` by definition.
    pub fn book_applied(&mut self, f_applied: f64) {
        if self.started {
            self.f_prev = f_applied;
        }
    }

    /// The force booked for the last sample (N or N·m): `F_out` or what [`Self::book_applied`] set.
    pub fn booked_force(&self) -> f64 {
        self.f_prev
    }
}

impl Default for PassivityController {
    fn default() -> Self {
        Self::linear()
    }
}

/// Separate controllers for the planar DOFs `x`, `y` (linear) and `θ` (angular).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarPassivity {
    /// Controller for `x` (m, N).
    pub x: PassivityController,
    /// Controller for `y` (m, N).
    pub y: PassivityController,
    /// Controller for `θ` (rad, N·m).
    pub theta: PassivityController,
}

impl Default for PlanarPassivity {
    fn default() -> Self {
        Self {
            x: PassivityController::linear(),
            y: PassivityController::linear(),
            theta: PassivityController::angular(),
        }
    }
}

impl PlanarPassivity {
    /// Checks every DOF's parameters.
    pub fn validate(&self) -> Result<(), String> {
        self.x.validate()?;
        self.y.validate()?;
        self.theta.validate()
    }
    /// Forgets every DOF's observed energy.
    pub fn reset(&mut self) {
        self.x.reset();
        self.y.reset();
        self.theta.reset();
    }
    /// One sample for all three DOFs: pose `(x, y, θ)`, velocity estimate, uncorrected wrench
    /// `(F_x, F_y, τ)`; returns the corrected wrench.
    pub fn update(&mut self, pose: [f64; 3], vel: [f64; 3], wrench: [f64; 3], dt: f64) -> [f64; 3] {
        [
            self.x.update(pose[0], vel[0], wrench[0], dt),
            self.y.update(pose[1], vel[1], wrench[1], dt),
            self.theta.update(pose[2], vel[2], wrench[2], dt),
        ]
    }
    /// [`update`](Self::update) with each axis's α capped at `alpha_cap[i]` (see
    /// [`PassivityController::update_limited`]).
    pub fn update_limited(
        &mut self,
        pose: [f64; 3],
        vel: [f64; 3],
        wrench: [f64; 3],
        dt: f64,
        alpha_cap: [f64; 3],
    ) -> [f64; 3] {
        [
            self.x
                .update_limited(pose[0], vel[0], wrench[0], dt, alpha_cap[0]),
            self.y
                .update_limited(pose[1], vel[1], wrench[1], dt, alpha_cap[1]),
            self.theta
                .update_limited(pose[2], vel[2], wrench[2], dt, alpha_cap[2]),
        ]
    }
    /// Books the wrench the device actually produced this sample (see
    /// [`PassivityController::book_applied`]).
    pub fn book_applied(&mut self, wrench: [f64; 3]) {
        self.x.book_applied(wrench[0]);
        self.y.book_applied(wrench[1]);
        self.theta.book_applied(wrench[2]);
    }
    /// Zeroes α on every axis (the loop is stopped: nothing is added).
    pub fn idle(&mut self) {
        self.x.alpha = 0.0;
        self.y.alpha = 0.0;
        self.theta.alpha = 0.0;
    }
    /// Total observed energy over the three DOFs (J).
    pub fn e_obs(&self) -> f64 {
        self.x.e_obs() + self.y.e_obs() + self.theta.e_obs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zoh_pairing_books_held_force_times_displacement() {
        let mut pc = PassivityController::linear().observer_only();
        pc.update(0.0, 0.0, 2.0, 0.002);
        // Held 2 N while the port moved +1 mm: 2 mJ left the environment.
        pc.update(0.001, 0.5, 0.0, 0.002);
        assert!((pc.e_obs() + 0.002).abs() < 1e-15);
        assert_eq!(pc.alpha(), 0.0);
    }

    #[test]
    fn controller_removes_the_deficit_within_bounds() {
        let mut pc = PassivityController::linear();
        pc.update(0.0, 0.0, 2.0, 0.002);
        let f = pc.update(0.001, 0.5, 0.0, 0.002);
        // α = 0.002 / (0.002·0.25) = 4 N·s/m; F_out = −α·v̂ = −2 N.
        assert!((pc.alpha() - 4.0).abs() < 1e-12);
        assert!((f + 2.0).abs() < 1e-12);
        let mut capped = PassivityController::new(1e-4, 1.0);
        capped.update(0.0, 0.0, 2.0, 0.002);
        capped.update(0.001, 0.5, 0.0, 0.002);
        assert_eq!(capped.alpha(), 1.0);
    }

    #[test]
    fn alpha_is_capped_by_the_explicit_damping_limit() {
        // A 4 N·s/m request on a 1 g mass at T = 2 ms: the limit 2·M/T = 1 N·s/m wins.
        let cap = explicit_damping_limit(0.001, 0.002);
        assert!((cap - 1.0).abs() < 1e-12);
        let mut pc = PassivityController::linear();
        pc.update_limited(0.0, 0.0, 2.0, 0.002, cap);
        pc.update_limited(0.001, 0.5, 0.0, 0.002, cap);
        assert_eq!(pc.alpha(), 1.0);
    }

    #[test]
    fn booked_force_replaces_the_commanded_one() {
        // Commanded 2 N, but only 0.5 N was applied (saturation): the 1 mm that followed took
        // 0.5 mJ out of the environment, not 2 mJ.
        let mut pc = PassivityController::linear().observer_only();
        pc.update(0.0, 0.0, 2.0, 0.002);
        pc.book_applied(0.5);
        pc.update(0.001, 0.5, 0.0, 0.002);
        assert!((pc.e_obs() + 0.0005).abs() < 1e-15);
    }

    #[test]
    fn validate_and_set_param_name_the_parameter() {
        let mut pc = PassivityController::linear();
        pc.set_param("alpha_max", -1.0).expect("known key");
        assert!(pc.validate().unwrap_err().contains("alpha_max"));
        assert!(pc.set_param("gain", 1.0).unwrap_err().contains("v_min"));
        pc.set_param("pairing", 1.0).expect("flag");
        assert_eq!(pc.pairing, EnergyPairing::SameSample);
    }
}
