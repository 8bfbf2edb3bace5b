//! Passivity observer / passivity controller (Hannaford & Ryu 2002), §12.
//!
//! The port is the device–environment interface: the environment (controller plus virtual environment)
//! applies `F_out,k` to the device along `+x_m`, and the device moves `Δx_m,k = x_m,k+1 − x_m,k`. The
//! observer tracks the energy that has flowed **into** the environment, which must stay ≥ 0; the
//! controller (impedance causality: velocity in, force out) adds damping `α_k` whenever the observed
//! energy is negative.

/// How the observer pairs force and motion.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EnergyPairing {
    /// ZOH-consistent pairing (default, [DER]): the force held over the previous interval times the
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
            (-self.e_obs / (dt * v_hat * v_hat)).min(self.alpha_max)
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
    fn validate_and_set_param_name_the_parameter() {
        let mut pc = PassivityController::linear();
        pc.set_param("alpha_max", -1.0).expect("known key");
        assert!(pc.validate().unwrap_err().contains("alpha_max"));
        assert!(pc.set_param("gain", 1.0).unwrap_err().contains("v_min"));
        pc.set_param("pairing", 1.0).expect("flag");
        assert_eq!(pc.pairing, EnergyPairing::SameSample);
    }
}
