//! The registry's device kinds as data ([`kinds`]): for every real device a front end can drive,
//! the `--device` form, the default device file, the model the loop builds, the limit and the
//! start-line summary, read from the shipped device files through the same glue functions `run`
//! uses, with nothing opened. Python's `haptic2d.devices()` lists these.

use super::{haply, inverse3, udp, DeviceModel, RealDevice};
use std::path::Path;

/// One device kind of the registry, with its shipped device file.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceKind {
    /// The `--device` form, e.g. `haply:PATH|haply:auto`.
    pub device: &'static str,
    /// The shipped device file the row describes (`devices/NAME.toml`), e.g. `haply-twin`.
    pub device_file: &'static str,
    /// The model the loop builds: `twin` (4 joints, `HapticSystem`), `five-bar` (2 joints,
    /// `Planar2System`) or `point` (the handle point, `PointSystem`); `None` when the driver is not in
    /// this build.
    pub model: Option<&'static str>,
    /// The output limit: motor torque (N·m) for a twin or five-bar, force magnitude (N) for a point
    /// device; `None` when the driver is not in this build.
    pub limit: Option<f64>,
    /// The unit of [`Self::limit`]: `N·m` or `N`.
    pub limit_unit: &'static str,
    /// The summary `run` prints on its start line, or why the driver is not in this build.
    pub summary: String,
}

/// Every device kind of the registry with each shipped device file: the three Haply files (gen 3
/// and gen 2 2DIY, twin), the UDP reference pantograph and the Inverse3 (in a build without the
/// `inverse3` feature: listed with no model, the summary saying how to build it). Errors name the
/// shipped file that did not load (a packaging fault, never a user's input).
pub fn kinds() -> Result<Vec<DeviceKind>, String> {
    let mut out = Vec::new();
    for (name, _) in haply::BUILTIN_FILES {
        let real = haply::real_device("/dev/null", Some(Path::new(name)))?;
        out.push(kind("haply:PATH|haply:auto", name, &real));
    }
    // The reference file has no key: its warning (protocol version 1) is for a run, not a listing.
    let (real, _) = udp::real_device_and_warnings("127.0.0.1:5005", None, false)?;
    out.push(kind("udp:ADDR:PORT", "udp-pantograph", &real));
    out.push(match inverse3::real_device(None, None) {
        Ok(real) => kind("inverse3[:URL]", "inverse3", &real),
        Err(why) => DeviceKind {
            device: "inverse3[:URL]",
            device_file: "inverse3",
            model: None,
            limit: None,
            limit_unit: "N",
            summary: why,
        },
    });
    Ok(out)
}

/// The row of `real`, a device of the `--device` form `device` with shipped file `device_file`.
fn kind(device: &'static str, device_file: &'static str, real: &RealDevice) -> DeviceKind {
    let (model, limit, limit_unit) = match &real.model {
        DeviceModel::Twin(p) => ("twin", p.tau_max, "N·m"),
        DeviceModel::FiveBar { tau_max, .. } => ("five-bar", *tau_max, "N·m"),
        DeviceModel::Point { force_limit, .. } => ("point", *force_limit, "N"),
    };
    DeviceKind {
        device,
        device_file,
        model: Some(model),
        limit: Some(limit),
        limit_unit,
        summary: real.summary.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows carry the shipped files' numbers: the 2DIY's firmware limit 0.123 N·m (DEVICES §2),
    /// the UDP reference device's 0.123 N·m, the Inverse3's 5 N (devices/inverse3.toml).
    #[test]
    fn every_kind_is_listed_with_its_shipped_limit() {
        let k = kinds().unwrap();
        let files: Vec<&str> = k.iter().map(|d| d.device_file).collect();
        assert_eq!(
            files,
            [
                "haply-2diy-gen3",
                "haply-2diy-gen2",
                "haply-twin",
                "udp-pantograph",
                "inverse3"
            ]
        );
        assert_eq!(k[0].model, Some("five-bar"));
        assert_eq!((k[0].limit, k[0].limit_unit), (Some(0.123), "N·m"));
        assert_eq!(k[2].model, Some("twin"));
        assert_eq!(k[3].model, Some("five-bar"));
        assert_eq!(k[3].limit, Some(0.123));
        let inv = &k[4];
        if cfg!(feature = "inverse3") {
            assert_eq!(
                (inv.model, inv.limit, inv.limit_unit),
                (Some("point"), Some(5.0), "N")
            );
            assert!(inv.summary.contains("force limit 5 N"), "{}", inv.summary);
        } else {
            assert_eq!((inv.model, inv.limit), (None, None));
            assert!(
                inv.summary.contains("--features inverse3"),
                "{}",
                inv.summary
            );
        }
    }
}
