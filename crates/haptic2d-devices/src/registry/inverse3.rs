//! `haptic2d run --device inverse3[:URL] [--device-file FILE]`: a Haply Inverse3 through its Inverse
//! Service (the `haply` client crate) as a real device of the one run loop (the extension point in
//! [`super`]), in planar mode. `URL` is the service's address, `http://HOST:PORT` (the WebSocket
//! is `ws://HOST:PORT/`); without it the device file's `[service]` (default
//! `http://localhost:10001`, `ws://localhost:10001/`). The device file (default the shipped
//! devices/inverse3.toml) maps two device axes to the world plane and holds the third; the model is
//! a point model ([`super::DeviceModel::Point`]): the driver reports the plane point (m) and
//! takes the plane force (N), and the loop's system is the Cartesian
//! [`PointSystem`](haptic2d::haptic::PointSystem) (no linkage in between).
//!
//! The driver is behind the `inverse3` feature of haptic2d-devices (haptic2d-cli's `inverse3`
//! turns it on; off by default: it brings Haply's client with its HTTP/TLS stack); without it `--device inverse3` is refused as bad input with the
//! command that builds it ([`NOT_BUILT`]).

#[cfg(feature = "inverse3")]
use super::DeviceModel;
use super::PointDynamics;
use super::RealDevice;
#[cfg(feature = "inverse3")]
use crate::inverse3::{Inverse3Device, Inverse3DeviceFile};
#[cfg(feature = "inverse3")]
use haptic2d_rt::DeviceIo;
use std::path::Path;

/// Why `--device inverse3` and `emulate inverse3` are refused by a build without the `inverse3`
/// feature, and how to get them.
pub const NOT_BUILT: &str = "the Haply Inverse3 driver is not in this build (the `inverse3` feature is off by default: it needs Haply's client with its HTTP/TLS stack and OpenSSL headers)\n    fix: cargo install --path crates/haptic2d-cli --features inverse3   (or cargo run --release --features inverse3 -- run --device inverse3)";

/// The handle dynamics the stability gate of `run` linearises an Inverse3 with: 0.03 kg, no
/// damping. Not a measurement of an Inverse3 (nobody here has one): the lightest of the project's
/// estimates (the 2DIY emulator's end-point mass, the one the gate used before, through the
/// virtual five-bar that this point model replaced; the Inverse3 emulator moves 0.2 kg with
/// 1 N·s/m). The gate errs towards refusing: over the named controllers and virtual couplings of
/// rising damping it refuses every released axis for this handle that it refuses for the
/// emulator's, and more (haptic2d-lab `stability::planar2` test
/// `the_gate_refuses_for_a_light_undamped_point_handle_whatever_it_refuses_for_a_heavy_one`).
pub const GATE_DYNAMICS: PointDynamics = PointDynamics {
    mass: 0.03,
    damping: 0.0,
};

/// Without the `inverse3` feature: the URL is checked, then the device refused ([`NOT_BUILT`]).
#[cfg(not(feature = "inverse3"))]
pub fn real_device(url: Option<&str>, _device_file: Option<&Path>) -> Result<RealDevice, String> {
    if let Some(u) = url {
        service_urls(u)?;
    }
    Err(format!("--device inverse3: {NOT_BUILT}"))
}

/// The service addresses `(http, ws)` of the `URL` of `inverse3:URL`: `http://HOST:PORT[/]`,
/// `ws://HOST:PORT[/]` or a bare `HOST:PORT`.
pub fn service_urls(url: &str) -> Result<(String, String), String> {
    let hint = "expected inverse3:http://HOST:PORT (e.g. inverse3:http://localhost:10001, the Inverse Service's address) or plain inverse3";
    let rest = url
        .strip_prefix("http://")
        .or_else(|| url.strip_prefix("ws://"))
        .unwrap_or(url);
    let host = rest.trim_end_matches('/');
    let ok = !host.is_empty()
        && !host.contains('/')
        && !host.contains("://")
        && host
            .rsplit_once(':')
            .is_some_and(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok());
    if !ok {
        return Err(format!("--device inverse3:{url}: {hint}"));
    }
    Ok((format!("http://{host}"), format!("ws://{host}/")))
}

/// The Inverse3 of `--device inverse3[:URL]` for the rig of `haptic2d run`: the device file read and
/// checked, the service address resolved, nothing opened yet.
#[cfg(feature = "inverse3")]
pub fn real_device(url: Option<&str>, device_file: Option<&Path>) -> Result<RealDevice, String> {
    let mut file = match device_file {
        Some(p) => Inverse3DeviceFile::from_path(p)?,
        None => Inverse3DeviceFile::shipped(),
    };
    if let Some(u) = url {
        let (http, ws) = service_urls(u)?;
        file = file.with_service(http, ws);
    }
    let name = format!("inverse3:{}", file.http_url);
    let axis = |a: crate::inverse3::device_file::SignedAxis| {
        format!(
            "{}{}",
            if a.sign < 0.0 { "-" } else { "" },
            ["x", "y", "z"][a.index]
        )
    };
    let summary = format!(
        "{}, planar: world x = device {}, y = device {}, {} held at {} m (K {} N/m, B {} N·s/m), force limit {} N",
        file.source,
        axis(file.axes[0]),
        axis(file.axes[1]),
        ["x", "y", "z"][file.held_axis],
        file.plane_position,
        file.plane_stiffness,
        file.plane_damping,
        file.force_limit
    );
    let open_name = name.clone();
    Ok(RealDevice {
        name,
        model: DeviceModel::Point {
            force_limit: file.force_limit,
            // The file's square, in the plane coordinates the driver reports.
            workspace: haptic2d::haptic::WorkspaceSquare::around(file.center, file.half_width),
            gate_dynamics: GATE_DYNAMICS,
        },
        summary,
        wait_periods: file.timeout_periods,
        max_missed_run: file.max_missed_deadlines,
        max_stall_periods: file.max_stall_periods,
        safety: file.safety,
        match_controller: None,
        // Connect and wait for the first state before the first deadline.
        open: Box::new(move |period| {
            let dev = Inverse3Device::open(&file, period, &open_name)?;
            Ok(Box::new(dev) as Box<dyn DeviceIo + Send>)
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(not(feature = "inverse3"))]
    fn without_the_feature_inverse3_is_refused_with_the_build_command() {
        let Err(e) = real_device(None, None) else {
            panic!("refused")
        };
        assert!(e.contains("--features inverse3"), "{e}");
        // A malformed URL still says the form first.
        let Err(e) = real_device(Some("h:1/x"), None) else {
            panic!("refused")
        };
        assert!(e.contains("inverse3:http://HOST:PORT"), "{e}");
    }

    #[test]
    fn service_urls_parse_and_bad_ones_say_the_form() {
        let w = |a: &str, b: &str| (a.to_string(), b.to_string());
        assert_eq!(
            service_urls("http://127.0.0.1:10001").unwrap(),
            w("http://127.0.0.1:10001", "ws://127.0.0.1:10001/")
        );
        assert_eq!(
            service_urls("ws://localhost:9000/").unwrap(),
            w("http://localhost:9000", "ws://localhost:9000/")
        );
        assert_eq!(
            service_urls("localhost:9000").unwrap(),
            w("http://localhost:9000", "ws://localhost:9000/")
        );
        for bad in [
            "",
            "http://",
            "localhost",
            "http://h:port",
            "https://h:1",
            "h:1/x",
        ] {
            let e = service_urls(bad).unwrap_err();
            assert!(e.contains("inverse3:http://HOST:PORT"), "{bad}: {e}");
        }
    }

    #[test]
    #[cfg(feature = "inverse3")]
    fn the_shipped_file_is_a_point_device_with_the_file_limits() {
        let r = real_device(Some("http://127.0.0.1:1234"), None).unwrap();
        assert_eq!(r.name, "inverse3:http://127.0.0.1:1234");
        let file = Inverse3DeviceFile::shipped();
        assert_eq!(
            r.model,
            DeviceModel::Point {
                force_limit: 5.0,
                workspace: haptic2d::haptic::WorkspaceSquare::around(file.center, 0.15),
                gate_dynamics: GATE_DYNAMICS,
            }
        );
        assert_eq!(r.wait_periods, 20.0);
        assert_eq!(r.max_missed_run, Some(10));
        let r = real_device(None, None).unwrap();
        assert_eq!(r.name, "inverse3:http://localhost:10001");
    }
}
