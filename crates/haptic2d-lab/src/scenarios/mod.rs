//! The paper's device-in-the-loop experiments, as library code: each runs a
//! [`HapticSystem`](haptic2d::haptic::HapticSystem) closed around the simulated twin pantograph and a
//! simulated hand ([`DeviceInTheLoop`](haptic2d::haptic::DeviceInTheLoop)) and measures the claim.
//! The [`Figure`](crate::Figure)s of [`crate::figures::fig5`] and [`crate::figures::fig8`] turn them into data, plots
//! and the report.
//!
//! - [`walls_with_device`]: Figs. 5–6, the walls on the haptic interface.
//! - [`peg_with_device`]: Figs. 8–11, the peg in a tight hole, one friction model per case.

pub mod peg_with_device;
pub mod walls_with_device;

use haptic2d::control::coupling::CouplingGains;
use haptic2d::control::four_channel::FourChannelGains;
use haptic2d::haptic::{ControllerKind, HapticConfig};

/// The parameters of a device-in-the-loop scenario ([`walls_with_device::Fig5Params`],
/// [`peg_with_device::Fig8Params`]) and the controller comparison runs made from its defaults.
pub trait ControllerRuns: Default {
    /// The haptic configuration the scenario runs.
    fn haptic_mut(&mut self) -> &mut HapticConfig;

    /// The defaults with `controller` in place of the default controller.
    fn with_controller(controller: ControllerKind) -> Self {
        let mut p = Self::default();
        p.haptic_mut().controller = controller;
        p
    }

    /// The defaults with the virtual-coupling controller (§11.2) instead of the four-channel one
    /// (same device). A comparison run.
    fn coupling() -> Self {
        Self::with_controller(ControllerKind::Coupling(CouplingGains::default()))
    }

    /// The defaults with the paper's four-channel gains (the §11.1 table,
    /// `FourChannelGains::spec`) on the spec's device as given: unstable with the hand released
    /// (§11.4). A comparison run.
    fn paper_controller() -> Self {
        Self::with_controller(ControllerKind::FourChannel(FourChannelGains::spec()))
    }
}

/// How "the hand is replaced by a constant force" (Figs. 5–6; the sinusoidal force of Figs. 8–11)
/// is read (issue 36 item 4). The paper's force information is observer-based, so the force could
/// have acted on the handle or been fed to the controller as the hand's force.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Protocol {
    /// The force acts on the handle, as a hand pushing it would; the observer estimates it (the
    /// default, the reading used so far).
    #[default]
    HandleForce,
    /// The hand lets go (nothing pushes the handle along the push) and the force is added to the
    /// hand-force estimate the controller receives
    /// ([`HapticSystem::set_hand_estimate_injection`](haptic2d::haptic::system::HapticSystem::set_hand_estimate_injection)).
    EstimateInjection,
}

impl Protocol {
    /// Both protocols.
    pub const ALL: [Protocol; 2] = [Protocol::HandleForce, Protocol::EstimateInjection];

    /// The protocol's name in reports: `handle-force` or `estimate-injection`.
    pub fn name(self) -> &'static str {
        match self {
            Protocol::HandleForce => "handle-force",
            Protocol::EstimateInjection => "estimate-injection",
        }
    }
}

/// The text of the built-in scene `scene` with its table from the line `table` up to (not
/// including) the line `next` replaced by `replacement`: how a device-in-the-loop case swaps the
/// wall law or friction model of the paper's scene.
pub fn builtin_with_table(
    scene: &str,
    table: &str,
    next: &str,
    replacement: &str,
) -> Result<String, String> {
    let text = haptic2d::scene::BUILTIN
        .iter()
        .find(|b| b.0 == scene)
        .ok_or(format!("built-in scene {scene} missing"))?
        .2;
    let start = text.find(table).ok_or(format!("{scene} has no {table}"))?;
    let end = text[start..]
        .find(next)
        .map(|i| start + i)
        .ok_or(format!("{scene} has no {next}"))?;
    Ok(format!("{}{replacement}{}", &text[..start], &text[end..]))
}

/// The hand holding the handle at pose `start` ([`HandModel::grip`](haptic2d::device::HandModel::grip)),
/// with the grip's stiffness (N/m, N/m, N·m/rad) and damping (N·s/m, N·s/m, N·m·s/rad) per axis,
/// which the pushes after the release keep along the axes they do not drive.
pub fn hold_at(
    start: [f64; 3],
) -> Result<(haptic2d::device::HandModel, [f64; 3], [f64; 3]), String> {
    let hold = haptic2d::device::HandModel::grip(start);
    match hold {
        haptic2d::device::HandModel::SpringDamper {
            stiffness, damping, ..
        } => Ok((hold, stiffness, damping)),
        _ => Err("grip hand is a spring-damper".into()),
    }
}

/// The device file of the friction comparison runs (issue 36 item 3): the §10.2 device with
/// realistic joint Coulomb friction and its friction compensation.
pub const CAPSTAN_FRICTION_FILE: &str = "devices/twin-pantograph-capstan-friction.toml";

const CAPSTAN_FRICTION_TOML: &str =
    include_str!("../../../../devices/twin-pantograph-capstan-friction.toml");

/// The device of [`CAPSTAN_FRICTION_FILE`] (its joint Coulomb friction `f_c`, the compensation
/// fraction and deadband), every other field its §10.2 default.
pub fn capstan_friction_device() -> Result<haptic2d::device::DeviceParams, String> {
    haptic2d::scene::device_params_from_toml(CAPSTAN_FRICTION_TOML, CAPSTAN_FRICTION_FILE, None)
        .map_err(|e| e.to_string())
}

/// `device` with the joint friction of [`CAPSTAN_FRICTION_FILE`]; its compensation as in the file
/// when `compensated`, off otherwise.
pub fn with_capstan_friction(
    device: &haptic2d::device::DeviceParams,
    compensated: bool,
) -> Result<haptic2d::device::DeviceParams, String> {
    let f = capstan_friction_device()?;
    Ok(haptic2d::device::DeviceParams {
        f_c: f.f_c,
        f_v: f.f_v,
        friction_compensation: if compensated {
            f.friction_compensation
        } else {
            0.0
        },
        friction_deadband: f.friction_deadband,
        ..*device
    })
}
