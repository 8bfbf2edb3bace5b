//! Settings of a [`HapticSystem`](super::HapticSystem): device, observer, controller, passivity
//! controller, which body is the slave, and how the device maps onto the world.

use crate::control::coupling::CouplingGains;
use crate::control::four_channel::FourChannelGains;
use crate::control::passivity::PlanarPassivity;
use crate::device::linalg::V3;
use crate::device::{DeviceParams, ObserverKind};
use crate::world::World;

/// Which teleoperation controller couples the device to the slave (§11).
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)] // a configuration value, copied at setup, never stored in bulk
pub enum ControllerKind {
    /// Lawrence's four-channel controller (§11.1), the default (with the released-stable gains of
    /// [`FourChannelGains::local_force_feedback`]).
    FourChannel(FourChannelGains),
    /// The impedance (virtual-coupling) baseline (§11.2).
    Coupling(CouplingGains),
}

impl Default for ControllerKind {
    fn default() -> Self {
        ControllerKind::FourChannel(FourChannelGains::default())
    }
}

impl ControllerKind {
    /// Names accepted by [`Self::from_name`].
    pub const NAMES: &'static str =
        "four-channel, coupling, four-channel-spec, four-channel-damped";

    /// The controller called `name` with its named gains: `four-channel` (default: local force
    /// feedback C6 = −1 and a small damping injection, stable with the hand released),
    /// `four-channel-spec` (the §11.1 table, unstable released), `four-channel-damped` (the §11.1
    /// table plus master damping injection) or `coupling`. The error lists the valid names.
    pub fn from_name(name: &str) -> Result<Self, String> {
        if let Some(g) = FourChannelGains::named(name) {
            return Ok(ControllerKind::FourChannel(g));
        }
        match name {
            "coupling" | "virtual-coupling" => {
                Ok(ControllerKind::Coupling(CouplingGains::default()))
            }
            _ => Err(format!(
                "unknown controller `{name}`; valid: {}",
                Self::NAMES
            )),
        }
    }

    /// The name used on the command line (`four-channel` for four-channel gains that are not one
    /// of the named configurations).
    pub fn name(&self) -> &'static str {
        match self {
            ControllerKind::FourChannel(g) => g.name().unwrap_or("four-channel"),
            ControllerKind::Coupling(_) => "coupling",
        }
    }
}

/// Everything a [`HapticSystem`](super::HapticSystem) needs besides the world.
#[derive(Clone, Debug, PartialEq)]
pub struct HapticConfig {
    /// Device parameters (§10.2). Default: the spec's twin pantograph.
    pub device: DeviceParams,
    /// Hand-wrench observer (§10.6). Default: generalized momentum.
    pub observer: ObserverKind,
    /// Teleoperation controller (§11). Default: four-channel with the released-stable gains
    /// ([`FourChannelGains::local_force_feedback`]).
    pub controller: ControllerKind,
    /// Passivity observer/controller on the device port (§12); `None` = off (default).
    pub passivity: Option<PlanarPassivity>,
    /// Name of the slave body; `None` = the first dynamic body of the world.
    pub slave: Option<String>,
    /// Keep the scene's loads on the slave body. Default false: in the haptic loop the hand drives the
    /// slave, so loads defined for world-only simulation (e.g. the Fig. 4 push) are dropped. Loads on
    /// other bodies are always kept.
    pub keep_slave_loads: bool,
    /// Handle pose (m, m, rad) that maps to the slave's initial pose; `None` = the workspace centre at
    /// θ = 0. The device should start here.
    pub device_origin: Option<V3>,
    /// Translation scale world/device (dimensionless). Default 1.
    pub scale: f64,
    /// Internal preload `ρ` of the redundancy resolution (N·m, §10.5). Default 0.
    pub preload: f64,
}

impl Default for HapticConfig {
    fn default() -> Self {
        Self {
            device: DeviceParams::default(),
            observer: ObserverKind::Momentum,
            controller: ControllerKind::default(),
            passivity: None,
            slave: None,
            keep_slave_loads: false,
            device_origin: None,
            scale: 1.0,
            preload: 0.0,
        }
    }
}

/// The slave body of a haptic system in `world`: the body named `name`, or the first dynamic body
/// (`None`). Errors (not found, with the bodies' names; a fixed body; no dynamic body) name the fix.
pub fn find_slave(world: &World, name: Option<&str>) -> Result<usize, String> {
    let slave = match name {
        Some(name) => world.body_index(name).ok_or_else(|| {
            format!(
                "slave body `{name}` not found; bodies: {}",
                world
                    .bodies
                    .iter()
                    .map(|b| b.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })?,
        None => world
            .bodies
            .iter()
            .position(|b| b.is_dynamic())
            .ok_or("the scene has no dynamic body for the device to drive")?,
    };
    if !world.bodies[slave].is_dynamic() {
        return Err(format!(
            "slave body `{}` is fixed; the device needs a dynamic body",
            world.bodies[slave].name
        ));
    }
    Ok(slave)
}
