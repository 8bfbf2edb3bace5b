//! [`TwinPantograph`]: the device façade the real-time loop calls each tick (§0.5 steps 1, 2 and 9):
//! encoders → pose (with θ unwrapping and the closure monitor) → velocity → hand wrench, and a desired
//! handle wrench → four saturated motor torques.

use super::dynamics::LumpedDynamics;
use super::fault::DeviceFault;
use super::filter::VelocityFilter;
use super::jacobian::{jacobian, jacobian_at, singularity_margin_at};
use super::linalg::{j_mul_v, M3, M43, V3, V4};
use super::observer::{HandWrenchObserver, ObserverKind};
use super::params::DeviceParams;
use super::redundancy::{min_norm_torques, null_vector, saturate};
use super::twin::TwinKinematics;

/// The torques to send to the amplifiers (held for one period) and what was done to them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueCommand {
    /// Joint torques `(τ_11, τ_12, τ_21, τ_22)` (N·m), each within `±τ_max`.
    pub tau: V4,
    /// Factor applied to the wrench part by saturation (1 = none, 0 = forces clamped to zero).
    pub wrench_scale: f64,
    /// True if saturation scaled the wrench.
    pub saturated: bool,
    /// True if the singularity margin was below `min_singularity_margin`: all torques are zero.
    pub near_singular: bool,
    /// The singularity margin at the pose used (dimensionless).
    pub margin: f64,
}

impl TorqueCommand {
    /// The command at a pose whose singularity margin `margin` (dimensionless) is below the
    /// device's minimum: all torques zero, the wrench scaled to nothing.
    #[inline]
    pub fn near_singular(margin: f64) -> Self {
        TorqueCommand {
            tau: [0.0; 4],
            wrench_scale: 0.0,
            saturated: false,
            near_singular: true,
            margin,
        }
    }
}

/// What one tick of sensing produces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceEstimate {
    /// Handle pose `x_m,k` (m, m, rad; θ unwrapped).
    pub pose: V3,
    /// Filtered handle twist `v̂_m,k` (m/s, m/s, rad/s).
    pub velocity: V3,
    /// Estimated hand wrench `Ŵ_h,k` (N, N, N·m).
    pub hand_wrench: V3,
    /// Closure error `|P_2 − P_1| − r_c` (m).
    pub closure_error: f64,
}

/// A twin-pantograph device: parameters plus the per-tick sensing state (last pose, unwrapped θ,
/// velocity filter, hand-wrench observer) and the Jacobian at the last measured pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwinPantograph {
    /// Device parameters (validated at construction).
    pub params: DeviceParams,
    /// Kinematics derived from the parameters.
    pub kin: TwinKinematics,
    /// The §10.7 velocity filter.
    pub filter: VelocityFilter,
    /// The §10.6 hand-wrench observer.
    pub observer: HandWrenchObserver,
    model: LumpedDynamics,
    theta_prev: f64,
    pose: Option<V3>,
    velocity: V3,
    jac: M43,
    margin: f64,
    closure_error: f64,
}

impl TwinPantograph {
    /// A device with parameters `params` (validated) at sample period `dt` (s), with the given observer.
    pub fn new(params: DeviceParams, dt: f64, observer: ObserverKind) -> Result<Self, String> {
        params.validate()?;
        params.validate_for_period(dt)?;
        Ok(Self {
            params,
            kin: TwinKinematics::new(&params),
            filter: VelocityFilter::new(params.velocity_cutoff_hz, dt),
            observer: HandWrenchObserver::new(&params, observer, dt)?,
            model: LumpedDynamics::new(&params),
            theta_prev: 0.0,
            pose: None,
            velocity: [0.0; 3],
            jac: [[0.0; 3]; 4],
            margin: 0.0,
            closure_error: 0.0,
        })
    }

    /// Sets the reference for θ unwrapping (rad): the next reading is taken within ±π of `theta`.
    /// Also restarts the velocity filter and the observer.
    pub fn reset(&mut self, theta: f64) {
        self.theta_prev = theta;
        self.pose = None;
        self.filter.reset();
        self.observer.reset();
    }

    /// Step 1a: handle pose from the four encoder angles `q` (rad), θ unwrapped. Also stores the
    /// Jacobian and the singularity margin at this pose for [`TwinPantograph::torques_for_wrench`].
    /// Errors (fault: zero the torques) when FK fails or the closure monitor trips.
    pub fn pose_from_encoders(&mut self, q: &V4) -> Result<V3, DeviceFault> {
        let fk = self.kin.fk(q, self.theta_prev)?;
        let cfg = self.kin.configuration(&fk.pose)?;
        self.jac = jacobian_at(&self.kin, &cfg)?;
        self.margin = singularity_margin_at(&self.kin, &cfg);
        self.theta_prev = fk.pose[2];
        self.closure_error = fk.closure_error;
        self.pose = Some(fk.pose);
        Ok(fk.pose)
    }

    /// Steps 1–2 in one call: pose from encoders, filtered velocity, and the hand-wrench estimate using
    /// the torques `tau_prev` (N·m) applied during the previous interval.
    pub fn estimate(&mut self, q: &V4, tau_prev: &V4) -> Result<DeviceEstimate, DeviceFault> {
        self.estimate_elapsed(q, tau_prev, self.filter.dt)
    }

    /// [`estimate`](Self::estimate) for a reading taken `elapsed` seconds (measured) after the
    /// previous one: the velocity filter differentiates over, and the momentum observer integrates
    /// the held torques over, the measured interval (§10.6, §10.7), so a late tick does not read a
    /// normal motion as a jump. `elapsed == T` is exactly `estimate`.
    pub fn estimate_elapsed(
        &mut self,
        q: &V4,
        tau_prev: &V4,
        elapsed: f64,
    ) -> Result<DeviceEstimate, DeviceFault> {
        let pose = self.pose_from_encoders(q)?;
        self.velocity = self.filter.update_elapsed(&pose, elapsed);
        let hand_wrench = self
            .observer
            .update_elapsed(&pose, &self.velocity, tau_prev, elapsed)?;
        Ok(DeviceEstimate {
            pose,
            velocity: self.velocity,
            hand_wrench,
            closure_error: self.closure_error,
        })
    }

    /// `J_a` (4×3, rad/m and rad/rad) at handle pose `pose` (m, m, rad).
    pub fn jacobian(&self, pose: &V3) -> Result<M43, DeviceFault> {
        jacobian(&self.kin, pose)
    }

    /// Step 9: the four motor torques (N·m) producing handle wrench `w` (N, N, N·m) at the last measured
    /// pose: minimum-norm redundancy resolution, plus internal preload `preload·ν` (N·m, clamped to
    /// `±0.1·τ_max`), plus friction compensation (`params.friction_compensation·τ̂_f` at the
    /// estimated joint rates, Coulomb part outside `params.friction_deadband`; default off), then
    /// direction-preserving saturation (so the compensation is clamped with every other torque). Below the singularity-margin threshold the torques are
    /// zero and `near_singular` is set.
    pub fn torques_for_wrench(&self, w: &V3, preload: f64) -> Result<TorqueCommand, DeviceFault> {
        if self.pose.is_none() {
            return Err(DeviceFault::NoPose);
        }
        if !preload.is_finite() {
            return Err(DeviceFault::NonFinite);
        }
        if self.margin < self.params.min_singularity_margin {
            return Ok(TorqueCommand::near_singular(self.margin));
        }
        let mut tau_w = min_norm_torques(&self.jac, w)?;
        if self.params.friction_compensation > 0.0 {
            let qd = j_mul_v(&self.jac, &self.velocity);
            let tf = self
                .model
                .friction_feedforward(&qd, self.params.friction_deadband);
            for i in 0..4 {
                tau_w[i] += self.params.friction_compensation * tf[i];
            }
        }
        let nu = null_vector(&self.jac)?;
        let s = saturate(&tau_w, preload, &nu, self.params.tau_max);
        Ok(TorqueCommand {
            tau: s.tau,
            wrench_scale: s.wrench_scale,
            saturated: s.wrench_scale < 1.0,
            near_singular: false,
            margin: self.margin,
        })
    }

    /// The last measured pose, if any.
    pub fn pose(&self) -> Option<V3> {
        self.pose
    }

    /// The singularity margin at the last measured pose (dimensionless).
    pub fn margin(&self) -> f64 {
        self.margin
    }

    /// The mass matrix `M_x` (kg, kg·m, kg·m², §10.6) at the last measured pose; zero before the first
    /// reading.
    pub fn mass_matrix(&self) -> M3 {
        match self.pose {
            Some(p) => self.model.mass_matrix(&self.jac, p[2]),
            None => [[0.0; 3]; 3],
        }
    }
}

#[cfg(test)]
mod friction_compensation_tests {
    use super::*;

    /// A device with joint friction `f_c` (no viscous part), compensation `fraction` and `deadband`,
    /// read twice 1 ms apart with the handle moved 0.1 mm along +x and 0.05 mm along +y between the
    /// readings (raw 0.1 and 0.05 m/s, through the 50 Hz velocity filter).
    fn moving(f_c: f64, fraction: f64, deadband: f64) -> TwinPantograph {
        let p = DeviceParams {
            f_c,
            f_v: 0.0,
            friction_compensation: fraction,
            friction_deadband: deadband,
            ..DeviceParams::default()
        };
        let mut d = TwinPantograph::new(p, 1e-3, ObserverKind::Static).unwrap();
        let kin = TwinKinematics::new(&p);
        let x0 = [0.0, 0.14, 0.0];
        let x1 = [1e-4, 0.14 + 5e-5, 0.0];
        d.estimate(&kin.ik(&x0).unwrap(), &[0.0; 4]).unwrap();
        d.estimate(&kin.ik(&x1).unwrap(), &[0.0; 4]).unwrap();
        d
    }

    #[test]
    fn friction_compensation_feeds_the_coulomb_torque_forward_in_the_direction_of_motion() {
        let d = moving(0.015, 0.8, 0.05);
        let qd = j_mul_v(&d.jac, &d.velocity);
        assert!(
            qd.iter().all(|v| v.abs() > 0.05),
            "every joint moves: {qd:?}"
        );
        let cmd = d.torques_for_wrench(&[0.0; 3], 0.0).unwrap();
        for (i, (t, v)) in cmd.tau.iter().zip(&qd).enumerate() {
            // No wrench asked: the torque is the compensation alone, 0.8·f_c along q̇_i.
            assert!(
                (t - 0.8 * 0.015 * v.signum()).abs() < 1e-12,
                "joint {i}: τ = {t}, q̇ = {v}"
            );
        }
        // Inside the deadband (every joint's rate below 10 rad/s) nothing is fed forward.
        let still = moving(0.015, 0.8, 10.0);
        let cmd = still.torques_for_wrench(&[0.0; 3], 0.0).unwrap();
        assert_eq!(cmd.tau, [0.0; 4]);
        // Off by default.
        let off = moving(0.015, 0.0, 0.05);
        assert_eq!(
            off.torques_for_wrench(&[0.0; 3], 0.0).unwrap().tau,
            [0.0; 4]
        );
    }

    #[test]
    fn friction_compensation_is_clamped_with_the_other_torques() {
        // A compensation of 0.45 N·m per joint on top of a 20 N push: more than τ_max = 0.5 N·m
        // on some joint, so the saturation scales the command and no torque exceeds τ_max.
        let d = moving(0.45, 1.0, 0.05);
        let cmd = d.torques_for_wrench(&[20.0, 0.0, 0.0], 0.0).unwrap();
        assert!(cmd.saturated, "{cmd:?}");
        let tau_max = DeviceParams::default().tau_max;
        assert!(
            cmd.tau.iter().all(|t| t.abs() <= tau_max + 1e-12),
            "{:?}",
            cmd.tau
        );
    }
}
