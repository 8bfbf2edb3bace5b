//! haptic2d's own board firmware (`devices/firmware`) compiled natively with `cc` against its
//! Arduino stub, for the tests that speak to it over its pseudo-terminal.

use crate::files::repo_root;
use crate::process::{spawn_announced, Killed};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Compiles the native firmware for `board` (`"M0"` or `"M3"`) with `$CC` (default `cc`,
/// warnings as errors) into `dir`; the executable `dir/h2df-native-BOARD`.
pub fn compile_native_firmware(board: &str, dir: &Path) -> PathBuf {
    let fw = repo_root().join("devices/firmware");
    let src = fw.join("haptic2d_firmware/src");
    let native = fw.join("native");
    std::fs::create_dir_all(dir).unwrap();
    let exe = dir.join(format!("h2df-native-{}", board.to_lowercase()));
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .args(["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror"])
        .arg("-DH2DF_NATIVE")
        .arg(format!("-DH2DF_BOARD_{board}"))
        .arg("-I")
        .arg(&native)
        .arg("-I")
        .arg(&src)
        .arg(src.join("h2df.c"))
        .arg(src.join("board.c"))
        .arg(native.join("arduino_stub.c"))
        .arg("-o")
        .arg(&exe)
        .output()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{cc}`: {e}"));
    assert!(
        out.status.success(),
        "the native firmware does not compile:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    exe
}

/// Starts the native firmware `exe` writing its motor log to `motor_log`, with extra `args`
/// (e.g. `--hand-move`); the child (killed on drop) and its pty path (its first line, `pty: PATH`).
pub fn start_native_firmware(exe: &Path, motor_log: &Path, args: &[&str]) -> (Killed, String) {
    spawn_announced(
        Command::new(exe)
            .arg("--motor-log")
            .arg(motor_log)
            .args(args)
            .stderr(Stdio::null()),
        "pty: ",
    )
}
