//! `haptic2d devices`: the serial ports of this machine with their USB ids, marking those that look
//! like a Haply board (USB ids of the built-in device files).

use crate::haply_arg::{exit, fail, BUILTIN_FILES};
use haptic2d_devices::haply::serial::list_ports;
use haptic2d_devices::haply::HaplyDeviceFile;
use std::process::ExitCode;

/// Lists the ports.
pub fn run() -> ExitCode {
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
    ExitCode::SUCCESS
}
