//! [`DeviceEnd`]: one haptic device with the tick's safety and no world — the end of a link
//! whose world (or slave device) is elsewhere: the device side of `haptic2d run --world`, either
//! device of a teleoperation. The world-free part of [`Haptic::haptic_tick`](super::Haptic) for
//! every device kind alike (the twin pantograph, a 2-DOF five-bar such as a 2DIY or a UDP
//! five-bar, a Cartesian point device such as the Inverse3), with the same [`SafetyStage`]:
//!
//! ```text
//! 0.   sense:   stall, joint plausibility          (SafetyStage::supervise_input)
//! 1–2.          pose, twist, hand wrench           (CartesianDevice::sense; a fault trips)
//! 2b.           a five-bar below its singularity margin trips
//! 1b.           the first valid reading is the origin; the ramp starts there
//!      (the caller: the link's force, its passivity controller)
//! 8b.  actuate: workspace wall, trip beyond it     (SafetyStage::workspace_wall)
//! 9.            τ = Jᵀ·f saturated, limit cycle, singular pose, ramp, final gate
//! ```
//!
//! [`DeviceEnd::actuate`] returns the part of the motors' wrench the request produced (the request
//! scaled by the saturation, the ramp and the final clamp; zero when gated): what a port's energy
//! books, as the tick's passivity observer books its port (step 9b). No
//! method allocates, locks, prints or does I/O.

use crate::device::linalg::{V3, V4};
use crate::device::pantograph2::Pantograph2;
use crate::device::{
    CartesianDevice, DeviceEstimate, DeviceFault, DeviceParams, ObserverKind, Pantograph2Device,
    PointDevice, TorqueCommand, TwinPantograph,
};

use super::safety::{Safety, SafetyConfig, SafetyReason, SafetyTrip};
use super::safety_stage::{SafetyStage, TickClock};
use super::workspace::{WorkspaceBound, WorkspaceSquare};

/// The device of a [`DeviceEnd`]: one of the three kinds of [`CartesianDevice`], read through the
/// loop's four joint slots (a five-bar uses `q[0..2]`, a point device `q[0..2]` in m).
// One end per run, built once and never moved in the loop: the size difference costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum EndDevice {
    /// The twin pantograph: x, y and θ.
    Twin(TwinPantograph),
    /// A 2-DOF five-bar: x and y.
    FiveBar(Pantograph2Device),
    /// A Cartesian point device: x and y (force in N in `τ[0..2]`).
    Point(PointDevice),
}

/// `$body` with `$d` bound to the device of whichever variant `$self` holds.
macro_rules! each {
    ($self:expr, $d:ident => $body:expr) => {
        match $self {
            EndDevice::Twin($d) => $body,
            EndDevice::FiveBar($d) => $body,
            EndDevice::Point($d) => $body,
        }
    };
}

impl EndDevice {
    /// [`CartesianDevice::sense`] on the four joint slots `q` (rad; a point device: m).
    fn sense(
        &mut self,
        q: &V4,
        tau_prev: &V4,
        elapsed: f64,
    ) -> Result<DeviceEstimate, DeviceFault> {
        match self {
            EndDevice::Twin(d) => d.sense(q, tau_prev, elapsed),
            EndDevice::FiveBar(d) => d.sense(&[q[0], q[1]], tau_prev, elapsed),
            EndDevice::Point(d) => d.sense(&[q[0], q[1]], tau_prev, elapsed),
        }
    }

    fn wrench_to_torques(&self, f: &V3) -> Result<TorqueCommand, DeviceFault> {
        each!(self, d => d.wrench_to_torques(f, 0.0))
    }

    fn tau_max(&self) -> V4 {
        each!(self, d => d.tau_max())
    }

    fn margin(&self) -> f64 {
        each!(self, d => d.margin())
    }
}

/// What [`DeviceEnd::actuate`] hands back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndOutput {
    /// The motor commands to write now (N·m; a point device: N in `τ[0..2]`); zero when gated.
    pub tau: V4,
    /// The part of the motors' wrench that the request `f` produced (N, N, N·m; device frame): `f`
    /// scaled by the saturation, the ramp and the final clamp; zero when gated. What a port's
    /// books count: the workspace wall's share is the device's own passive wall, not the port's.
    pub applied: V3,
    /// That scale, in [0, 1]: saturation × ramp × final clamp (0 when gated).
    pub factor: f64,
    /// True when the final gate zeroed the torques (latched, or tripped this tick).
    pub gated: bool,
}

/// One device, its safety stage and its start pose (see the module doc).
#[derive(Clone, Debug)]
pub struct DeviceEnd {
    device: EndDevice,
    safety: SafetyStage,
    tau_prev: V4,
    origin: Option<V3>,
    /// The handle's apparent mass per axis (kg, kg, kg·m²) for a device without a dynamic model.
    nominal_mass: V3,
    /// Whether a singularity margin below the latch's limit trips at the reading (the five-bar).
    margin_at_sense: bool,
}

impl DeviceEnd {
    /// The twin pantograph with parameters `params` (its observer estimates the hand wrench), the
    /// safety settings `safety` (validated here) and the bound of its workspace, at period `dt` (s).
    pub fn twin(params: DeviceParams, safety: SafetyConfig, dt: f64) -> Result<Self, String> {
        safety.validate()?;
        let device = TwinPantograph::new(params, dt, ObserverKind::default())?;
        let latch = Safety::new(
            params.min_singularity_margin,
            params.tau_max,
            safety.torque_trip_margin,
        );
        let stage = SafetyStage::new(safety, latch, WorkspaceBound::new(&params, dt), dt);
        Ok(Self::assemble(
            EndDevice::Twin(device),
            stage,
            [0.0; 3],
            false,
        ))
    }

    /// A 2-DOF five-bar `linkage` (m) with motor limits `tau_max` (N·m), singularity limit
    /// `min_margin`, workspace square `workspace`, the handle's apparent mass `mass` (kg, for the
    /// caller's damping caps: the five-bar has no dynamic model in the tick), `safety`, period `dt`.
    pub fn five_bar(
        linkage: Pantograph2,
        tau_max: [f64; 2],
        min_margin: f64,
        workspace: WorkspaceSquare,
        mass: f64,
        safety: SafetyConfig,
        dt: f64,
    ) -> Result<Self, String> {
        let gate = tau_max[0].min(tau_max[1]);
        check_positive("tau_max", gate, "N·m")?;
        let stage = square_stage(workspace, mass, (min_margin, gate), safety, dt)?;
        let device = Pantograph2Device::new(linkage, tau_max, min_margin, 50.0, dt);
        let end = EndDevice::FiveBar(device);
        Ok(Self::assemble(end, stage, [mass, mass, 0.0], true))
    }

    /// A Cartesian point device with force limit `force_limit` (N), workspace square `workspace`,
    /// the handle's apparent mass `mass` (kg), `safety`, period `dt` (s).
    pub fn point(
        force_limit: f64,
        workspace: WorkspaceSquare,
        mass: f64,
        safety: SafetyConfig,
        dt: f64,
    ) -> Result<Self, String> {
        check_positive("force_limit", force_limit, "N")?;
        // No singularity: the margin is 1 at every reading.
        let stage = square_stage(workspace, mass, (0.0, force_limit), safety, dt)?;
        let end = EndDevice::Point(PointDevice::new(force_limit, 50.0, dt));
        Ok(Self::assemble(end, stage, [mass, mass, 0.0], false))
    }

    fn assemble(device: EndDevice, safety: SafetyStage, nominal_mass: V3, at_sense: bool) -> Self {
        Self {
            device,
            safety,
            tau_prev: [0.0; 4],
            origin: None,
            nominal_mass,
            margin_at_sense: at_sense,
        }
    }

    /// Steps 0–2b on the joint reading `q` (the loop's four slots), taken `elapsed` s after the
    /// previous tick's, of which `device_wait` s waiting for the device (NaN: unknown): the stall
    /// and plausibility checks, the pose, twist and hand-wrench estimate, a five-bar's singularity
    /// check. The first valid reading becomes the origin and starts the ramp. `None` when the
    /// device could not be sensed (the latch then holds the fault).
    pub fn sense(
        &mut self,
        at: TickClock,
        q: &V4,
        elapsed: f64,
        device_wait: f64,
    ) -> Option<DeviceEstimate> {
        self.safety.supervise_input(at, q, elapsed, device_wait);
        let est = match self.device.sense(q, &self.tau_prev, elapsed) {
            Ok(e) => e,
            Err(fault) => {
                self.safety.trip(at, SafetyReason::Device(fault));
                return None;
            }
        };
        if self.margin_at_sense {
            let (margin, limit) = (self.device.margin(), self.safety.latch().min_margin);
            if margin < limit {
                self.safety
                    .trip(at, SafetyReason::Singularity { margin, limit });
            }
        }
        if self.origin.is_none() {
            self.origin = Some(est.pose);
            self.safety.restart_ramp();
        }
        Some(est)
    }

    /// Step 0, stall alone, for a device whose signals use one period whatever the interval (a
    /// simulated plant advanced per tick): trips when `elapsed` (s since the previous tick, of
    /// which `device_wait` s waiting for the device) exceeds the stall limit. Call it before
    /// [`Self::sense`], which then gets one period.
    pub fn check_stall(&mut self, at: TickClock, elapsed: f64, device_wait: f64) {
        self.safety.check_stall(at, elapsed, device_wait);
    }

    /// Steps 8b–9 for the wrench `f` (N, N, N·m; device frame) asked of the handle sensed as `est`
    /// (`None`: not sensed this tick, no torque): the workspace wall, the torques, the limit
    /// cycle, a singular pose, the ramp and the final gate. Remembers the torques for the next
    /// tick's observer.
    pub fn actuate(&mut self, at: TickClock, est: Option<&DeviceEstimate>, f: &V3) -> EndOutput {
        let mut w = *f;
        let mut tau = [0.0; 4];
        let mut scale = 0.0;
        if let Some(e) = est {
            self.safety.workspace_wall(at, &e.pose, &e.velocity, &mut w);
        }
        if est.is_some() && !self.safety.is_latched() {
            match self.device.wrench_to_torques(&w) {
                Ok(c) if c.near_singular => {
                    let (margin, limit) = (c.margin, self.safety.latch().min_margin);
                    self.safety
                        .trip(at, SafetyReason::Singularity { margin, limit });
                }
                Ok(c) => {
                    (tau, scale) = (c.tau, c.wrench_scale);
                    let tau_max = self.device.tau_max();
                    self.safety.observe_limit_cycle(at, &c.tau, &tau_max);
                }
                Err(fault) => self.safety.trip(at, SafetyReason::Torques(fault)),
            }
        }
        let ramp = self.safety.ramp();
        tau.iter_mut().for_each(|v| *v *= ramp);
        let peak_before = tau.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let gated = self.safety.gate(at, &mut tau, est.is_some());
        let peak_after = tau.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let applied = if gated || peak_before == 0.0 {
            0.0
        } else {
            scale * ramp * (peak_after / peak_before)
        };
        self.tau_prev = tau;
        EndOutput {
            tau,
            applied: f.map(|x| x * applied),
            factor: applied,
            gated,
        }
    }

    /// The handle's mass per axis at the last sensed pose (kg, kg, kg·m²): the twin's mass-matrix
    /// diagonal, or the apparent mass given for a device without a dynamic model (θ: 0 there).
    pub fn mass_diagonal(&self) -> V3 {
        match &self.device {
            EndDevice::Twin(d) => {
                let m = d.mass_matrix();
                [m[0][0].abs(), m[1][1].abs(), m[2][2].abs()]
            }
            EndDevice::FiveBar(_) | EndDevice::Point(_) => self.nominal_mass,
        }
    }

    /// The pose at the first valid reading (m, m, rad; device frame), `None` before it.
    pub fn origin(&self) -> Option<V3> {
        self.origin
    }

    /// The axes the device renders: `[true; 3]` for the twin, x and y for the others.
    pub fn axes(&self) -> [bool; 3] {
        [true, true, matches!(self.device, EndDevice::Twin(_))]
    }

    /// The device.
    pub fn device(&self) -> &EndDevice {
        &self.device
    }

    /// The device, mutably (e.g. to reset a twin's θ unwrapping before the first reading).
    pub fn device_mut(&mut self) -> &mut EndDevice {
        &mut self.device
    }

    /// The safety stage (the latch's limits, the ramp).
    pub fn safety(&self) -> &SafetyStage {
        &self.safety
    }

    /// Latches `reason` at `at` (the first reason wins): a stop the caller found (a lost link).
    pub fn trip(&mut self, at: TickClock, reason: SafetyReason) {
        self.safety.trip(at, reason);
    }

    /// The latched trip, if any.
    pub fn trip_info(&self) -> Option<SafetyTrip> {
        self.safety.trip_info()
    }

    /// The start-up ramp factor of this tick (see [`SafetyStage::ramp`]).
    pub fn ramp(&self) -> f64 {
        self.safety.ramp()
    }
}

/// The safety stage of a device bounded by the workspace square `workspace` (a five-bar, a point
/// device), with the latch's singularity limit and gate `(min_margin, gate)`, after checking the
/// settings and the handle's `mass` (kg).
fn square_stage(
    workspace: WorkspaceSquare,
    mass: f64,
    (min_margin, gate): (f64, f64),
    safety: SafetyConfig,
    dt: f64,
) -> Result<SafetyStage, String> {
    safety.validate()?;
    workspace.validate()?;
    check_positive("mass", mass, "kg")?;
    let latch = Safety::new(min_margin, gate, safety.torque_trip_margin);
    let bound = WorkspaceBound::of_square(&workspace, dt);
    Ok(SafetyStage::new(safety, latch, bound, dt))
}

fn check_positive(name: &str, v: f64, unit: &str) -> Result<(), String> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(format!("{name} = {v} {unit}: must be a finite number > 0"))
    }
}

#[cfg(test)]
#[path = "device_end_tests.rs"]
mod tests;
