//! The running teleoperation controller of a haptic system (one of the §11 architectures), built
//! from a [`ControllerKind`] with its gains checked against the slave's mass; shared by the twin's
//! and the 2-DOF tick.

use crate::control::coupling::VirtualCoupling;
use crate::control::four_channel::{FourChannel, TeleopSignals};
use crate::device::linalg::V3;
use crate::world::World;

use super::config::ControllerKind;

/// The running controller (one of the §11 architectures).
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub(super) enum Controller {
    FourChannel(FourChannel),
    Coupling(VirtualCoupling),
}

impl Controller {
    /// A controller `kind` in its reset state, its gains checked against the mass of the slave body
    /// `slave` of `world` at period `dt` (§6.4).
    pub(super) fn build(
        kind: ControllerKind,
        world: &World,
        slave: usize,
        dt: f64,
    ) -> Result<Self, String> {
        let body = &world.bodies[slave];
        let mass = [body.mass, body.mass, body.inertia];
        Ok(match kind {
            ControllerKind::FourChannel(g) => {
                g.check_slave_mass(&mass, dt)
                    .map_err(|e| format!("{e} (slave body `{}`)", body.name))?;
                Controller::FourChannel(FourChannel::new(g, dt)?)
            }
            ControllerKind::Coupling(g) => {
                let c = VirtualCoupling::new(g)?;
                c.check_slave_mass(&mass, dt)
                    .map_err(|e| format!("{e} (slave body `{}`)", body.name))?;
                Controller::Coupling(c)
            }
        })
    }

    #[inline]
    pub(super) fn step(&mut self, s: &TeleopSignals) -> (V3, V3) {
        match self {
            Controller::FourChannel(c) => c.step(s),
            Controller::Coupling(c) => c.step(s),
        }
    }
}
