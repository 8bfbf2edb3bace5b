//! `haptic2d devices`: the serial ports of this machine with their USB ids, marking those that look
//! like a Haply board (USB ids of the built-in device files), and whether Haply's Inverse Service
//! (the Inverse3's) answers at its default address.

use crate::haply_arg::{exit, fail, BUILTIN_FILES};
use haptic2d_devices::haply::serial::list_ports;
use haptic2d_devices::haply::HaplyDeviceFile;
use std::process::ExitCode;

/// One line on the Inverse Service: something accepts TCP at `localhost:10001` (within 200 ms), or not.
fn inverse_service_line() -> String {
    use std::net::{SocketAddr, TcpStream};
    let addr: SocketAddr = ([127, 0, 0, 1], 10001).into();
    let up = TcpStream::connect_timeout(&addr, std::time::Duration::from_millis(200)).is_ok();
    if up {
        "Inverse Service (Haply Inverse3): something listens at localhost:10001 → haptic2d run --device inverse3".into()
    } else {
        "Inverse Service (Haply Inverse3): nothing at localhost:10001 (start Haply's Inverse Service, or `haptic2d emulate inverse3` without a device)".into()
    }
}

/// Lists the ports.
pub fn run() -> ExitCode {
    let service = inverse_service_line();
    let ports = match list_ports() {
        Ok(p) => p,
        Err(e) => return fail(exit::ERROR, &e),
    };
    let mut haply_ids = Vec::new();
    for (n, text) in BUILTIN_FILES {
        if let Ok(f) = HaplyDeviceFile::from_toml(text, n) {
            haply_ids.extend(f.usb_ids);
        }
    }
    if ports.is_empty() {
        println!("no serial ports found");
        println!("(a Haply board shows up as /dev/ttyACM* on Linux; try `haptic2d emulate haply` without one)");
        println!("{service}");
        return ExitCode::SUCCESS;
    }
    println!("{:<24} {:<11} description", "port", "USB id");
    for p in ports {
        let id = p
            .usb
            .map_or("-".to_string(), |(v, d)| format!("{v:04x}:{d:04x}"));
        let mark = if p.usb.is_some_and(|u| haply_ids.contains(&u)) {
            "  ← Haply board? (--device haply:auto picks the first)"
        } else {
            ""
        };
        println!("{:<24} {:<11} {}{mark}", p.path, id, p.description);
    }
    println!("{service}");
    ExitCode::SUCCESS
}
