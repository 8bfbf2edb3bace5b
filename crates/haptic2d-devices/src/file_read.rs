//! Reading a device file with the same size cap as scene files (issue 10: every input bounded), so
//! `--device-file /dev/zero` or a mistaken multi-gigabyte path is a clear error, not a hang.

use haptic2d::scene::MAX_FILE_BYTES;
use std::io::Read;
use std::path::Path;

/// The text of the device file at `path`, at most [`MAX_FILE_BYTES`] (16 MiB); `fix` is the hint
/// after a read error (e.g. "give the path of a Haply device file, e.g. devices/…").
pub fn read_device_file(path: &Path, fix: &str) -> Result<String, String> {
    let name = path.display();
    let file = std::fs::File::open(path)
        .map_err(|e| format!("cannot read device file {name}: {e}\n    fix: {fix}"))?;
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read device file {name}: {e}\n    fix: {fix}"))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(format!(
            "device file {name} is larger than the cap of {MAX_FILE_BYTES} bytes ({} MiB)\n    fix: {fix}",
            MAX_FILE_BYTES >> 20
        ));
    }
    String::from_utf8(bytes)
        .map_err(|e| format!("device file {name} is not UTF-8 text ({e})\n    fix: {fix}"))
}
