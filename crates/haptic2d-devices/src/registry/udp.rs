//! `haptic2d run --device udp:ADDR:PORT [--device-file FILE]`: a device on the open UDP protocol
//! (docs/DEVICE-PROTOCOL.md) as a real device of the one run loop (the extension point in
//! [`super`]). The device listens at ADDR:PORT; the device file (default: the reference
//! pantograph, devices/udp-pantograph.toml) says whether joints or a pose come in, what goes out
//! and which linkage applies; the system is the 2-DOF pantograph system. When the device closes
//! (end of the run, a lost device, Ctrl-C) the network counters are printed on stdout:
//! `udp: N sent, N received: … fresh, … late, … lost, … reordered, … duplicate, … malformed; …;
//! dropped: … bad MAC, … wrong session, … wrong source, … seq jumps`.
//!
//! Addresses: a multicast, broadcast or unspecified address is refused (it would command every
//! device on the segment); an address beyond loopback needs `--allow-remote-device` and prints a
//! warning; without `protocol.key_file` (protocol version 1, unauthenticated) only loopback is
//! allowed, with a warning.

use super::{DeviceModel, RealDevice};
use crate::udp::{UdpDevice, UdpDeviceFile};
use haptic2d_rt::{DeviceError, DeviceIo};
use std::io::Write;
use std::net::{IpAddr, SocketAddr, ToSocketAddrs};
use std::path::Path;

/// The device address of `ADDR:PORT` (the part after `udp:`; a name is resolved once, here).
pub fn address_of(addr: &str) -> Result<SocketAddr, String> {
    let hint =
        "expected udp:ADDR:PORT, e.g. udp:127.0.0.1:5005 (the address the device listens at)";
    if addr.is_empty() {
        return Err(format!("--device udp:{addr}: {hint}"));
    }
    if let Ok(a) = addr.parse::<SocketAddr>() {
        return Ok(a);
    }
    addr.to_socket_addrs()
        .map_err(|e| format!("--device udp:{addr}: {e}; {hint}"))?
        .next()
        .ok_or_else(|| format!("--device udp:{addr}: no address; {hint}"))
}

/// Checks a device address: multicast, broadcast and unspecified addresses are refused; one beyond
/// loopback needs `allow_remote`. Returns the warning to print (`None` on loopback).
pub fn check_address(addr: SocketAddr, allow_remote: bool) -> Result<Option<String>, String> {
    let ip = addr.ip();
    let what = match ip {
        IpAddr::V4(v4) if v4.is_broadcast() => Some("the broadcast address"),
        _ if ip.is_multicast() => Some("a multicast address"),
        _ if ip.is_unspecified() => Some("the unspecified address"),
        _ => None,
    };
    if let Some(what) = what {
        return Err(format!(
            "--device udp:{addr}: {what} is not a device: commands sent there reach every host that listens\n    fix: give the device's own (unicast) address"
        ));
    }
    if ip.is_loopback() {
        return Ok(None);
    }
    if !allow_remote {
        return Err(format!(
            "--device udp:{addr}: a device beyond loopback drives motors over the network\n    fix: add --allow-remote-device if that is what you mean (and give the device file a protocol.key_file)"
        ));
    }
    Ok(Some(format!(
        "warning: --device udp:{addr}: the device is beyond loopback; torque commands go over the network (authenticated, protocol version 2)"
    )))
}

/// The UDP device of `--device udp:ADDR:PORT` for the rig of `haptic2d run`: the address resolved
/// and checked ([`check_address`]; `allow_remote` is `--allow-remote-device`), the device file read
/// and checked (a file without a key is refused beyond loopback), nothing opened yet. Warnings go
/// to stderr.
pub fn real_device(
    addr: &str,
    device_file: Option<&Path>,
    allow_remote: bool,
) -> Result<RealDevice, String> {
    let (real, warnings) = real_device_and_warnings(addr, device_file, allow_remote)?;
    for w in warnings {
        eprintln!("{w}");
    }
    Ok(real)
}

/// [`real_device`] with its warnings (unauthenticated protocol, beyond loopback) returned instead of
/// printed: for a listing of the registry, which prints nothing.
pub fn real_device_and_warnings(
    addr: &str,
    device_file: Option<&Path>,
    allow_remote: bool,
) -> Result<(RealDevice, Vec<String>), String> {
    let mut warnings = Vec::new();
    let addr = address_of(addr)?;
    let warning = check_address(addr, allow_remote)?;
    let file = match device_file {
        Some(p) => UdpDeviceFile::from_path(p)?,
        None => UdpDeviceFile::reference(),
    };
    if file.key.is_none() {
        if !addr.ip().is_loopback() {
            return Err(format!(
                "--device udp:{addr}: {} has no protocol.key_file; protocol version 1 (unauthenticated) is allowed on loopback only\n    fix: give the device and the device file a shared key (docs/DEVICE-PROTOCOL.md §6)",
                file.source
            ));
        }
        warnings.push(format!(
            "warning: udp:{addr} speaks protocol version 1 (no protocol.key_file in {}): datagrams are not authenticated, any local process could send states; set protocol.key_file for version 2",
            file.source
        ));
    }
    warnings.extend(warning);
    let name = format!("udp:{addr}");
    let summary = format!(
        "{}, 2-DOF pantograph, {} in, {} out, torque limit {} N·m, protocol version {}",
        file.source,
        if file.pose_input { "pose" } else { "joints" },
        if file.wrench_output {
            "wrench"
        } else {
            "torques"
        },
        file.torque_limit,
        if file.key.is_some() { 2 } else { 1 }
    );
    let open_name = name.clone();
    let real = RealDevice {
        name,
        model: DeviceModel::FiveBar {
            linkage: file.linkage,
            tau_max: file.torque_limit,
            center: reach_center(&file.linkage),
            workspace: haptic2d::haptic::WorkspaceSquare::five_bar(&file.linkage),
            identified: None,
        },
        summary,
        wait_periods: file.timeout_periods,
        max_missed_run: file.max_missed_deadlines,
        max_stall_periods: file.max_stall_periods,
        safety: file.safety,
        match_controller: None,
        // Open (the first state received) before the first deadline.
        open: Box::new(move |period| {
            let dev = UdpDevice::open(addr, &file, period, &open_name)?;
            Ok(Box::new(Counted(dev)) as Box<dyn DeviceIo + Send>)
        }),
    };
    Ok((real, warnings))
}

/// Where the stability gate linearises a UDP pantograph (m, device frame): on the symmetry axis
/// `x = d/2`, at the middle of the reach of each motor's two links, `r = (l1 + l2 + |l1 − l2|)/2`
/// from the motor, so `y = √(r² − (d/2)²)`. For the reference (Haply 2DIY gen 3) geometry this is
/// (0.019, 0.088) m, beside the Haply device file's workspace centre (0.019, 0.10) m.
fn reach_center(l: &haptic2d::device::pantograph2::Pantograph2) -> [f64; 2] {
    let r = 0.5 * (l.l1 + l.l2 + (l.l1 - l.l2).abs());
    let x = 0.5 * l.d;
    [x, (r * r - x * x).max(0.0).sqrt()]
}

/// A [`UdpDevice`] that prints its network counters when it closes (after the loop).
struct Counted(UdpDevice);

impl DeviceIo for Counted {
    #[inline]
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        self.0.read_encoders()
    }

    #[inline]
    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
        self.0.write_torques(tau)
    }

    fn zero_torques(&mut self) {
        self.0.zero_torques()
    }

    fn name(&self) -> &str {
        self.0.name()
    }

    fn buttons(&self) -> u8 {
        self.0.buttons()
    }
}

impl Drop for Counted {
    fn drop(&mut self) {
        // A closed or broken stdout is not an error here (nothing else to report it to).
        let _ = writeln!(std::io::stdout().lock(), "udp: {}", self.0.counters());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn udp_addresses_parse_and_bad_ones_say_the_form() {
        assert_eq!(
            address_of("127.0.0.1:5005").unwrap(),
            "127.0.0.1:5005".parse::<SocketAddr>().unwrap()
        );
        assert!(address_of("[::1]:5005").unwrap().is_ipv6());
        let e = address_of("").unwrap_err();
        assert!(e.contains("udp:ADDR:PORT"), "{e}");
        let e = address_of("127.0.0.1").unwrap_err();
        assert!(e.contains("udp:ADDR:PORT"), "{e}");
    }

    #[test]
    fn the_reference_device_is_a_five_bar_with_its_limits() {
        let r = real_device("127.0.0.1:5005", None, false).unwrap();
        assert_eq!(r.name, "udp:127.0.0.1:5005");
        assert!(matches!(r.model, DeviceModel::FiveBar { tau_max, .. } if tau_max == 0.123));
        assert_eq!(r.wait_periods, 3.0);
        assert_eq!(r.max_missed_run, Some(10));
    }

    #[test]
    fn multicast_broadcast_and_unspecified_addresses_are_refused() {
        for a in [
            "224.0.0.1:5005",
            "239.1.2.3:5005",
            "255.255.255.255:5005",
            "0.0.0.0:5005",
            "[ff02::1]:5005",
            "[::]:5005",
        ] {
            let e = check_address(a.parse().unwrap(), true).unwrap_err();
            assert!(
                e.contains("is not a device") && e.contains("unicast"),
                "{a}: {e}"
            );
        }
    }

    #[test]
    fn a_remote_address_needs_the_flag_and_warns() {
        let a: SocketAddr = "192.0.2.7:5005".parse().unwrap();
        let e = check_address(a, false).unwrap_err();
        assert!(e.contains("--allow-remote-device"), "{e}");
        let w = check_address(a, true).unwrap().unwrap();
        assert!(
            w.starts_with("warning:") && w.contains("beyond loopback"),
            "{w}"
        );
        assert_eq!(
            check_address("127.0.0.1:5005".parse().unwrap(), false),
            Ok(None)
        );
        assert_eq!(
            check_address("[::1]:5005".parse().unwrap(), false),
            Ok(None)
        );
        // Allowed beyond loopback, but a file without a key is still refused (version 1).
        let e = real_device("192.0.2.7:5005", None, true).err().unwrap();
        assert!(
            e.contains("protocol.key_file") && e.contains("loopback"),
            "{e}"
        );
    }
}
