//! A minimal CSV writer for the numeric time series (header + rows of `f64`).

use std::fmt::Write as _;
use std::path::Path;

/// Writes `columns` (each the same length) under `header` to `path`, full precision.
pub fn write_columns(path: &Path, header: &[&str], columns: &[&[f64]]) -> Result<(), String> {
    if header.len() != columns.len() {
        return Err(format!(
            "{}: {} header names for {} columns",
            path.display(),
            header.len(),
            columns.len()
        ));
    }
    let rows = columns.iter().map(|c| c.len()).min().unwrap_or(0);
    let mut text = String::with_capacity(rows * 16 * columns.len().max(1) + 64);
    text.push_str(&header.join(","));
    text.push('\n');
    for r in 0..rows {
        for (i, c) in columns.iter().enumerate() {
            if i > 0 {
                text.push(',');
            }
            let _ = write!(text, "{}", c[r]);
        }
        text.push('\n');
    }
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}
