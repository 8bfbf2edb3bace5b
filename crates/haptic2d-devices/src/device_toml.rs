//! What every device file's loader shares (Haply, UDP, Inverse3): the capped read with a fix naming
//! the template, and the TOML parse whose syntax or unknown-field error names the template too.

use haptic2d::scene::{SceneError, SceneErrors, MAX_FILE_BYTES};
use serde::de::DeserializeOwned;
use std::path::Path;

/// Reads the device file at `path` (at most [`MAX_FILE_BYTES`]) and returns its text and its name
/// for messages (`device file PATH`). `kind` says what was expected ("a Haply device file") and
/// `template` is a shipped example, both for the fix line of an error.
pub fn read(path: &Path, kind: &str, template: &str) -> Result<(String, String), String> {
    let text = crate::file_read::read_bounded(path, MAX_FILE_BYTES, "device file")
        .map_err(|e| format!("{e}\n    fix: give the path of {kind}, e.g. {template}"))?;
    Ok((text, format!("device file {}", path.display())))
}

/// Deserialises a device file's `text` into its raw table `T`; `source` names the file in messages,
/// `template` is the shipped file the fix points to.
pub fn parse<T: DeserializeOwned>(
    text: &str,
    source: &str,
    template: &str,
) -> Result<T, SceneErrors> {
    toml::from_str(text).map_err(|e| SceneErrors {
        source: source.to_string(),
        errors: vec![SceneError::from_toml(
            text,
            &e,
            format!("check the field names and TOML syntax against {template}"),
        )],
    })
}

/// Reads the device file at `path` ([`read`]: `kind` and `template` name what was expected in the
/// fix of an error) and parses its text with `parse(text, source)`; a parse error becomes its
/// message.
pub fn load<T>(
    path: &Path,
    kind: &str,
    template: &str,
    parse: impl FnOnce(&str, &str) -> Result<T, SceneErrors>,
) -> Result<T, String> {
    let (text, source) = read(path, kind, template)?;
    parse(&text, &source).map_err(|e| e.to_string())
}

/// The parsed file `value` when no check failed (`errs` empty), else every error, the file named
/// by `source`.
pub fn checked<T>(source: &str, errs: Vec<SceneError>, value: Option<T>) -> Result<T, SceneErrors> {
    match value {
        Some(v) if errs.is_empty() => Ok(v),
        _ => Err(SceneErrors {
            source: source.to_string(),
            errors: errs,
        }),
    }
}

/// Checks `TABLE.timeout_periods` (`field`): no state for this many control periods means the
/// device is lost, so it must be a finite number ≥ 1; `default` is the file kind's default, named
/// in the fix.
pub fn check_timeout(field: &str, periods: f64, default: u32, errs: &mut Vec<SceneError>) {
    if !(periods.is_finite() && periods >= 1.0) {
        errs.push(SceneError::new(
            field,
            format!("{periods} periods is not a timeout"),
            format!("give a number of control periods ≥ 1 (default {default})"),
        ));
    }
}

/// Checks the watchdog limits of the device file's table `table` (`protocol`, `service`):
/// `max_missed_deadlines` a count (0 turns the check off) that fits a `u32`, `max_stall_periods` a
/// finite number of periods ≥ 1.
pub fn check_watchdog(
    table: &str,
    max_missed_deadlines: i64,
    max_stall_periods: f64,
    errs: &mut Vec<SceneError>,
) {
    if max_missed_deadlines < 0 || max_missed_deadlines > u32::MAX as i64 {
        errs.push(SceneError::new(
            format!("{table}.max_missed_deadlines"),
            format!("{max_missed_deadlines} is not a count"),
            "give a number of consecutive deadlines ≥ 0 (0 turns the check off)",
        ));
    }
    if !(max_stall_periods.is_finite() && max_stall_periods >= 1.0) {
        errs.push(SceneError::new(
            format!("{table}.max_stall_periods"),
            format!("{max_stall_periods} periods is not a stall limit"),
            "give the loop's longest delay between two ticks in periods, ≥ 1 (default 5)",
        ));
    }
}

/// The watchdog's limit of consecutive missed deadlines from a checked file value: `None` (off)
/// for 0 (or a value out of `u32` range, which the checks have already refused).
pub fn missed_deadline_limit(max_missed_deadlines: i64) -> Option<u32> {
    u32::try_from(max_missed_deadlines).ok().filter(|n| *n > 0)
}
