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
