//! Reading a text input file with a size cap (issue 10: every input bounded), shared by the scene
//! and device files of the CLI and the device files of the drivers here, so `/dev/zero` or a
//! mistaken multi-gigabyte path is a clear error, not an endless read.

use std::io::Read;
use std::path::Path;

/// Reads the UTF-8 text file at `path` (`what` names it in messages, e.g. "scene file"), refusing
/// more than `max` bytes (callers pass `haptic2d::scene::MAX_FILE_BYTES`, 16 MiB): at most
/// `max + 1` bytes are ever read.
pub fn read_bounded(path: &Path, max: u64, what: &str) -> Result<String, String> {
    let shown = path.display();
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read {what} {shown}: {e}"))?;
    let mut bytes = Vec::new();
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {what} {shown}: {e}"))?;
    if bytes.len() as u64 > max {
        let grid = if what == "scene file" {
            " (scene piles are built with [[grid]] tables)"
        } else {
            ""
        };
        return Err(format!(
            "{what} {shown} is larger than the documented cap of {max} bytes ({} MiB)\n    fix: give a TOML {what}{grid}",
            max >> 20
        ));
    }
    String::from_utf8(bytes)
        .map_err(|e| format!("{what} {shown} is not UTF-8 text ({e})\n    fix: give a TOML {what}"))
}
