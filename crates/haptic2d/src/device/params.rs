//! Twin-pantograph device parameters with the defaults of §10.2, §10.5–§10.7.

use serde::{Deserialize, Serialize};

use super::jacobian::singularity_margin;
use super::twin::TwinKinematics;

/// Geometry, inertia, friction, sensing and observer parameters of the twin-pantograph device.
///
/// All fields are plain public numbers so that a TOML table can override any subset
/// (`#[serde(default)]`); call [`DeviceParams::validate`] after loading.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DeviceParams {
    /// Distance between a pantograph's two motor axes `s` (m). Default 0.06.
    pub s: f64,
    /// Proximal link length `l1` (m). Default 0.10.
    pub l1: f64,
    /// Distal link length `l2` (m). Default 0.13.
    pub l2: f64,
    /// Crank radius `r_c` (m): distance from `P_1` (handle shaft) to `P_2` (crank pin). Default 0.025.
    pub r_c: f64,
    /// Workspace centre, x (m). Default 0.
    pub workspace_center_x: f64,
    /// Workspace centre, y (m). Default 0.14.
    pub workspace_center_y: f64,
    /// Workspace half-width in x and y (m): the square `centre ± half_width`, all θ. Default 0.032.
    pub workspace_half_width: f64,
    /// Capstan/cable reduction `n_g` (dimensionless). Default 10.
    pub n_g: f64,
    /// Motor rotor inertia `I_rot` (kg·m²), on the motor shaft (reflected: `I_rot·n_g²`). Default 5e-6.
    pub i_rot: f64,
    /// Proximal link inertia about its axis `I_p` (kg·m²). Default 1.33e-4.
    pub i_p: f64,
    /// Distal link mass `m_d` (kg). Default 0.05.
    pub m_d: f64,
    /// Handle + crank mass `m_h` (kg), at `P_1`. Default 0.08.
    pub m_h: f64,
    /// Handle + crank inertia about `P_1`, `I_h` (kg·m²). Default 4e-5.
    pub i_h: f64,
    /// Endpoint hardware mass of each pantograph `m_ee` (kg). Default 0.01.
    pub m_ee: f64,
    /// Joint torque limit after reduction `τ_max` (N·m), same for all four joints. Default 0.5.
    pub tau_max: f64,
    /// Joint Coulomb friction `f_c` (N·m). Default 0.005.
    pub f_c: f64,
    /// Joint viscous friction `f_v` (N·m·s/rad). Default 1e-4.
    pub f_v: f64,
    /// Encoder counts per revolution of the motor shaft (counts). Default 4000; the joint resolution is
    /// `2π/(counts·n_g)` rad.
    pub encoder_counts: f64,
    /// Cut-off of the first-order velocity low-pass `f_v` of §10.7 (Hz). Default 50.
    pub velocity_cutoff_hz: f64,
    /// Cut-off of the 2nd-order acceleration low-pass of the inverse-dynamics observer (Hz). Default 30.
    pub accel_cutoff_hz: f64,
    /// Momentum-observer gains `K_O = diag(k_x, k_y, k_θ)` (1/s). Default (60, 60, 60). `K_O·T < 1`.
    pub observer_gain: [f64; 3],
    /// Closure-monitor tolerance on `| |P_2 − P_1| − r_c |` (m). Default 1e-3.
    pub closure_tol: f64,
    /// Singularity-margin threshold (dimensionless `|sin|`): below it commanded forces are clamped to
    /// zero and a flag is raised (§10.4). Default 0.1.
    pub min_singularity_margin: f64,
    /// Friction-compensation fraction applied by the low-level controller, `0..=1` (§11.2): that
    /// fraction of the model's joint friction `τ̂_f(q̇)` is fed forward in the direction of motion
    /// (§10.5). Default 0 (the spec's option uses 0.5).
    pub friction_compensation: f64,
    /// Deadband of the friction compensation's Coulomb part (rad/s of joint rate): a joint whose
    /// estimated rate `|q̇_i|` is below it gets no Coulomb feed-forward (its viscous part is kept),
    /// so encoder noise at rest does not dither the motors. Default 0.05 (about 5 mm/s at the
    /// handle with `l1` = 0.1 m, several times the velocity estimate's quantisation noise).
    pub friction_deadband: f64,
    /// Stiffness of the workspace bound (N/m): past the edge of the workspace square the handle feels
    /// a wall `F = −K·(penetration) − B·v` (never pulling inward). Default 2000; 0 = no wall (the trip
    /// still applies).
    pub workspace_wall_stiffness: f64,
    /// Damping of the workspace bound `B` (N·s/m). Default 5. The loop renders the wall with stiffness
    /// `min(K, 2·B/T)`, so that Colgate's condition `B ≥ K·T/2` (§5.4) holds at its period `T` and the
    /// sampled wall stays passive (at 1 kHz the default 2000 N/m is rendered in full down to 200 Hz).
    pub workspace_wall_damping: f64,
    /// Trip distance (m): the safety latch trips when the handle is more than this far past the edge of
    /// the workspace square. Default 0.01.
    pub workspace_trip_distance: f64,
}

impl Default for DeviceParams {
    fn default() -> Self {
        Self {
            s: 0.06,
            l1: 0.10,
            l2: 0.13,
            r_c: 0.025,
            workspace_center_x: 0.0,
            workspace_center_y: 0.14,
            workspace_half_width: 0.032,
            n_g: 10.0,
            i_rot: 5e-6,
            i_p: 1.33e-4,
            m_d: 0.05,
            m_h: 0.08,
            i_h: 4e-5,
            m_ee: 0.01,
            tau_max: 0.5,
            f_c: 0.005,
            f_v: 1e-4,
            encoder_counts: 4000.0,
            velocity_cutoff_hz: 50.0,
            accel_cutoff_hz: 30.0,
            observer_gain: [60.0; 3],
            closure_tol: 1e-3,
            min_singularity_margin: 0.1,
            friction_compensation: 0.0,
            friction_deadband: 0.05,
            workspace_wall_stiffness: 2000.0,
            workspace_wall_damping: 5.0,
            workspace_trip_distance: 0.01,
        }
    }
}

impl DeviceParams {
    /// Every field, in declaration order, with its unit as written in scene and device files
    /// (`"-"` for a dimensionless number). Used by file loaders for messages and by the template
    /// `devices/twin-pantograph.toml`.
    pub const FIELDS: [(&'static str, &'static str); 28] = [
        ("s", "m"),
        ("l1", "m"),
        ("l2", "m"),
        ("r_c", "m"),
        ("workspace_center_x", "m"),
        ("workspace_center_y", "m"),
        ("workspace_half_width", "m"),
        ("n_g", "-"),
        ("i_rot", "kg·m²"),
        ("i_p", "kg·m²"),
        ("m_d", "kg"),
        ("m_h", "kg"),
        ("i_h", "kg·m²"),
        ("m_ee", "kg"),
        ("tau_max", "N·m"),
        ("f_c", "N·m"),
        ("f_v", "N·m·s/rad"),
        ("encoder_counts", "counts/rev"),
        ("velocity_cutoff_hz", "Hz"),
        ("accel_cutoff_hz", "Hz"),
        ("observer_gain", "1/s"),
        ("closure_tol", "m"),
        ("min_singularity_margin", "-"),
        ("friction_compensation", "-"),
        ("friction_deadband", "rad/s"),
        ("workspace_wall_stiffness", "N/m"),
        ("workspace_wall_damping", "N·s/m"),
        ("workspace_trip_distance", "m"),
    ];

    /// The unit of field `name` (see [`DeviceParams::FIELDS`]), or `None` for an unknown name.
    pub fn unit_of(name: &str) -> Option<&'static str> {
        Self::FIELDS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, u)| *u)
    }
}

fn positive(name: &str, v: f64) -> Result<(), String> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(format!(
            "device.{name} must be a finite number > 0 (got {v})"
        ))
    }
}

fn non_negative(name: &str, v: f64) -> Result<(), String> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(format!(
            "device.{name} must be a finite number >= 0 (got {v})"
        ))
    }
}

impl DeviceParams {
    /// Effective joint inertia `I_j = I_rot·n_g² + I_p + (m_d/2)·l1²` (kg·m²), §10.6.
    pub fn joint_inertia(&self) -> f64 {
        self.i_rot * self.n_g * self.n_g + self.i_p + 0.5 * self.m_d * self.l1 * self.l1
    }

    /// Endpoint point mass of pantograph 1 plus the handle, `m_e1 + m_h = m_d + m_ee + m_h` (kg).
    pub fn mass_at_p1(&self) -> f64 {
        self.m_d + self.m_ee + self.m_h
    }

    /// Endpoint point mass of pantograph 2, `m_e2 = m_d + m_ee` (kg).
    pub fn mass_at_p2(&self) -> f64 {
        self.m_d + self.m_ee
    }

    /// Joint encoder resolution `2π/(encoder_counts·n_g)` (rad per count).
    pub fn encoder_resolution(&self) -> f64 {
        std::f64::consts::TAU / (self.encoder_counts * self.n_g)
    }

    /// Checks every field (finite, positive where required), the link geometry, and that the whole
    /// workspace square (a 5×5 grid × 24 angles) is reachable with singularity margin at least
    /// `min_singularity_margin`. The error names the field to fix.
    pub fn validate(&self) -> Result<(), String> {
        positive("s", self.s)?;
        positive("l1", self.l1)?;
        positive("l2", self.l2)?;
        positive("r_c", self.r_c)?;
        positive("workspace_half_width", self.workspace_half_width)?;
        if !self.workspace_center_x.is_finite() || !self.workspace_center_y.is_finite() {
            return Err("device.workspace_center_x/workspace_center_y must be finite".into());
        }
        positive("n_g", self.n_g)?;
        positive("i_rot", self.i_rot)?;
        non_negative("i_p", self.i_p)?;
        non_negative("m_d", self.m_d)?;
        positive("m_h", self.m_h)?;
        positive("i_h", self.i_h)?;
        non_negative("m_ee", self.m_ee)?;
        positive("tau_max", self.tau_max)?;
        non_negative("f_c", self.f_c)?;
        non_negative("f_v", self.f_v)?;
        positive("encoder_counts", self.encoder_counts)?;
        positive("velocity_cutoff_hz", self.velocity_cutoff_hz)?;
        positive("accel_cutoff_hz", self.accel_cutoff_hz)?;
        for (i, k) in self.observer_gain.iter().enumerate() {
            positive(&format!("observer_gain[{i}]"), *k)?;
        }
        positive("closure_tol", self.closure_tol)?;
        non_negative("min_singularity_margin", self.min_singularity_margin)?;
        if !(0.0..=1.0).contains(&self.friction_compensation) {
            return Err(format!(
                "device.friction_compensation must be in [0, 1] (got {})",
                self.friction_compensation
            ));
        }
        non_negative("friction_deadband", self.friction_deadband)?;
        non_negative("workspace_wall_stiffness", self.workspace_wall_stiffness)?;
        non_negative("workspace_wall_damping", self.workspace_wall_damping)?;
        positive("workspace_trip_distance", self.workspace_trip_distance)?;
        if self.l2 <= self.s / 2.0 {
            return Err(format!(
                "device.l2 ({}) must exceed s/2 ({}) for the distal links to meet",
                self.l2,
                self.s / 2.0
            ));
        }
        self.validate_workspace()
    }

    /// Checks that the workspace square is reachable (IK succeeds) and well conditioned (margin ≥
    /// `min_singularity_margin`) on a 5×5 grid × 24 handle angles.
    fn validate_workspace(&self) -> Result<(), String> {
        let kin = TwinKinematics::new(self);
        let hw = self.workspace_half_width;
        for ix in 0..5 {
            for iy in 0..5 {
                for it in 0..24 {
                    let x = [
                        self.workspace_center_x + hw * (ix as f64 / 2.0 - 1.0),
                        self.workspace_center_y + hw * (iy as f64 / 2.0 - 1.0),
                        std::f64::consts::TAU * it as f64 / 24.0,
                    ];
                    let margin = singularity_margin(&kin, &x).map_err(|e| {
                        format!(
                            "device.workspace_half_width: pose ({:.4} m, {:.4} m, {:.3} rad) is not reachable with these link lengths (s, l1, l2, r_c): {e}",
                            x[0], x[1], x[2]
                        )
                    })?;
                    if margin < self.min_singularity_margin {
                        return Err(format!(
                            "device.workspace_half_width: pose ({:.4} m, {:.4} m, {:.3} rad) is too close to a singularity (margin {margin:.3} < min_singularity_margin {})",
                            x[0], x[1], x[2], self.min_singularity_margin
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// Checks the parameters that depend on the sample period `dt` (s): `K_O·T < 1` for the momentum
    /// observer (§10.6).
    pub fn validate_for_period(&self, dt: f64) -> Result<(), String> {
        positive("sample period", dt)?;
        for (i, k) in self.observer_gain.iter().enumerate() {
            if k * dt >= 1.0 {
                return Err(format!(
                    "device.observer_gain[{i}] = {k} 1/s times the sample period {dt} s must be < 1"
                ));
            }
        }
        Ok(())
    }
}
