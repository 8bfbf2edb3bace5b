//! Resolves the device parameters of `haptic2d run`: `--device-file FILE` wins over the scene's
//! `[device]` table, which wins over the spec defaults (§10.2).

use haptic2d::device::DeviceParams;
use haptic2d::scene::{device_params_from_toml, Scene, DEVICE_TEMPLATE, MAX_FILE_BYTES};
use std::path::Path;

/// The device parameters in use and where they came from.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceSetting {
    /// The parameters, validated at the run's sample period.
    pub params: DeviceParams,
    /// `spec defaults`, `scene FILE` or `device file FILE`, for the start line.
    pub origin: String,
}

/// Picks the device parameters for a run at sample period `dt` (s): those of `device_file` when
/// given, else the scene's `[device]` table, else the spec defaults. A bad device file is one
/// message naming the file, the field and the fix.
pub fn resolve(
    device_file: Option<&Path>,
    scene: &Scene,
    dt: f64,
) -> Result<DeviceSetting, String> {
    if let Some(path) = device_file {
        let name = path.display().to_string();
        // Bounded like scene files (`run --device-file /dev/zero` is an error, not an endless read).
        let text = crate::scene_arg::read_bounded(path, MAX_FILE_BYTES, "device file")
            .map_err(|e| format!("{e}\n    fix: give the path of a TOML device file; copy {DEVICE_TEMPLATE} and edit it"))?;
        let params = device_params_from_toml(&text, &format!("device file {name}"), Some(dt))
            .map_err(|e| e.to_string())?;
        return Ok(DeviceSetting {
            params,
            origin: format!("device file {name}"),
        });
    }
    Ok(match scene.device {
        Some(params) => DeviceSetting {
            params,
            origin: format!("scene {}", scene.source),
        },
        None => DeviceSetting {
            params: DeviceParams::default(),
            origin: "spec defaults".to_string(),
        },
    })
}
