//! [`PointSystem`]: a Cartesian pass-through device ([`PointDevice`]: the handle point in, a force
//! out, `J = I`, no virtual linkage) holding the slave at a grasp point — the 2-DOF tick of
//! [`Planar2System`](super::planar2::Planar2System) (the same [`GraspCoupling`], the one tick of
//! [`Haptic`]) over a device whose driver does its own kinematics, such as the Haply Inverse3 in
//! planar mode. The joint values are the point's coordinates (m), the torques forces (N): the
//! saturation, limit-cycle monitor and final gate work on the force against `force_limit`.

use crate::device::PointDevice;
use crate::world::World;

use super::config::ControllerKind;
use super::controller::Controller;
use super::planar2::{grasp_system, GraspCoupling, GraspParts};
use super::safety::SafetyConfig;
use super::tick::Haptic;
use super::workspace::WorkspaceSquare;

/// A point device coupled to the slave body of a world (see the module doc).
pub type PointSystem = Haptic<GraspCoupling<PointDevice, PointConfig>>;

/// Settings of a [`PointSystem`].
#[derive(Clone, Debug, PartialEq)]
pub struct PointConfig {
    /// Force limit on `|(f_x, f_y)|` (N), > 0: the device's own (the Inverse3's `limits.force_limit`).
    pub force_limit: f64,
    /// Teleoperation controller (§11), acting on x and y.
    pub controller: ControllerKind,
    /// Name of the slave body; `None` = the first dynamic body.
    pub slave: Option<String>,
    /// Grasp point in the slave's body frame (m). Default `(0, 0)`, the centre.
    pub grasp: [f64; 2],
    /// Velocity low-pass cut-off (Hz), §10.7. Default 50.
    pub velocity_cutoff_hz: f64,
    /// The shared safety settings ([`SafetyConfig`]): ramp, stall limit, trip margin.
    pub safety: SafetyConfig,
    /// Keep the scene's loads on the slave body. Default false (the hand drives it).
    pub keep_slave_loads: bool,
    /// The workspace square of the device file (device frame, m) with its wall and trip.
    pub workspace: WorkspaceSquare,
}

impl PointConfig {
    /// A configuration for a device with force limit `force_limit` (N) and workspace square
    /// `workspace`, with the defaults above.
    pub fn new(force_limit: f64, workspace: WorkspaceSquare) -> Self {
        Self {
            force_limit,
            controller: ControllerKind::default(),
            slave: None,
            grasp: [0.0; 2],
            velocity_cutoff_hz: 50.0,
            safety: SafetyConfig::default(),
            keep_slave_loads: false,
            workspace,
        }
    }
}

impl PointSystem {
    /// Builds the system around `world` (its period is the tick period). Errors name the setting.
    pub fn new(world: World, config: PointConfig) -> Result<Self, String> {
        let f = config.force_limit;
        if !(f.is_finite() && f > 0.0) {
            return Err(format!("force_limit = {f} N: must be a finite number > 0"));
        }
        let parts = GraspParts {
            controller: config.controller,
            slave: config.slave.clone(),
            grasp: config.grasp,
            velocity_cutoff_hz: config.velocity_cutoff_hz,
            safety: config.safety,
            keep_slave_loads: config.keep_slave_loads,
            workspace: config.workspace,
            // No singularity: the margin is 1 at every reading.
            min_margin: 0.0,
            gate_limit: f,
        };
        let cutoff = config.velocity_cutoff_hz;
        grasp_system(world, |dt| PointDevice::new(f, cutoff, dt), config, parts)
    }

    /// Switches the teleoperation controller to `kind` from its reset state; the gains are checked
    /// against the slave's mass as in [`Self::new`], and on error the running controller is kept.
    pub fn set_controller(&mut self, kind: ControllerKind) -> Result<(), String> {
        self.controller = Controller::build(kind, &self.world, self.slave, self.dt)?;
        self.coupling.settings.controller = kind;
        Ok(())
    }

    /// The configuration.
    pub fn config(&self) -> &PointConfig {
        &self.coupling.settings
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::coupling::CouplingGains;
    use crate::haptic::record::FLAG_SATURATED;
    use crate::haptic::{DeviceSystem, SafetyReason};
    use crate::scene::builtin;

    /// The device's rest point (m, device frame) and the square around it.
    const U0: [f64; 2] = [0.01, -0.02];

    /// A point system on box-in-walls with a spring-only coupling (K = 500 N/m, no damping, so the
    /// force depends on the position error alone), no ramp and a 5 N force limit.
    fn point_system() -> DeviceSystem {
        let world = builtin("box-in-walls", Some(1000.0))
            .unwrap()
            .unwrap()
            .world;
        let mut c = PointConfig::new(5.0, WorkspaceSquare::around(U0, 0.05));
        c.controller = ControllerKind::Coupling(CouplingGains {
            k: [500.0, 500.0, 1.0],
            b: [0.0; 3],
        });
        c.safety.ramp_time = 0.0;
        DeviceSystem::Point(PointSystem::new(world, c).unwrap())
    }

    fn at(dx: f64) -> [f64; 4] {
        [U0[0] + dx, U0[1], 0.0, 0.0]
    }

    /// `J = I`: the force sent is the coupling's `K·(x_s − x_m)`, no linkage in between. The first
    /// reading anchors the map (zero force); 4 mm off with the slave at rest asks −500 × 0.004 = −2 N
    /// along x.
    #[test]
    fn a_point_device_receives_the_coupling_force_unchanged() {
        let mut sys = point_system();
        let out = sys.tick(&at(0.0), None, false);
        assert_eq!(out.torques, [0.0; 4], "anchored at the first reading");
        let out = sys.tick(&at(0.004), None, false);
        assert!(!out.tripped, "{:?}", sys.safety_trip());
        assert!((out.torques[0] + 2.0).abs() < 1e-9, "{:?}", out.torques);
        assert!(out.torques[1].abs() < 1e-12 && out.torques[2..] == [0.0; 2]);
        assert_eq!(out.margin, 1.0);
    }

    /// 20 mm off asks 10 N, twice the 5 N limit: the device's saturation scales it to 5 N keeping
    /// the direction, and the record says so; the shared gate (limit 5 N) does not trip.
    #[test]
    fn a_force_above_the_device_limit_is_saturated_not_tripped() {
        let mut sys = point_system();
        sys.tick(&at(0.0), None, false);
        let out = sys.tick(&at(0.02), None, false);
        assert!(!out.tripped, "{:?}", sys.safety_trip());
        assert!((out.torques[0] + 5.0).abs() < 1e-9, "{:?}", out.torques);
        assert!(out.record.flags & FLAG_SATURATED != 0);
    }

    /// The shared safety stage reaches the point device: past the workspace square's trip distance
    /// the latch trips with the workspace reason and the force is zero in the same tick.
    #[test]
    fn a_point_device_past_its_workspace_square_trips_the_shared_latch() {
        let mut sys = point_system();
        sys.tick(&at(0.0), None, false);
        let out = sys.tick(&at(0.08), None, false);
        assert!(out.tripped);
        assert_eq!(out.torques, [0.0; 4]);
        let trip = sys.safety_trip().unwrap();
        assert!(
            matches!(trip.reason, SafetyReason::Workspace { axis: 0, .. }),
            "{trip}"
        );
    }

    #[test]
    fn a_force_limit_that_is_not_positive_is_refused_naming_the_field() {
        let world = builtin("box-in-walls", Some(1000.0))
            .unwrap()
            .unwrap()
            .world;
        let c = PointConfig::new(0.0, WorkspaceSquare::around(U0, 0.05));
        let err = PointSystem::new(world, c).unwrap_err();
        assert!(err.contains("force_limit"), "{err}");
    }
}
