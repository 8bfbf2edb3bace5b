//! [`PointSystem`]: a Cartesian pass-through device ([`PointDevice`]: the handle point in, a force
//! out, `J = I`, no virtual linkage) holding the slave at a grasp point — the 2-DOF tick of
//! [`Planar2System`](super::planar2::Planar2System) (the same [`GraspCoupling`], the one tick of
//! [`Haptic`]) over a device whose driver does its own kinematics, such as the Haply Inverse3 in
//! planar mode. The joint values are the point's coordinates (m), the torques forces (N): the
//! saturation, limit-cycle monitor and final gate work on the force against `force_limit`.

use crate::device::PointDevice;
use crate::world::World;

use super::config::ControllerKind;
use super::planar2::{grasp_system, GraspConfig, GraspCoupling, GraspSettings};
use super::tick::Haptic;
use super::workspace::WorkspaceSquare;

/// A point device coupled to the slave body of a world (see the module doc).
pub type PointSystem = Haptic<GraspCoupling<PointDevice, PointConfig>>;

/// Settings of a [`PointSystem`].
#[derive(Clone, Debug, PartialEq)]
pub struct PointConfig {
    /// Force limit on `|(f_x, f_y)|` (N), > 0: the device's own (the Inverse3's `limits.force_limit`).
    pub force_limit: f64,
    /// The settings every 2-DOF system shares (controller, slave, grasp point, filter, safety,
    /// workspace square).
    pub common: GraspConfig,
}

impl PointConfig {
    /// A configuration for a device with force limit `force_limit` (N) and workspace square
    /// `workspace` (device frame, m), with [`GraspConfig::new`]'s defaults.
    pub fn new(force_limit: f64, workspace: WorkspaceSquare) -> Self {
        Self {
            force_limit,
            common: GraspConfig::new(workspace),
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
        let cutoff = config.common.velocity_cutoff_hz;
        let common = config.common.clone();
        let device = |dt| PointDevice::new(f, cutoff, dt);
        // No singularity: the margin is 1 at every reading.
        grasp_system(world, device, config, &common, (0.0, f))
    }
}

impl GraspSettings for PointConfig {
    fn controller_mut(&mut self) -> &mut ControllerKind {
        &mut self.common.controller
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::coupling::CouplingGains;
    use crate::haptic::record::FLAG_SATURATED;
    use crate::haptic::tick::tests::{box_in_walls, tripped};
    use crate::haptic::{DeviceSystem, SafetyReason};

    /// The device's rest point (m, device frame) and the square around it.
    const U0: [f64; 2] = [0.01, -0.02];

    /// A point system on box-in-walls with a spring-only coupling (K = 500 N/m, no damping, so the
    /// force depends on the position error alone), no ramp and a 5 N force limit.
    fn point_system() -> DeviceSystem {
        let world = box_in_walls();
        let mut c = PointConfig::new(5.0, WorkspaceSquare::around(U0, 0.05));
        c.common.controller = ControllerKind::Coupling(CouplingGains {
            k: [500.0, 500.0, 1.0],
            b: [0.0; 3],
        });
        c.common.safety.ramp_time = 0.0;
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
        let trip = tripped(&sys, &out);
        assert!(
            matches!(trip.reason, SafetyReason::Workspace { axis: 0, .. }),
            "{trip}"
        );
    }

    #[test]
    fn a_force_limit_that_is_not_positive_is_refused_naming_the_field() {
        let c = PointConfig::new(0.0, WorkspaceSquare::around(U0, 0.05));
        let err = PointSystem::new(box_in_walls(), c).unwrap_err();
        assert!(err.contains("force_limit"), "{err}");
    }
}
