//! The UDP reference devices (`devices/udp/sim_device.py` and `sim_device.c`) in processes of their
//! own, on loopback, for the UDP driver and CLI tests.

use crate::files::repo_root;
use crate::process::{spawn_announced, Killed};
use std::net::SocketAddr;
use std::path::Path;
use std::process::{Command, Stdio};

/// Which reference device.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Which {
    /// `devices/udp/sim_device.py` (needs `python3`).
    Python,
    /// `devices/udp/sim_device.c` (needs `cc`).
    C,
}

/// Builds `devices/udp/sim_device.c` with `cc` (warnings as errors) as `exe`; false without `cc`.
pub fn build_c_device(exe: &Path) -> bool {
    let Ok(built) = Command::new("cc")
        .args(["-O2", "-Wall", "-Werror", "-o"])
        .arg(exe)
        .arg(repo_root().join("devices/udp/sim_device.c"))
        .arg("-lm")
        .status()
    else {
        return false;
    };
    assert!(built.success(), "sim_device.c does not build");
    true
}

/// The command line of the reference device (`None` where its tool is missing); the C device is
/// built as `c_exe` first.
pub fn device_command(which: Which, c_exe: &Path) -> Option<Command> {
    match which {
        Which::Python => {
            Command::new("python3").arg("--version").output().ok()?;
            let mut p = Command::new("python3");
            p.arg(repo_root().join("devices/udp/sim_device.py"));
            Some(p)
        }
        Which::C => build_c_device(c_exe).then(|| Command::new(c_exe)),
    }
}

/// Starts `device` on an ephemeral loopback port with `args`: the process (killed on drop) and
/// the address of its first line, `listening on ADDR`.
pub fn start_device(mut device: Command, args: &[&str]) -> (Killed, SocketAddr) {
    device
        .args(["--bind", "127.0.0.1:0"])
        .args(args)
        .stderr(Stdio::inherit());
    let (child, addr) = spawn_announced(&mut device, "listening on ");
    let addr = addr
        .parse()
        .unwrap_or_else(|e| panic!("`{addr}` is not an address: {e}"));
    (child, addr)
}

/// The reference device `which` started with `args` (its C build at `c_exe`); `None` where its
/// tool is missing.
pub fn start_reference_device(
    which: Which,
    c_exe: &Path,
    args: &[&str],
) -> Option<(Killed, SocketAddr)> {
    Some(start_device(device_command(which, c_exe)?, args))
}
