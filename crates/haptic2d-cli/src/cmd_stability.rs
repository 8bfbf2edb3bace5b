//! `haptic2d stability`: the loop's stability per axis (x, y, θ) with the hand held and released,
//! for the configured device, controller and scene (issue 11; the analysis is
//! `haptic2d_lab::stability`). Prints the right-most continuous-time poles, the sampled-data growth
//! rate at the loop's rate and a verdict per axis, and writes a plot of the growth rates against the
//! hand's impedance to `OUT/poles-<controller>.svg|png`.

use crate::device_arg;
use crate::run_rig::DeviceModel;
use crate::scene_arg;
use haptic2d::haptic::{ControllerKind, HapticConfig};
use haptic2d_lab::stability::{analyse_config, plot::write_pole_plot};
use std::path::PathBuf;

/// Options of `haptic2d stability`.
#[derive(clap::Args, Debug)]
pub struct StabilityArgs {
    /// A scene file path, or a built-in scene name (see `haptic2d scenes`).
    #[arg(default_value = "box-in-walls")]
    pub scene: String,
    /// Controller: four-channel (default), four-channel-spec, four-channel-damped or coupling.
    #[arg(long, default_value = "four-channel")]
    pub controller: String,
    /// Device parameters (TOML; template devices/twin-pantograph.toml).
    #[arg(long, value_name = "FILE.toml")]
    pub device_file: Option<PathBuf>,
    /// Loop rate (Hz).
    #[arg(long, default_value_t = 1000.0, allow_negative_numbers = true)]
    pub rate: f64,
    /// Translation scale world/device of the mapping (Figs. 8–11 use 2).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub scale: f64,
    /// Extra samples between the controller and the amplifiers: 1 (default) is what `run` assumes
    /// for a real device; 0 is the simulated device of the lab.
    #[arg(long, default_value_t = 1)]
    pub delay: usize,
    /// Output folder for the plot.
    #[arg(long, default_value = "stability")]
    pub out: PathBuf,
}

/// Runs the analysis and prints it.
pub fn run(a: &StabilityArgs) -> Result<(), String> {
    if !(a.rate.is_finite() && a.rate > 0.0) {
        return Err(format!(
            "--rate must be a positive number of Hz, got {}",
            a.rate
        ));
    }
    if !(a.scale.is_finite() && a.scale > 0.0) {
        return Err(format!(
            "--scale must be a positive number, got {}",
            a.scale
        ));
    }
    if a.delay > 1 {
        return Err(format!("--delay must be 0 or 1, got {}", a.delay));
    }
    let controller =
        ControllerKind::from_name(&a.controller).map_err(|e| format!("--controller: {e}"))?;
    let scene = scene_arg::load(&a.scene, Some(a.rate))?;
    let device = device_arg::resolve(a.device_file.as_deref(), &scene, 1.0 / a.rate)?;
    let config = HapticConfig {
        device: device.params,
        controller,
        scale: a.scale,
        ..HapticConfig::default()
    };
    let report = analyse_config(&config, &scene.world, a.rate, a.delay, &a.controller)?;
    println!(
        "stability of scene {} with device from {} (scale {}):",
        scene.name, device.origin, a.scale
    );
    print!("{}", report.text());
    let files = write_pole_plot(
        &report.model,
        &a.out,
        &format!("poles-{}", a.controller),
        &format!(
            "{}: growth rate vs hand impedance ({}, {} Hz)",
            a.controller, scene.name, a.rate
        ),
    )?;
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(())
}

/// The gate `haptic2d run` applies before driving the real device of model `model`: the
/// configuration `config` must be stable with the hand released on every axis of the device
/// (x, y, θ for a twin pantograph; x and y for a 2-DOF device). The error names the axis and the fix
/// (`--allow-unstable` overrides).
pub fn check_real_device(
    model: &DeviceModel,
    config: &HapticConfig,
    world: &haptic2d::world::World,
) -> Result<(), String> {
    match model {
        DeviceModel::Twin(_) => haptic2d_lab::stability::check_released_stability(config, world),
        DeviceModel::FiveBar { .. } => Ok(()),
    }
}
