//! `haptic2d stability`: the loop's stability per axis (x, y, θ) with the hand held and released,
//! for the configured device, controller and scene (issue 11; the analysis is
//! `haptic2d_lab::stability`). Prints the right-most continuous-time poles, the sampled-data growth
//! rate at the loop's rate and a verdict per axis, and writes a plot of the growth rates against the
//! hand's impedance to `OUT/poles-<controller>.svg|png`.

use crate::device_arg;
use crate::exit::Failure;
use crate::scene_arg;
use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::geom::Vec2;
use haptic2d::haptic::{ControllerKind, HapticConfig};
use haptic2d_devices::haply::identified::Identified;
use haptic2d_devices::haply::{HaplyDeviceFile, HaplyKind, Plant2};
use haptic2d_devices::registry::DeviceModel;
use haptic2d_lab::stability::planar2::{
    analyse_planar2, check_released_stability_planar2, check_released_stability_point,
    FiveBarDynamics,
};
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
    /// Controller architecture and gains from a file (wins over --controller; examples in
    /// controllers/).
    #[arg(long, value_name = "FILE.toml")]
    pub controller_file: Option<PathBuf>,
    /// Device parameters (TOML; template devices/twin-pantograph.toml), or a Haply device file
    /// (devices/haply-*.toml: a 2DIY gives the x and y axes of the 2-DOF device).
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

/// Runs the analysis and prints it. Rejected options, scenes and device files are bad input (exit
/// 2); a plot that cannot be written is a runtime failure (exit 1).
pub fn run(a: &StabilityArgs) -> Result<(), Failure> {
    if !(a.rate.is_finite() && a.rate > 0.0 && a.rate <= haptic2d::scene::MAX_RATE_HZ) {
        return Err(format!(
            "--rate must be a positive number of Hz up to {:e}, got {}\n    fix: e.g. --rate 1000",
            haptic2d::scene::MAX_RATE_HZ,
            a.rate
        )
        .into());
    }
    if a.out.exists() && !a.out.is_dir() {
        return Err(format!("--out: `{}` exists and is not a folder", a.out.display()).into());
    }
    if !(a.scale.is_finite() && a.scale > 0.0) {
        return Err(format!("--scale must be a positive number, got {}", a.scale).into());
    }
    if a.delay > 1 {
        return Err(format!("--delay must be 0 or 1, got {}", a.delay).into());
    }
    let (controller, label) =
        crate::controller_file::resolve(&a.controller, a.controller_file.as_deref())?;
    // A Haply device file (a top-level `kind`): the 2DIY's x and y, or the twin with its θ gains
    // matched to the crank.
    let haply = match a.device_file.as_deref() {
        Some(p) if is_haply_file(p) => Some(crate::haply_arg::load_file(Some(p))?),
        _ => None,
    };
    if let Some(f) = &haply {
        if let HaplyKind::TwoDiy {
            linkage, center, ..
        } = &f.kind
        {
            return Ok(run_planar2(
                a,
                &label,
                f,
                &f.controller_for(controller),
                linkage,
                *center,
            )?);
        }
    }
    let controller = haply
        .as_ref()
        .map_or(controller, |f| f.controller_for(controller));
    let scene = scene_arg::load(&a.scene, Some(a.rate))?;
    let device = match &haply {
        Some(HaplyDeviceFile {
            kind: HaplyKind::Twin(p),
            source,
            ..
        }) => device_arg::DeviceSetting {
            params: *p,
            origin: source.clone(),
        },
        _ => device_arg::resolve(a.device_file.as_deref(), &scene, 1.0 / a.rate)?,
    };
    let config = HapticConfig {
        device: device.params,
        controller,
        scale: a.scale,
        ..HapticConfig::default()
    };
    let report = analyse_config(&config, &scene.world, a.rate, a.delay, &label)?;
    println!(
        "stability of scene {} with device from {} (scale {}):",
        scene.name, device.origin, a.scale
    );
    print!("{}", report.text());
    let files = write_pole_plot(
        &report.model,
        &a.out,
        &format!("poles-{label}"),
        &format!(
            "{label}: growth rate vs hand impedance ({}, {} Hz)",
            scene.name, a.rate
        ),
    )
    .map_err(Failure::error)?;
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(())
}

/// The gate `haptic2d run` applies before driving the real device of model `model`: the
/// configuration `config` must be stable with the hand released on every axis of the device
/// (x, y, θ for a twin pantograph; x and y for a 2-DOF or point device). The error names the axis and the fix
/// (`--allow-unstable` overrides).
pub fn check_real_device(
    model: &DeviceModel,
    config: &HapticConfig,
    world: &haptic2d::world::World,
) -> Result<(), String> {
    match model {
        DeviceModel::Twin(_) => haptic2d_lab::stability::check_released_stability(config, world),
        DeviceModel::FiveBar {
            linkage,
            center,
            identified,
            ..
        } => check_released_stability_planar2(
            linkage,
            &five_bar_dynamics(linkage, *center, identified.as_ref())?.0,
            Vec2::new(center[0], center[1]),
            &config.controller,
            world,
        ),
        DeviceModel::Point { gate_dynamics, .. } => check_released_stability_point(
            gate_dynamics.mass,
            gate_dynamics.damping,
            &config.controller,
            world,
        ),
    }
}

/// The lumped dynamics of a 2DIY five-bar and where they come from: the device file's
/// `[identified]` table (`haptic2d device identify`) when present, else the numbers of the
/// emulator's simulated linkage (`haptic2d_devices::haply::Plant2`; estimates, not measurements of
/// a kit).
fn five_bar_dynamics(
    linkage: &Pantograph2,
    center: [f64; 2],
    identified: Option<&Identified>,
) -> Result<(FiveBarDynamics, String), String> {
    if let Some(i) = identified {
        return Ok((
            FiveBarDynamics {
                i_j: i.joint_inertia,
                m_e: i.end_mass,
                b: i.joint_damping(),
            },
            format!("identified {} ([identified] of the device file)", i.date),
        ));
    }
    let p = Plant2::new(*linkage, Vec2::new(center[0], center[1]))?;
    Ok((
        FiveBarDynamics {
            i_j: p.i_j,
            m_e: p.m_e,
            b: p.b,
        },
        "built-in estimates, not measured (run `haptic2d device identify`)".into(),
    ))
}

/// `haptic2d stability --device-file HAPLY.toml` for a 2DIY: the x and y axes.
fn run_planar2(
    a: &StabilityArgs,
    label: &str,
    file: &haptic2d_devices::haply::HaplyDeviceFile,
    controller: &ControllerKind,
    linkage: &Pantograph2,
    center: [f64; 2],
) -> Result<(), String> {
    let scene = scene_arg::load(&a.scene, Some(a.rate))?;
    let (dynamics, origin) = five_bar_dynamics(linkage, center, file.identified.as_ref())?;
    println!(
        "device dynamics: I_j {:.3e} kg·m², m_e {:.4} kg, b {:.2e} N·m·s/rad — {origin}",
        dynamics.i_j, dynamics.m_e, dynamics.b
    );
    let axes = analyse_planar2(
        linkage,
        &dynamics,
        Vec2::new(center[0], center[1]),
        controller,
        &scene.world,
        a.rate,
        a.delay,
    )?;
    println!(
        "stability of scene {} with the 2-DOF device of {} (x and y of the grasp point; the rotation is left to the world), controller {} at {} Hz ({} extra output sample{}):",
        scene.name,
        file.source,
        label,
        a.rate,
        a.delay,
        if a.delay == 1 { "" } else { "s" }
    );
    for r in &axes {
        let m = &r.model;
        println!(
            "axis {}: device m {:.4} kg, b {:.4} N s/m; slave {:.4} kg; against the {} spring K_e {:.1} N/m, B_e {:.3} N s/m",
            r.axis, m.m, m.b, m.m_s, r.contact, m.k_e, m.b_e
        );
        for (cond, p) in [("held", &r.held), ("released", &r.released)] {
            println!("  {cond:<8} sampled growth {:+.2} 1/s", p.growth);
        }
        println!("  verdict: {}", r.verdict().label());
    }
    Ok(())
}

/// True when `path` is a Haply device file (a top-level `kind = …` line before any table), not a
/// twin-pantograph parameter file; or the name of a built-in Haply file.
fn is_haply_file(path: &std::path::Path) -> bool {
    let builtin = crate::haply_arg::BUILTIN_FILES.iter().any(|(n, _)| {
        path.to_str()
            .is_some_and(|s| s == *n || s == format!("{n}.toml"))
    });
    let top_level_kind = |t: String| {
        t.lines()
            .map(str::trim)
            .take_while(|l| !l.starts_with('['))
            .any(|l| {
                l.strip_prefix("kind")
                    .is_some_and(|r| r.trim_start().starts_with('='))
            })
    };
    builtin
        || crate::scene_arg::read_bounded(path, haptic2d::scene::MAX_FILE_BYTES, "device file")
            .is_ok_and(top_level_kind)
}
