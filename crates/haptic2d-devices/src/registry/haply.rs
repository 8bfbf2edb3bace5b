//! The Haply boards of the registry (`--device haply:PATH|haply:auto`): the device file (default:
//! the built-in gen 3 2DIY file), the port, and the [`RealDevice`] of a board.

use super::{DeviceModel, RealDevice};
use crate::haply::serial::{find_board, open_port};
use crate::haply::{HaplyDevice, HaplyDeviceFile, HaplyKind};
use haptic2d_rt::DeviceIo;
use std::path::Path;

/// The shipped device files, embedded so that a binary works from anywhere.
pub const BUILTIN_FILES: [(&str, &str); 3] = [
    (
        "haply-2diy-gen3",
        include_str!("../../../../devices/haply-2diy-gen3.toml"),
    ),
    (
        "haply-2diy-gen2",
        include_str!("../../../../devices/haply-2diy-gen2.toml"),
    ),
    (
        "haply-twin",
        include_str!("../../../../devices/haply-twin.toml"),
    ),
];

/// Loads `--device-file` (a path, or a built-in name such as `haply-twin`), default the built-in
/// gen 3 2DIY file. Errors name the file, the field and the fix.
pub fn load_file(arg: Option<&Path>) -> Result<HaplyDeviceFile, String> {
    let name = arg.map(|p| p.display().to_string());
    let builtin = BUILTIN_FILES.iter().find(|(n, _)| {
        name.as_deref()
            .is_none_or(|s| s == *n || s == format!("{n}.toml"))
    });
    match (arg, builtin) {
        (Some(p), _) if p.exists() => HaplyDeviceFile::from_path(p),
        (_, Some((n, text))) => HaplyDeviceFile::from_toml(text, &format!("built-in device file {n}"))
            .map_err(|e| e.to_string()),
        (None, None) => Err("no built-in Haply device file".into()),
        (Some(p), None) => Err(format!(
            "device file {} not found\n    fix: give the path of a Haply device file, or a built-in one: {}",
            p.display(),
            BUILTIN_FILES.map(|(n, _)| n).join(", ")
        )),
    }
}

/// The port of `haply:PATH` or `haply:auto` (the first port with the file's USB ids).
pub fn port_of(device: &str, file: &HaplyDeviceFile) -> Result<String, String> {
    match device.strip_prefix("haply:") {
        Some("auto") => find_board(&file.usb_ids),
        Some("") | None => Err(format!(
            "--device `{device}`: expected haply:PATH (e.g. haply:/dev/ttyACM0) or haply:auto"
        )),
        Some(path) => Ok(path.to_string()),
    }
}

/// The Haply board of `--device haply:PORT` (`PORT` a path or `auto`) for the rig of `haptic2d run`:
/// the device file `device_file` (default the built-in gen 3 2DIY) read and checked, the port
/// resolved, nothing opened yet. See the extension point in [`super`].
pub fn real_device(port: &str, device_file: Option<&Path>) -> Result<RealDevice, String> {
    let file = load_file(device_file)?;
    let path = port_of(&format!("haply:{port}"), &file)?;
    let name = format!("haply:{path}");
    let (model, kind) = match &file.kind {
        HaplyKind::TwoDiy {
            linkage,
            center,
            half_width,
        } => (
            DeviceModel::FiveBar {
                linkage: *linkage,
                tau_max: file.torque_limit,
                center: *center,
                workspace: haptic2d::haptic::WorkspaceSquare::around(*center, *half_width),
                identified: file.identified.clone(),
            },
            "2-DOF 2DIY",
        ),
        HaplyKind::Twin(p) => (DeviceModel::Twin(*p), "twin pantograph"),
    };
    let dynamics = match (&file.kind, &file.identified) {
        (HaplyKind::Twin(_), _) => String::new(),
        (_, Some(i)) => format!(
            ", stability gate on the identified dynamics of {} (I_j {:.3e} kg·m², m_e {:.4} kg, b {:.2e} N·m·s/rad)",
            i.date,
            i.joint_inertia,
            i.end_mass,
            i.joint_damping()
        ),
        (_, None) => ", stability gate on the built-in estimates of the dynamics (not measured: `haptic2d device identify`)".to_string(),
    };
    let summary = format!(
        "{}, {kind}, torque limit {} N·m{dynamics}",
        file.source, file.torque_limit
    );
    let open_name = name.clone();
    let matcher = file.clone();
    // The driver's own timeout (a pseudo-terminal's is longer: see PTY_MIN_TIMEOUT_PERIODS).
    let wait_periods = crate::haply::driver::timeout_periods_for(&file, &name);
    Ok(RealDevice {
        name,
        model,
        summary,
        wait_periods,
        max_missed_run: file.max_missed_deadlines,
        max_stall_periods: file.max_stall_periods,
        safety: file.safety,
        match_controller: Some(Box::new(move |k| matcher.controller_for(k))),
        // Open and hand-shake before the first deadline, with the handle at the rest pose
        // (docs/DEVICES.md §7); the firmware's line and, for a board without a watchdog, the
        // warning are printed once here, before the loop.
        open: Box::new(move |period| {
            let port = open_port(&path)?;
            eprintln!(
                "{open_name}: hold the handle still at its rest pose while the board is set up"
            );
            let dev = HaplyDevice::open(port, &file, period, &open_name)?;
            eprintln!("{open_name}: {}", dev.firmware_summary());
            if let Some(w) = dev.start_warning() {
                eprintln!("warning: {w}");
            }
            Ok(Box::new(dev) as Box<dyn DeviceIo + Send>)
        }),
    })
}
