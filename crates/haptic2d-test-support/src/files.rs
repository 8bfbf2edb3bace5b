//! Temp copies of files for the tests: a shipped device file with edits, in a directory of its own.

use std::path::{Path, PathBuf};

/// The repository's root, from this crate's manifest directory.
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The text of the shipped device file `devices/NAME`.
pub fn shipped_device_text(name: &str) -> String {
    let p = repo_root().join("devices").join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// A temp directory `haptic2d-PREFIX-PID-TAG` of its own, created (the pid keeps two test runs
/// apart, `tag` the tests of one binary).
pub fn temp_dir(prefix: &str, tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("haptic2d-{prefix}-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    dir
}

/// Writes `text` as `dir/name`; its path.
pub fn write_in(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    p
}
